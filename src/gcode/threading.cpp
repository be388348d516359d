// SPDX-License-Identifier: GPL-3.0-or-later
// G33 spindle-synchronised moves, G33.1 rigid tapping and the G76 multi-pass threading cycle,
// expanded into canonical calls as LinuxCNC 2.9 expands them.
#include "opencnc/gcode/threading.hpp"

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include <fmt/format.h>

namespace opencnc::gcode {

namespace {

constexpr long double kPiL = 3.141592653589793238462643383279502884L;

// Checks every spindle-synchronised code makes before it moves.
void check_spindle(ExecContext& ctx, const Block& b, int code) {
  const ModalState& m = ctx.state().modal;
  const char* name = code == 330 ? "G33" : code == 331 ? "G33.1" : "G76";
  if (m.cutter_comp != CutterComp::Off && m.comp_radius > 0.0)
    ctx.error(ErrorCode::CompSpindleSync, fmt::format("{} cannot run while cutter compensation is on (G40 first)", name));
  if (b.dollar_flag && (b.dollar < 0 || b.dollar >= 1))
    ctx.error(ErrorCode::SpindleNumber, fmt::format("{} with spindle ${}: this machine has spindle 0 only", name, b.dollar));
  if (m.spindle == canon::SpindleDirection::Stopped)
    ctx.error(ErrorCode::SpindleStopped, fmt::format("{} needs the spindle turning (M3 or M4)", name));
}

// G33: one straight move locked to the spindle, K units per revolution.
class ThreadMove final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    check_spindle(ctx, b, code);
    ctx.state().modal.motion = code;
    const Pose end = ctx.end_point(b);
    ctx.output().start_speed_feed_synch(0, b.get('k'), false);
    ctx.straight(false, end);
    ctx.output().stop_speed_feed_synch();
  }
};

// G33.1: the machine taps to the end point at pitch K, reverses the spindle (I scales the
// speed out) and comes back, so X, Y and Z end where they started.
class RigidTap final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    check_spindle(ctx, b, code);
    InterpState& st = ctx.state();
    st.modal.motion = code;
    const Pose end = ctx.end_point(b);
    ctx.output().start_speed_feed_synch(0, b.get('k'), false);
    ctx.output().rigid_tap(0, end, b.has('i') ? b.get('i') : 1.0);
    ctx.output().stop_speed_feed_synch();
    // The tap does not move the other axes, yet LinuxCNC records their end as reached: a
    // following move starts from there.
    for (int axis = 3; axis < kAxisCount; ++axis) st.position.current[axis] = end[axis];
  }
};

// The geometry of a G76 cycle in the XZ plane, as LinuxCNC derives it from the words: X
// depths are measured from the start (the drive line), positive into the work for boring.
struct ThreadPlan {
  bool boring = false;          // I > 0: internal thread
  double safe_x = 0;            // the start X, where every pass returns
  double start_y = 0, start_z = 0, target_z = 0;
  double full_dia_depth = 0;    // |I|: from the drive line to the crest
  double cut_increment = 0;     // |J|: first pass depth
  double full_threadheight = 0; // |K|
  double end_depth = 0;         // |I| + |K|
  double pitch = 0, taper_pitch = 0, taper_dist = 0;
  double compound = 0;          // Q in radians, signed by the direction of the cut
  double degression = 1;        // R
  int spring_cuts = 0;          // H
  bool entry_taper = false, exit_taper = false;   // L bits 1 and 2
  Pose other{};                 // the axes G76 does not move
};

ThreadPlan plan_thread(ExecContext& ctx, const Block& b, const Pose& end) {
  const InterpState& st = ctx.state();
  ThreadPlan t;
  const Pose& cur = st.position.current;
  double i = b.get('i'), j = b.get('j'), k = b.get('k');
  if (st.modal.lathe_diameter) {   // I J K are diameters too
    i /= 2;
    j /= 2;
    k /= 2;
  }
  t.boring = i > 0.0;
  t.safe_x = cur[0];
  t.start_y = cur[1];
  t.start_z = cur[2];
  t.full_dia_depth = std::fabs(i);
  t.cut_increment = std::fabs(j);
  t.full_threadheight = std::fabs(k);
  t.end_depth = std::fabs(k) + std::fabs(i);
  t.pitch = b.get('p');
  double compound = b.q_or(-1.0);
  if (compound == -1) compound = 0;
  compound = static_cast<double>(compound * (kPiL / 180.0L));
  if (end[2] > t.start_z) compound = -compound;
  t.compound = compound;
  t.spring_cuts = b.has('h') ? static_cast<int>(b.get('h')) : 0;
  t.degression = b.has('r') ? b.get('r') : 1.0;
  if (t.degression < 1.0) t.degression = 1.0;
  t.taper_dist = b.has('e') ? b.get('e') : 0.0;
  if (t.taper_dist < 0.0) t.taper_dist = 0.0;
  t.taper_pitch = t.taper_dist > 0.0 ? t.pitch * std::hypot(t.taper_dist, t.full_threadheight) / t.taper_dist : t.pitch;
  if (end[2] > t.start_z) t.taper_dist = -t.taper_dist;
  const int flags = b.has('l') ? static_cast<int>(b.get('l')) : 0;
  t.entry_taper = (flags & 1) != 0;
  t.exit_taper = (flags & 2) != 0;
  t.target_z = end[2] + std::fabs(k) * std::tan(t.compound);
  t.other = cur;
  return t;
}

// One pass at `depth`, shifted back along Z by `zoff` (the compound infeed): in, cut along
// the thread with optional entry and exit tapers, out, with the feed override off while cutting.
void threading_pass(ExecContext& ctx, const ThreadPlan& t, double depth, double zoff) {
  canon::Sink& out = ctx.output();
  auto at = [&](double x, double z) {
    Pose p = t.other;
    p[0] = x;
    p[1] = t.start_y;
    p[2] = z;
    return p;
  };
  // X at a depth below the drive line (outwards for a boring bar).
  auto x_at = [&](double d) { return t.boring ? t.safe_x + d : t.safe_x - d; };
  const double back = t.boring ? t.safe_x + depth - t.end_depth : t.safe_x - depth + t.end_depth;
  const double crest = t.boring ? t.safe_x + depth - t.full_threadheight : t.safe_x - depth + t.full_threadheight;
  ctx.straight(true, at(back, t.start_z - zoff));
  if (t.taper_dist != 0.0 && t.entry_taper) {
    out.disable_feed_override();
    out.start_speed_feed_synch(0, t.taper_pitch, false);
    ctx.straight(false, at(crest, t.start_z - zoff));
    ctx.straight(false, at(x_at(depth), t.start_z - zoff - t.taper_dist));
    out.start_speed_feed_synch(0, t.pitch, false);
  } else {
    ctx.straight(true, at(x_at(depth), t.start_z - zoff));
    out.disable_feed_override();
    out.start_speed_feed_synch(0, t.pitch, false);
  }
  if (t.taper_dist != 0.0 && t.exit_taper) {
    ctx.straight(false, at(x_at(depth), t.target_z - zoff + t.taper_dist));
    out.start_speed_feed_synch(0, t.taper_pitch, false);
    ctx.straight(false, at(crest, t.target_z - zoff));
  } else {
    ctx.straight(false, at(x_at(depth), t.target_z - zoff));
  }
  out.stop_speed_feed_synch();
  ctx.straight(true, at(back, t.target_z - zoff));
  out.enable_feed_override();
}

// G76: passes of decreasing depth of cut (depth_n = |I| + |J| n^(1/R)) until the full depth
// |I| + |K|, then the final pass and H spring passes at full depth; each pass starts further
// back in Z by the depth times tan(Q), so that the tool cuts on one flank only.
class ThreadCycle final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    check_spindle(ctx, b, code);
    InterpState& st = ctx.state();
    st.modal.motion = code;
    const Pose end = ctx.end_point(b);
    for (int axis = 3; axis < kAxisCount; ++axis) {
      if (end[axis] != st.position.current[axis])
        ctx.error(ErrorCode::ThreadG76RotaryAxis, "G76 moves only X and Z: remove the other axis words");
    }
    if (b.get('i') == 0) ctx.error(ErrorCode::ThreadG76Word, "G76 needs a non-zero I (thread crest from the drive line)");
    if (b.get('j') <= 0) ctx.error(ErrorCode::ThreadG76Word, "G76 needs J greater than 0 (depth of the first pass)");
    if (b.get('k') <= b.get('j'))
      ctx.error(ErrorCode::ThreadG76Depth, "G76 needs K (full thread depth) greater than J (first pass)");
    const ThreadPlan t = plan_thread(ctx, b, end);
    double depth = t.full_dia_depth + t.cut_increment;
    // A huge R makes the depth grow too slowly to end: the segment limit stops such a cycle,
    // and the pass count is 64-bit so that it cannot overflow before.
    std::int64_t pass = 1;
    while (depth < t.end_depth) {
      threading_pass(ctx, t, depth, (depth - t.full_dia_depth) * std::tan(t.compound));
      depth = t.full_dia_depth + t.cut_increment * std::pow(static_cast<double>(++pass), 1.0 / t.degression);
    }
    depth = t.end_depth;
    for (std::int64_t i = 0; i <= t.spring_cuts; ++i)
      threading_pass(ctx, t, depth, (depth - t.full_dia_depth) * std::tan(t.compound));
    ctx.straight(true, end);
  }
};

}  // namespace

void add_threading(Extensions& ext) {
  ext.g[330] = std::make_shared<ThreadMove>();
  ext.g[331] = std::make_shared<RigidTap>();
  ext.g[760] = std::make_shared<ThreadCycle>();
}

}  // namespace opencnc::gcode
