// SPDX-License-Identifier: GPL-3.0-or-later
// Fanuc lathe cycles that need no roughing engine: G75 grooving (X pecks, Z steps) and G76
// multiple-pass threading, in Fanuc's two-block form (G75 R; G75 X Z P Q F / G76 P Q R;
// G76 X Z R P Q F) and Haas's one-block form (G75 X Z I K F / G76 X Z K D F I A).
#include <cmath>
#include <memory>
#include <vector>

#include "codes.hpp"
#include "gcode_error.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxPasses = 10000;  // a thread or groove needing more is a programming error

double sign(double v) noexcept {
  return v < 0.0 ? -1.0 : 1.0;
}

Pose xz(const Pose& base, double x, double z) {
  Pose p = base;
  p[Axis::X] = x;
  p[Axis::Z] = z;
  return p;
}

// Plain data of one threading job, in radius coordinates.
struct Thread {
  double x0, z0;        // start point (where every pass starts and ends)
  double x_end, z_end;  // thread end at the root
  double taper;         // radius at the start minus radius at the end (R / I)
  double height;        // thread height (radius)
  double first_depth;   // depth of the first cut
  double min_depth;     // smallest depth increment
  double allowance;     // finishing allowance
  int finish_passes;
  double chamfer;  // pull-out length along Z
  double half_angle_deg;
  double lead;
};

// Depths of cut: the first cut's depth times the square root of the pass number (equal chip
// area per pass), at least `min_depth` deeper each time, up to height - allowance; then the
// finishing passes at the full height.
std::vector<double> thread_depths(const Thread& t) {
  std::vector<double> depths;
  const double rough_end = t.height - t.allowance;
  double last = 0;
  for (int n = 1; rough_end > 0 && last < rough_end; ++n) {
    double d = t.first_depth * std::sqrt(static_cast<double>(n));
    if (d - last < t.min_depth) d = last + t.min_depth;
    last = std::min(d, rough_end);
    depths.push_back(last);
    if (depths.size() > static_cast<std::size_t>(kMaxPasses)) return {};
  }
  for (int i = 0; i < std::max(1, t.finish_passes); ++i) depths.push_back(t.height);
  return depths;
}

// One synchronised move: the spindle-synchronised feed is the distance along the move per
// revolution that advances Z by one lead (as LinuxCNC's canon takes it).
void synchronised(ExecContext& ctx, const Pose& from, const Pose& to, double lead) {
  const double dz = std::fabs(to[Axis::Z] - from[Axis::Z]);
  const double length = std::hypot(to[Axis::X] - from[Axis::X], to[Axis::Z] - from[Axis::Z]);
  ctx.output().start_speed_feed_synch(0, dz > 0 ? lead * length / dz : lead, false);
  ctx.straight(false, to);
}

void cut_thread(ExecContext& ctx, const Thread& t) {
  const std::vector<double> depths = thread_depths(t);
  if (depths.empty())
    ctx.error(ErrorCode::LimitRepeatCount, fmt::format("G76 would need more than {} passes", kMaxPasses));
  const double side = sign(t.x0 - t.x_end);  // +1: outside (external thread)
  const double dir = sign(t.z_end - t.z0);
  const double flank = std::tan(t.half_angle_deg * kPi / 180.0);
  Pose at = ctx.state().position.current;
  for (const double depth : depths) {
    const double x_end = t.x_end + side * (t.height - depth);
    const double z_start = t.z0 + dir * depth * flank;  // infeed along the flank
    ctx.straight(true, xz(at, t.x0, z_start));
    const Pose start = xz(at, x_end + t.taper, z_start);
    ctx.straight(true, start);
    ctx.output().disable_feed_override();
    const double chamfer = std::min(t.chamfer, std::fabs(t.z_end - z_start));
    if (chamfer > 0) {
      const double f = 1.0 - chamfer / std::fabs(t.z_end - z_start);
      const Pose before = xz(at, x_end + t.taper * (1.0 - f), t.z_end - dir * chamfer);
      synchronised(ctx, start, before, t.lead);
      synchronised(ctx, before, xz(at, x_end + side * chamfer, t.z_end), t.lead);
    } else {
      synchronised(ctx, start, xz(at, x_end, t.z_end), t.lead);
    }
    ctx.output().stop_speed_feed_synch();
    ctx.straight(true, xz(at, t.x0, ctx.state().position.current[Axis::Z]));
    ctx.output().enable_feed_override();
    at = ctx.state().position.current;
  }
  ctx.straight(true, xz(at, t.x0, t.z0));
}

// G76: P(mmrraa) Q(dmin) R(d) in the first block; X/U Z/W R(taper) P(height) Q(first depth)
// F(lead) in the second. Haas: X Z K(height) D(first depth) F I(taper) A(angle) in one.
class FanucThreading final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupMotion, 0, false, true}; }
  void execute(ExecContext& ctx, const Block& b, int code) override {
    require_lathe(ctx, code);
    FanucCycleSettings& set = ctx.state().fanuc.cycles;
    const bool haas = b.has('k') || b.has('d');
    if (!haas && !b.any_axis()) {
      // The first block: settings for the threads that follow.
      if (b.has('p')) {
        const int p = round_to_int(b.get('p'));
        set.thread_finish_passes = p / 10000;
        set.thread_chamfer = (p / 100) % 100 / 10.0;
        set.thread_angle_deg = p % 100;
      }
      if (b.has('q')) set.thread_min_depth = length_word(ctx, b, 'q');
      if (b.has('r')) set.thread_allowance = b.get('r');
      return;
    }
    const Pose& cur = ctx.state().position.current;
    const Pose end = ctx.end_point(b);
    Thread t{};
    t.x0 = cur[Axis::X];
    t.z0 = cur[Axis::Z];
    t.x_end = end[Axis::X];
    t.z_end = end[Axis::Z];
    t.lead = b.has('f') ? b.get('f') : 0.0;
    if (haas) {
      t.height = b.has('k') ? b.get('k') : 0.0;
      t.first_depth = b.has('d') ? b.get('d') : 0.0;
      t.taper = b.has('i') ? b.get('i') : 0.0;
      t.half_angle_deg = b.has('a') ? b.get('a') / 2.0 : 0.0;
      t.finish_passes = 1;
    } else {
      t.height = b.has('p') ? length_word(ctx, b, 'p') : 0.0;
      t.first_depth = b.has('q') ? length_word(ctx, b, 'q') : 0.0;
      t.taper = b.has('r') ? b.get('r') : 0.0;
      t.half_angle_deg = set.thread_angle_deg / 2.0;
      t.min_depth = set.thread_min_depth;
      t.allowance = set.thread_allowance;
      t.finish_passes = set.thread_finish_passes;
      t.chamfer = set.thread_chamfer * t.lead;
    }
    const char* h = haas ? "K" : "P";
    const char* q = haas ? "D" : "Q";
    if (t.lead <= 0) ctx.error(ErrorCode::FanucCycleWordMissing, "G76 needs F (the lead)");
    if (t.height <= 0)
      ctx.error(ErrorCode::FanucCycleWordMissing, fmt::format("G76 needs {} (the thread height)", h));
    if (t.first_depth <= 0)
      ctx.error(ErrorCode::FanucCycleWordMissing,
                fmt::format("G76 needs {} (the depth of the first cut)", q));
    if (t.allowance >= t.height && t.allowance > 0)
      ctx.error(ErrorCode::FanucCycleWordValue,
                "G76 R (finishing allowance) must be less than the thread height");
    if (t.z_end == t.z0)
      ctx.error(ErrorCode::FanucCycleWordMissing, "G76 needs a Z (or W) end different from the start");
    if (t.x_end == t.x0)
      ctx.error(ErrorCode::FanucCycleWordValue,
                "G76 must start outside (or inside) the thread's root diameter");
    if (ctx.state().modal.spindle == canon::SpindleDirection::Stopped)
      ctx.error(ErrorCode::SpindleStopped, "G76 needs the spindle turning (M3 or M4)");
    cut_thread(ctx, t);
  }
};

// Plain data of one grooving job, in radius coordinates.
struct Groove {
  double x0, z0, x_end, z_end;
  double peck;     // X depth per peck (0: one plunge)
  double step;     // Z distance between plunges
  double retract;  // rapid back after each peck
};

void cut_grooves(ExecContext& ctx, const Groove& g) {
  const double xdir = sign(g.x_end - g.x0), zdir = sign(g.z_end - g.z0);
  const double width = std::fabs(g.z_end - g.z0);
  if (width > 0 && g.step <= 0)
    ctx.error(ErrorCode::FanucCycleWordMissing, "G75 with a Z end needs the step between plunges (Q or K)");
  const double plunges = width > 0 ? std::ceil(width / g.step - 1e-9) : 0;
  const double depth = std::fabs(g.x_end - g.x0);
  const double pecks = g.peck > 0 ? std::ceil(depth / g.peck - 1e-9) : 1;
  if (plunges > kMaxPasses || pecks > kMaxPasses)
    ctx.error(ErrorCode::LimitRepeatCount,
              fmt::format("G75 would need more than {} plunges or pecks", kMaxPasses));
  Pose at = ctx.state().position.current;
  for (int j = 0; j <= static_cast<int>(plunges); ++j) {
    const double z = j == static_cast<int>(plunges) ? g.z_end : g.z0 + zdir * g.step * j;
    if (j > 0) ctx.straight(true, xz(at, g.x0, z));
    for (int k = 1; k <= static_cast<int>(pecks); ++k) {
      const double x = k == static_cast<int>(pecks) ? g.x_end : g.x0 + xdir * g.peck * k;
      ctx.straight(false, xz(at, x, z));
      if (k < static_cast<int>(pecks) && g.retract > 0)
        ctx.straight(true, xz(at, x - xdir * std::min(g.retract, g.peck), z));
    }
    ctx.straight(true, xz(at, g.x0, z));
  }
  ctx.straight(true, xz(at, g.x0, g.z0));
}

// G75: R(e) in the first block; X/U Z/W P(peck) Q(step) F in the second. Haas: X Z I(peck)
// K(step) F in one.
class FanucGrooving final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupMotion, 0, false, true}; }
  void execute(ExecContext& ctx, const Block& b, int code) override {
    require_lathe(ctx, code);
    FanucCycleSettings& set = ctx.state().fanuc.cycles;
    const bool haas = b.has('i') || b.has('k');
    if (!haas && !b.any_axis()) {
      if (b.has('r')) set.groove_retract = b.get('r');
      return;
    }
    if (ctx.state().modal.feed_rate <= 0)
      ctx.error(ErrorCode::FeedZero, "G75 with zero feed rate (program an F word)");
    const Pose& cur = ctx.state().position.current;
    const Pose end = ctx.end_point(b);
    Groove g{};
    g.x0 = cur[Axis::X];
    g.z0 = cur[Axis::Z];
    g.x_end = end[Axis::X];
    g.z_end = end[Axis::Z];
    g.peck = haas ? (b.has('i') ? b.get('i') : 0.0) : (b.has('p') ? length_word(ctx, b, 'p') : 0.0);
    g.step = haas ? (b.has('k') ? b.get('k') : 0.0) : (b.has('q') ? length_word(ctx, b, 'q') : 0.0);
    // Without a programmed retract, back off a quarter of the peck to break the chip.
    g.retract = set.groove_retract > 0 ? set.groove_retract : g.peck / 4.0;
    cut_grooves(ctx, g);
  }
};

}  // namespace

double length_word(ExecContext& ctx, const Block& b, char letter) {
  const double v = b.get(letter);
  if ((b.decimal & (1u << (letter - 'a'))) != 0) return v;
  return v * (ctx.state().modal.units == canon::Units::Inch ? 0.0001 : 0.001);
}

void require_lathe(ExecContext& ctx, int code) {
  if (ctx.options().machine != MachineKind::Lathe)
    ctx.error(
        ErrorCode::Unsupported,
        fmt::format(
            "G{} is a Fanuc lathe cycle (on a Fanuc mill it is a canned cycle this controller does not have)",
            code / 10));
}

void add_fanuc_lathe_cycles(Extensions& ext) {
  ext.g[750] = std::make_shared<FanucGrooving>();
  ext.g[760] = std::make_shared<FanucThreading>();
}

}  // namespace opencnc::gcode
