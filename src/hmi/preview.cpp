// SPDX-License-Identifier: GPL-3.0-or-later
// The toolpath of a program as polylines for the HMI's 3D view.
#include "opencnc/hmi/preview.hpp"

#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/core/vec3.hpp"
#include "opencnc/gcode/interpreter.hpp"

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

/// The tools the program puts in the spindle (M6 after a T, M61 Q), each once, in number order.
std::vector<int> program_tools(const canon::Program& p) {
  std::set<int> tools;
  int selected = 0;
  for (std::size_t a = 0; a < p.action_count(); ++a) {
    const canon::Action& x = p.action(a);
    if (x.kind == canon::ActionKind::SelectTool) selected = x.index;
    if (x.kind == canon::ActionKind::ChangeTool && selected > 0) tools.insert(selected);
    if (x.kind == canon::ActionKind::ChangeToolNumber && x.index > 0) tools.insert(x.index);
  }
  return {tools.begin(), tools.end()};
}

}  // namespace

json program_preview(const control::GcodeProgramSource& source, const std::string& path, const Pose& start,
                     std::size_t max_moves) {
  gcode::Options options = source.options_for(path, {});
  options.mode = gcode::Mode::Scan;
  gcode::Interpreter interp(options);
  canon::ProgramBuilder builder(kXyzabc, start);
  json diags = json::array();
  bool truncated = false;
  if (interp.open(path)) {
    for (;;) {
      const gcode::RunStatus rs = interp.run(builder, 1000);
      if (rs != gcode::RunStatus::Ok) break;
      if (builder.program().size() >= max_moves) {
        truncated = true;
        break;
      }
    }
  }
  for (const Diagnostic& d : interp.diagnostics().items()) diags.push_back(d.format());
  const canon::Program& p = builder.program();
  json lines = json::array();
  std::vector<double> pts;
  bool rapid = false;
  auto flush = [&] {
    if (pts.size() > 3) lines.push_back({{"rapid", rapid}, {"points", pts}});
    pts.assign(pts.end() - 3, pts.end());
  };
  const Pose s = p.start();
  pts = {s[0], s[1], s[2]};
  for (canon::SegmentId id = 0; id < p.size(); ++id) {
    const canon::Move& m = p.move(id);
    const bool r = m.kind == canon::MoveKind::Traverse;
    if (r != rapid) {
      flush();
      rapid = r;
    }
    if (m.kind == canon::MoveKind::Arc) {
      arc_points(p, id, pts);
    } else {
      const Pose e = p.end(id);
      pts.insert(pts.end(), {e[0], e[1], e[2]});
    }
  }
  flush();
  return {{"polylines", lines},
          {"moves", p.size()},
          {"truncated", truncated},
          {"diagnostics", diags},
          {"tools", program_tools(p)}};
}

}  // namespace opencnc::hmi
