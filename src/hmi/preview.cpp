// SPDX-License-Identifier: GPL-3.0-or-later
// The toolpath of a program as polylines for the HMI's 3D view, as the program source makes it.
#include "opencnc/hmi/preview.hpp"

#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/core/vec3.hpp"

namespace opencnc::hmi {

namespace {

using nlohmann::json;

constexpr double kChordDeg = 5;  ///< an arc is drawn with a chord every this many degrees

/// Appends the points of arc `id` after its start (chords every kChordDeg, the helix linear). An
/// arc of the U V W planes moves X Y Z along a line: its end point only.
void arc_points(const canon::Program& p, canon::SegmentId id, std::vector<double>& out) {
  const canon::ArcGeometry& g = p.arc(id);
  const Pose s = p.start_of(id), e = p.end(id);
  const Vec3 &c = g.center, &n = g.normal;
  const Vec3 r0 = take3(s) - c, re = take3(e) - c;
  const double along0 = dot(r0, n), along_e = dot(re, n);
  const Vec3 u = r0 - along0 * n, v = cross(n, u);
  const double radius2 = dot(u, u);
  const double sweep = canon::plane_base(g.plane) == 0 && radius2 > 0
                           ? canon::arc_sweep(std::atan2(dot(re, v) / radius2, dot(re, u) / radius2), g.turns)
                           : 0.0;
  const int steps =
      std::max(1, static_cast<int>(std::ceil(std::fabs(sweep) * 180 / std::numbers::pi / kChordDeg)));
  for (int k = 1; k < steps; ++k) {
    const double t = static_cast<double>(k) / steps, a = sweep * t;
    const double along = along0 + (along_e - along0) * t;
    for (int i = 0; i < 3; ++i) out.push_back(c[i] + u[i] * std::cos(a) + v[i] * std::sin(a) + n[i] * along);
  }
  for (int i = 0; i < 3; ++i) out.push_back(e[i]);
}

/// Builds the polylines (rapids and feeds apart) and notes the tools the program puts in the
/// spindle (M6 after a T, M61 Q), as the scan shows them; stops after `max_moves` moves.
class PreviewReader final : public controller::ScanReader {
 public:
  PreviewReader(const Pose& start, std::size_t max_moves) : max_moves_(max_moves) {
    pts_ = {start[0], start[1], start[2]};
  }
  bool action(const canon::Program& p, std::size_t index) override {
    const canon::Action& x = p.action(index);
    if (x.kind == canon::ActionKind::SelectTool) selected_ = x.index;
    if (x.kind == canon::ActionKind::ChangeTool && selected_ > 0) tools_.insert(selected_);
    if (x.kind == canon::ActionKind::ChangeToolNumber && x.index > 0) tools_.insert(x.index);
    return true;
  }
  bool move(const canon::Program& p, canon::SegmentId id) override {
    if (moves_ >= max_moves_) {
      truncated_ = true;
      return false;
    }
    ++moves_;
    const canon::Move& m = p.move(id);
    const bool r = m.kind == canon::MoveKind::Traverse;
    if (r != rapid_) {
      flush();
      rapid_ = r;
    }
    if (m.kind == canon::MoveKind::Arc) {
      arc_points(p, id, pts_);
    } else {
      const Pose e = p.end(id);
      pts_.insert(pts_.end(), {e[0], e[1], e[2]});
    }
    return true;
  }
  json result(json diagnostics) {
    flush();
    return {{"polylines", lines_},
            {"moves", moves_},
            {"truncated", truncated_},
            {"diagnostics", std::move(diagnostics)},
            {"tools", std::vector<int>(tools_.begin(), tools_.end())}};
  }

 private:
  void flush() {
    if (pts_.size() > 3) lines_.push_back({{"rapid", rapid_}, {"points", pts_}});
    pts_.assign(pts_.end() - 3, pts_.end());
  }

  std::size_t max_moves_;
  std::size_t moves_ = 0;
  bool truncated_ = false, rapid_ = false;
  std::vector<double> pts_;
  json lines_ = json::array();
  int selected_ = 0;
  std::set<int> tools_;
};

}  // namespace

json program_preview(const controller::GcodeProgramSource& source, const std::string& path, const Pose& start,
                     std::size_t max_moves) {
  PreviewReader reader(start, max_moves);
  const Diagnostics d = source.scan(path, start, {}, reader);
  json diags = json::array();
  for (const Diagnostic& x : d.items()) diags.push_back(x.format());
  return reader.result(std::move(diags));
}

}  // namespace opencnc::hmi
