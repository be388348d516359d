// SPDX-License-Identifier: GPL-3.0-or-later
// The modal-state digest: a sink that keeps the last value of every state-setting canonical call
// until segment k's first motion, then hashes them in a fixed order.
#include "opencnc/broaching/modal_digest.hpp"

#include <bit>
#include <map>

#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/interpreter.hpp"

namespace opencnc::recovery {

namespace {

/// FNV-1a 64 over values fed in a fixed order.
class Fnv {
 public:
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ b[i]) * 0x100000001b3ULL;
  }
  void num(double d) { bytes(&d, sizeof d); }
  void num(std::int64_t v) { bytes(&v, sizeof v); }
  void pose(const Pose& p) {
    for (double d : p.v) num(d);
  }
  std::uint64_t value() const { return h_ == 0 ? 1 : h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

/// What the program has set by the time it reaches segment k (the canonical view of its modal
/// state: what the builder and the machine act on).
class DigestSink final : public canon::Sink {
 public:
  explicit DigestSink(canon::SegmentId first) : first_(first) {}
  bool reached() const noexcept { return reached_; }
  /// The digest as it stood at segment k's first motion.
  std::uint64_t reached_digest() const noexcept { return digest_; }

  std::uint64_t digest() const {
    Fnv f;
    f.num(static_cast<std::int64_t>(units_));
    for (const auto& [index, offset] : g5x_) {
      f.num(static_cast<std::int64_t>(index));
      f.pose(offset);
    }
    f.pose(g92_);
    f.num(rotation_);
    f.num(static_cast<std::int64_t>(plane_));
    f.num(static_cast<std::int64_t>(feed_reference_));
    f.num(feed_rate_);
    f.num(static_cast<std::int64_t>(feed_mode_));
    f.num(static_cast<std::int64_t>(motion_control_));
    f.num(tolerance_);
    f.num(naive_tolerance_);
    f.pose(tool_offset_);
    f.num(static_cast<std::int64_t>(tool_));
    for (const auto& [spindle, s] : spindles_) {
      f.num(static_cast<std::int64_t>(spindle));
      f.num(s.speed);
      f.num(static_cast<std::int64_t>(s.direction));
      f.num(s.css_max);
    }
    f.num(static_cast<std::int64_t>(mist_ * 2 + flood_));
    f.num(static_cast<std::int64_t>(coupling_.law));
    f.num(static_cast<std::int64_t>(coupling_.table));
    f.num(coupling_.pitch);
    f.num(coupling_.rate);
    return f.value();
  }

  void use_length_units(canon::Units u) override { units_ = u; }
  void set_g5x_offset(int index, const Pose& o) override { g5x_[index] = o; }
  void set_g92_offset(const Pose& o) override { g92_ = o; }
  void set_xy_rotation(double d) override { rotation_ = d; }
  void select_plane(canon::Plane p) override { plane_ = p; }
  void set_feed_reference(canon::FeedReference r) override { feed_reference_ = r; }
  void set_feed_rate(double f) override { feed_rate_ = f; }
  void set_feed_mode(int, canon::FeedMode m) override { feed_mode_ = m; }
  void set_motion_control_mode(canon::MotionControl m, double t) override {
    motion_control_ = m;
    tolerance_ = t;
  }
  void set_naivecam_tolerance(double t) override { naive_tolerance_ = t; }
  void use_tool_length_offset(const Pose& o) override { tool_offset_ = o; }
  void change_tool(int t) override { tool_ = t; }
  void change_tool_number(int t) override { tool_ = t; }
  void set_spindle_speed(int s, double rpm) override { spindles_[s].speed = rpm; }
  void start_spindle_clockwise(int s) override { spindles_[s].direction = 1; }
  void start_spindle_counterclockwise(int s) override { spindles_[s].direction = -1; }
  void stop_spindle_turning(int s) override { spindles_[s].direction = 0; }
  void set_spindle_mode(int s, double css_max) override { spindles_[s].css_max = css_max; }
  void mist_on() override { mist_ = 1; }
  void mist_off() override { mist_ = 0; }
  void flood_on() override { flood_ = 1; }
  void flood_off() override { flood_ = 0; }
  void set_axis_coupling(const canon::AxisCoupling& c) override { coupling_ = c; }

  void straight_traverse(canon::SegmentId id, const Pose&) override { motion(id); }
  void straight_feed(canon::SegmentId id, const Pose&) override { motion(id); }
  void arc_feed(canon::SegmentId id, const canon::ArcFeed&) override { motion(id); }
  void straight_probe(canon::SegmentId id, const Pose&) override { motion(id); }
  void rigid_tap(canon::SegmentId id, const Pose&, double) override { motion(id); }
  void nurbs_feed(canon::SegmentId id, int, std::span<const canon::NurbsPoint>) override { motion(id); }

 private:
  void motion(canon::SegmentId id) {
    if (id >= first_ && !reached_) {
      reached_ = true;
      digest_ = digest();
    }
  }

  struct Spindle {
    double speed = 0, css_max = 0;
    int direction = 0;
  };
  canon::SegmentId first_;
  bool reached_ = false;
  std::uint64_t digest_ = 0;
  canon::Units units_ = canon::Units::Mm;
  std::map<int, Pose> g5x_;
  Pose g92_{}, tool_offset_{};
  double rotation_ = 0, feed_rate_ = 0, tolerance_ = 0, naive_tolerance_ = 0;
  canon::Plane plane_ = canon::Plane::XY;
  canon::FeedReference feed_reference_ = canon::FeedReference::Workpiece;
  canon::FeedMode feed_mode_ = canon::FeedMode::UnitsPerMinute;
  canon::MotionControl motion_control_ = canon::MotionControl::ExactPath;
  int tool_ = 0, mist_ = 0, flood_ = 0;
  std::map<int, Spindle> spindles_;
  canon::AxisCoupling coupling_;
};

/// Blocks per run() call: the loop checks between calls whether segment k was reached.
constexpr std::uint64_t kBlocksPerStep = 64;

}  // namespace

std::optional<std::uint64_t> modal_digest_at(const gcode::Options& options, const std::string& path,
                                             const Pose& program_start, canon::SegmentId segment,
                                             std::string* error) {
  gcode::Options o = options;
  o.mode = gcode::Mode::Scan;
  gcode::Interpreter interp(o);
  DigestSink sink(segment);
  const auto fail = [&](std::string why) -> std::optional<std::uint64_t> {
    if (error != nullptr) *error = std::move(why);
    return std::nullopt;
  };
  if (!interp.open(path)) {
    return fail(interp.diagnostics().empty() ? "cannot read " + path
                                             : interp.diagnostics().items().front().format());
  }
  interp.set_machine_position(program_start);
  for (;;) {
    const gcode::RunStatus st = interp.run(sink, kBlocksPerStep);
    if (sink.reached()) return sink.reached_digest();
    if (st == gcode::RunStatus::Error) {
      const auto& d = interp.diagnostics().items();
      return fail(d.empty() ? std::string("the program failed before the segment") : d.front().format());
    }
    if (st == gcode::RunStatus::Finished)
      return fail("the program ends before segment " + std::to_string(segment));
  }
}

}  // namespace opencnc::recovery
