// SPDX-License-Identifier: GPL-3.0-or-later
// Canned cycles G73 G74 G81-G89: one cycle block resolved from its words and the sticky
// state, then expanded into canonical moves as LinuxCNC 2.9 expands it.
#include "opencnc/gcode/canned_cycles.hpp"

#include <cmath>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::gcode {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The axes of a cycle plane as Pose indices: the two in-plane axes (where the holes are) and
// the drilling axis, in LinuxCNC's order (G18: Z, X, then Y drills; G19: Y, Z, then X).
struct PlaneAxes {
  int a = 0, b = 1, c = 2;
  const char* name = "XY";
  bool uvw = false;
};

PlaneAxes axes_of(canon::Plane p) noexcept {
  const canon::PlaneAxes x = canon::plane_axes(p);
  return {x.first, x.second, x.normal, canon::plane_name(p), canon::plane_base(p) != 0};
}

char word_letter(int axis) noexcept { return "xyzabcuvw"[axis]; }
char upper(char c) noexcept { return static_cast<char>(c - 'a' + 'A'); }
// The G87 word for an axis: I for X and U, J for Y and V, K for Z and W.
char g87_letter(int axis) noexcept { return "ijk"[axis % 3]; }

// One cycle block with every value resolved (absolute positions, program units).
struct CycleBlock {
  int code = 810;
  PlaneAxes ax;
  Pose base{};              // the position before the block: the other axes stay there
  double aa = 0, bb = 0;    // hole position before the first repeat's increment
  double aa_inc = 0, bb_inc = 0, radius_inc = 0, theta_inc = 0;   // G91 increments per repeat
  double r = 0;             // R plane
  double r_word = 0, bottom_word = 0;   // R and bottom as programmed (what carries over)
  double bottom = 0;        // bottom of the hole
  double clear = 0;         // retract height (G98: initial level or R, G99: R)
  double current_cc = 0;    // drilling-axis position when the first hole is approached
  int repeats = 1;
  double dwell = 0;         // G74 G82 G84 G86 G88 G89
  double peck = 0;          // G73 G83
  double rapid_delta = 0;   // G73 G83: how far above the last peck the drill comes back
  double offset_a = 0, offset_b = 0, middle = 0;   // G87: offset in the plane, top of the bore
  canon::SpindleDirection spindle = canon::SpindleDirection::Stopped;
};

// Writes the moves of one cycle block: every point is (a, b, c) in the cycle plane, the other
// axes stay where the block started.
class CycleMoves {
 public:
  CycleMoves(ExecContext& ctx, const CycleBlock& cb) : ctx_(ctx), cb_(cb) {}
  void traverse(double a, double b, double c) { ctx_.straight(true, at(a, b, c)); }
  void feed(double a, double b, double c) { ctx_.straight(false, at(a, b, c)); }
  canon::Sink& out() { return ctx_.output(); }
  ExecContext& ctx() { return ctx_; }

 private:
  Pose at(double a, double b, double c) const {
    Pose p = cb_.base;
    p[cb_.ax.a] = a;
    p[cb_.ax.b] = b;
    p[cb_.ax.c] = c;
    return p;
  }
  ExecContext& ctx_;
  const CycleBlock& cb_;
};

// Cycles run in exact-path mode; the caller's path mode and naive-CAM tolerance come back
// afterwards, as LinuxCNC restores them.
struct PathMode {
  canon::MotionControl mode = canon::MotionControl::Continuous;
  double tolerance = 0;
  double naivecam = 0;
};

PathMode enter_exact_path(ExecContext& ctx) {
  const ModalState& m = ctx.state().modal;
  const PathMode saved{m.control, m.path_tolerance, m.naivecam_tolerance};
  if (saved.mode != canon::MotionControl::ExactPath) ctx.output().set_motion_control_mode(canon::MotionControl::ExactPath, 0);
  return saved;
}

void restore_path_mode(ExecContext& ctx, const PathMode& saved) {
  if (saved.mode == canon::MotionControl::ExactPath) return;
  ctx.output().set_motion_control_mode(saved.mode, saved.tolerance);
  ctx.output().set_naivecam_tolerance(saved.naivecam);
}

void start_spindle(canon::Sink& out, canon::SpindleDirection dir) {
  if (dir == canon::SpindleDirection::Clockwise) out.start_spindle_clockwise(0);
  else out.start_spindle_counterclockwise(0);
}

// The direction as LinuxCNC's CANON_DIRECTION value, which its G87 hands to ORIENT_SPINDLE.
int canon_direction(canon::SpindleDirection dir) noexcept { return dir == canon::SpindleDirection::Clockwise ? 2 : 3; }

void require_turning(CycleMoves& m, const CycleBlock& cb) {
  if (cb.spindle == canon::SpindleDirection::Stopped)
    m.ctx().error(ErrorCode::SpindleStopped, fmt::format("G{} needs the spindle turning (M3 or M4)", cb.code / 10));
}

// --- one hole, starting at the R plane above it -------------------------------------------

// G73 (chip breaking: back off a little after each peck) and G83 (back out to R after each
// peck). The depths are stepped by repeated subtraction, as LinuxCNC steps them, so that the
// number of pecks agrees to the last bit.
void peck_hole(CycleMoves& m, const CycleBlock& cb, double a, double b) {
  if (cb.peck <= 0.0) m.ctx().error(ErrorCode::CycleQNotPositive, "the peck increment Q must be greater than 0");
  for (double depth = cb.r - cb.peck; depth > cb.bottom; depth = depth - cb.peck) {
    m.feed(a, b, depth);
    if (cb.code == 830) m.traverse(a, b, cb.r);
    m.traverse(a, b, depth + cb.rapid_delta);
  }
  m.feed(a, b, cb.bottom);
  m.traverse(a, b, cb.clear);
}

// The feed of a tap in and out, with the coordinates in the order LinuxCNC 2.9 gives them:
// in G18 and G19 its G74/G84 hand (a, b, c) to the plane's mapping rotated by one place. In
// G18 a hole at Z3 X1 tapped to Y-2 is fed to X-2 Y3 Z1, in G19 a hole at Y1 Z3 tapped to X-2
// to X3 Y-2 Z1: sideways moves that rs274 prints and LinuxCNC's motion runs. opencnc follows
// LinuxCNC here (issue 6); docs/cycles.md says so.
void tap_feed(CycleMoves& m, const CycleBlock& cb, double a, double b, double c) {
  switch (cb.ax.c) {
    case 0:  // G19: drilling along X
      m.feed(c, a, b);
      return;
    case 1:  // G18: drilling along Y
      m.feed(b, c, a);
      return;
    default:
      m.feed(a, b, c);
      return;
  }
}

// G84 (right hand) and G74 (left hand) floating-chuck tapping: feed in with the overrides off,
// reverse the spindle, dwell, feed out, restore the spindle direction and the overrides.
void tap_hole(CycleMoves& m, const CycleBlock& cb, const ModalState& modal, double a, double b) {
  const bool right = cb.code == 840;
  if (cb.spindle == canon::SpindleDirection::Stopped)
    m.ctx().error(ErrorCode::SpindleStopped, fmt::format("G{} needs the spindle turning", right ? 84 : 74));
  if (right && cb.spindle != canon::SpindleDirection::Clockwise)
    m.ctx().error(ErrorCode::SpindleWrongDirection, "G84 taps right-hand threads: the spindle must turn clockwise (M3)");
  if (!right && cb.spindle != canon::SpindleDirection::Counterclockwise)
    m.ctx().error(ErrorCode::SpindleWrongDirection, "G74 taps left-hand threads: the spindle must turn counterclockwise (M4)");
  if (cb.ax.uvw)
    m.ctx().error(ErrorCode::CycleTappingPlane, fmt::format("G{} cannot tap in the {} plane", right ? 84 : 74, cb.ax.name));
  canon::Sink& out = m.out();
  out.disable_feed_override();
  out.disable_speed_override(0);
  tap_feed(m, cb, a, b, cb.bottom);
  out.stop_spindle_turning(0);
  start_spindle(out, right ? canon::SpindleDirection::Counterclockwise : canon::SpindleDirection::Clockwise);
  out.dwell(cb.dwell);
  tap_feed(m, cb, a, b, cb.clear);
  out.stop_spindle_turning(0);
  start_spindle(out, cb.spindle);
  if (modal.feed_override) out.enable_feed_override();
  if (modal.speed_override) out.enable_speed_override(0);
}

// G87 back boring: in at the offset with the spindle oriented and stopped, over to the hole at
// the bottom, bore up to the middle and back down, then out the same way.
void back_bore_hole(CycleMoves& m, const CycleBlock& cb, double a, double b) {
  require_turning(m, cb);
  canon::Sink& out = m.out();
  const double oa = a + cb.offset_a, ob = b + cb.offset_b;
  const int dir = canon_direction(cb.spindle);
  m.traverse(oa, ob, cb.r);
  out.stop_spindle_turning(0);
  out.orient_spindle(0, 0.0, dir);
  m.traverse(oa, ob, cb.bottom);
  m.traverse(a, b, cb.bottom);
  start_spindle(out, cb.spindle);
  m.feed(a, b, cb.middle);
  m.feed(a, b, cb.bottom);
  out.stop_spindle_turning(0);
  out.orient_spindle(0, 0.0, dir);
  m.traverse(oa, ob, cb.bottom);
  m.traverse(oa, ob, cb.clear);
  m.traverse(a, b, cb.clear);
  start_spindle(out, cb.spindle);
}

void hole(CycleMoves& m, const CycleBlock& cb, const ModalState& modal, double a, double b) {
  canon::Sink& out = m.out();
  switch (cb.code) {
    case 810:   // drill
      m.feed(a, b, cb.bottom);
      m.traverse(a, b, cb.clear);
      return;
    case 820:   // drill, dwell at the bottom
      m.feed(a, b, cb.bottom);
      out.dwell(cb.dwell);
      m.traverse(a, b, cb.clear);
      return;
    case 730:
    case 830:
      peck_hole(m, cb, a, b);
      return;
    case 740:
    case 840:
      tap_hole(m, cb, modal, a, b);
      return;
    case 850:   // bore, feed out to R
      m.feed(a, b, cb.bottom);
      m.feed(a, b, cb.r);
      m.traverse(a, b, cb.clear);
      return;
    case 860:   // bore, dwell, stop the spindle, rapid out
      require_turning(m, cb);
      m.feed(a, b, cb.bottom);
      out.dwell(cb.dwell);
      out.stop_spindle_turning(0);
      m.traverse(a, b, cb.clear);
      start_spindle(out, cb.spindle);
      return;
    case 870:
      back_bore_hole(m, cb, a, b);
      return;
    case 880:   // bore, dwell, stop: the operator retracts by hand
      require_turning(m, cb);
      m.feed(a, b, cb.bottom);
      out.dwell(cb.dwell);
      out.stop_spindle_turning(0);
      out.program_stop();
      {
        SyncValues stop;  // the operator retracts by hand: the interpreter waits for the go-on
        stop.kind = SyncKind::ProgramStop;
        m.ctx().request_sync(stop);
      }
      start_spindle(out, cb.spindle);
      return;
    case 890:   // bore, dwell, feed out
      m.feed(a, b, cb.bottom);
      out.dwell(cb.dwell);
      m.feed(a, b, cb.clear);
      return;
    default:
      return;
  }
}

// --- resolving the block -------------------------------------------------------------------

// Checks that hold for every cycle before its words are read.
void check_modes(ExecContext& ctx, int code) {
  const ModalState& m = ctx.state().modal;
  if (m.feed_rate == 0.0) ctx.error(ErrorCode::FeedZero, fmt::format("G{} with zero feed rate (program an F word)", code / 10));
  if (m.feed_mode == canon::FeedMode::InverseTime)
    ctx.error(ErrorCode::CycleInverseTime, "canned cycles cannot run in inverse-time feed mode (G93)");
  if (m.cutter_comp != CutterComp::Off)
    ctx.error(ErrorCode::CompCannedCycle, "canned cycles cannot run while cutter compensation is on (G40 first)");
}

// Axis words of the other set (U V W in the XYZ planes, X Y Z in the UVW planes).
void check_plane_words(ExecContext& ctx, const Block& b, const PlaneAxes& ax) {
  const int first = ax.uvw ? 0 : 6;
  for (int axis = first; axis < first + 3; ++axis) {
    const char w = word_letter(axis);
    if (b.has(w))
      ctx.error(ErrorCode::CycleRotaryAxis,
                fmt::format("{} word in a canned cycle in the {} plane (the cycle cannot move that axis)", upper(w), ax.name));
  }
}

// Hole position, R and bottom of the block, in absolute coordinates; the first block of a run
// of cycles records the initial level (the G98 retract height and the base of a G91 R).
void resolve_geometry(ExecContext& ctx, const Block& b, bool same, CycleBlock& cb) {
  InterpState& st = ctx.state();
  const PlaneAxes& ax = cb.ax;
  const char la = word_letter(ax.a), lb = word_letter(ax.b), lc = word_letter(ax.c);
  if (!same && !b.has(lc)) {
    if (!ctx.options().axes.has(static_cast<Axis>(ax.c)))
      ctx.error(ErrorCode::CycleBottomMissing,
                fmt::format("canned cycles in the {} plane need a {} axis, which this machine does not have", ax.name, upper(lc)));
    ctx.error(ErrorCode::CycleBottomMissing,
              fmt::format("the first block of a canned cycle in the {} plane needs {} (the bottom)", ax.name, upper(lc)));
  }
  const double bottom_word = b.has(lc) ? b.get(lc) : st.cycle.bottom;
  cb.bottom_word = bottom_word;
  const Pose& cur = st.position.current;
  cb.current_cc = cur[ax.c];
  if (!st.cycle.initial_level_valid) {
    st.cycle.initial_level = cb.current_cc;
    st.cycle.initial_level_valid = true;
  }
  if (st.modal.distance == DistanceMode::Absolute) {
    cb.r = cb.r_word;
    cb.bottom = bottom_word;
    cb.aa = b.has(la) ? b.get(la) : cur[ax.a];
    cb.bb = b.has(lb) ? b.get(lb) : cur[ax.b];
    if (b.radius_flag || b.theta_flag) {   // polar words (G17 only)
      const double radius = b.radius_flag ? b.radius : std::hypot(cur[ax.b], cur[ax.a]);
      const double theta = b.theta_flag ? b.theta * kPi / 180.0 : std::atan2(cur[ax.b], cur[ax.a]);
      cb.aa = radius * std::cos(theta);
      cb.bb = radius * std::sin(theta);
    }
  } else {
    // G91: X and Y step each repeat, R is above the initial level, the bottom below R.
    cb.aa_inc = b.has(la) ? b.get(la) : 0.0;
    cb.bb_inc = b.has(lb) ? b.get(lb) : 0.0;
    cb.radius_inc = b.radius_flag ? b.radius : 0.0;
    cb.theta_inc = b.theta_flag ? b.theta * kPi / 180.0 : 0.0;
    cb.r = cb.r_word + st.cycle.initial_level;
    cb.bottom = cb.r + bottom_word;
    cb.aa = cur[ax.a];
    cb.bb = cur[ax.b];
  }
  if (cb.r < cb.bottom)
    ctx.error(ErrorCode::CycleRBelowBottom,
              fmt::format("the R plane ({:.4f}) is below the bottom of the cycle ({} {:.4f})", cb.r, upper(lc), cb.bottom));
}

// The words only some cycles use (P dwell, Q peck, G87 I J K), from the block or, while the
// same cycle stays active, from the sticky state. I J K carry over from here, P and Q once the
// block has run (LinuxCNC's order).
void resolve_cycle_words(ExecContext& ctx, const Block& b, bool same, CycleBlock& cb) {
  CycleState& sticky = ctx.state().cycle;
  const int code = cb.code;
  const double p = b.p_or(-1.0), q = b.q_or(-1.0);
  if (code == 820 || code == 860 || code == 880 || code == 890) {
    if (!same && p == -1.0) ctx.error(ErrorCode::CycleDwellMissing, fmt::format("G{} needs a P word (dwell in seconds)", code / 10));
    cb.dwell = p == -1.0 ? sticky.p : p;
  } else if (code == 740 || code == 840) {
    cb.dwell = p == -1.0 ? sticky.p : p;
  } else if (code == 730 || code == 830) {
    if (!same && q == -1.0) ctx.error(ErrorCode::CycleQMissing, fmt::format("G{} needs a Q word (peck increment)", code / 10));
    cb.peck = q == -1.0 ? sticky.q : q;
    cb.rapid_delta = 0.010;   // inch (LinuxCNC's G83_RAPID_DELTA)
    if (ctx.state().modal.units == canon::Units::Mm) cb.rapid_delta = cb.rapid_delta * 25.4;
  } else if (code == 870) {
    const char la = g87_letter(cb.ax.a), lb = g87_letter(cb.ax.b), lc = g87_letter(cb.ax.c);
    if (!same) {
      for (char w : {'i', 'j', 'k'}) {
        if (!b.has(w)) ctx.error(ErrorCode::CycleG87WordMissing, fmt::format("G87 needs I, J and K words ({} is missing)", upper(w)));
      }
    }
    for (char w : {'i', 'j', 'k'}) {
      double& v = w == 'i' ? sticky.i : w == 'j' ? sticky.j : sticky.k;
      if (b.has(w)) v = b.get(w);
    }
    auto value = [&](char w) { return w == 'i' ? sticky.i : w == 'j' ? sticky.j : sticky.k; };
    cb.offset_a = value(la);
    cb.offset_b = value(lb);
    // The top of the bore is absolute in G90, above the bottom in G91.
    cb.middle = value(lc);
    if (ctx.state().modal.distance == DistanceMode::Incremental) cb.middle = cb.bottom + cb.middle;
  }
}

// Adds one repeat's G91 step to the hole position; polar steps turn or stretch the radius.
void step_hole(ExecContext& ctx, const CycleBlock& cb, double& a, double& b) {
  a = a + cb.aa_inc;
  b = b + cb.bb_inc;
  if (cb.radius_inc != 0.0) {
    if (a == 0 && b == 0) ctx.error(ErrorCode::PolarAtOrigin, "incremental polar motion is undefined at the origin");
    const double theta = std::atan2(b, a);
    const double radius = std::hypot(b, a) + cb.radius_inc;
    a = radius * std::cos(theta);
    b = radius * std::sin(theta);
  }
  if (cb.theta_inc != 0.0) {
    if (a == 0 && b == 0) ctx.error(ErrorCode::PolarAtOrigin, "incremental polar motion is undefined at the origin");
    const double theta = std::atan2(b, a) + cb.theta_inc;
    const double radius = std::hypot(b, a);
    a = radius * std::cos(theta);
    b = radius * std::sin(theta);
  }
}

class CannedCycle final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& block, int code) override;
};

void CannedCycle::execute(ExecContext& ctx, const Block& block, int code) {
  check_modes(ctx, code);
  InterpState& st = ctx.state();
  const bool same = st.modal.motion == code;
  CycleBlock cb;
  cb.code = code;
  cb.ax = axes_of(st.modal.plane);
  cb.base = st.position.current;
  cb.spindle = st.modal.spindle;
  if (!block.has('r') && !same) ctx.error(ErrorCode::CycleRMissing, "a canned cycle needs an R word (the R plane) in its first block");
  cb.r_word = block.has('r') ? block.get('r') : st.cycle.r;
  if (block.has('l') && block.get('l') == 0) ctx.error(ErrorCode::CycleRepeatZero, "L0: a canned cycle must run at least once");
  cb.repeats = block.has('l') ? static_cast<int>(block.get('l')) : 1;
  check_plane_words(ctx, block, cb.ax);
  resolve_geometry(ctx, block, same, cb);

  // Below the R plane: straight up to it first (LinuxCNC keeps the initial level itself).
  double old_cc = st.cycle.initial_level;
  CycleMoves moves(ctx, cb);
  if (old_cc < cb.r) {
    Pose up = st.position.current;
    up[cb.ax.c] = cb.r;
    ctx.straight(true, up);
    old_cc = cb.r;
    cb.current_cc = old_cc;
  }
  cb.clear = st.modal.retract == RetractMode::RPlane ? cb.r : old_cc;

  const PathMode saved = enter_exact_path(ctx);
  resolve_cycle_words(ctx, block, same, cb);
  const ModalState& modal = st.modal;
  double a = cb.aa, b = cb.bb;
  for (int repeat = cb.repeats; repeat > 0; --repeat) {
    step_hole(ctx, cb, a, b);
    // The first hole is approached at the height the tool is at; the others at the retract
    // height. Either way the tool then goes down to R.
    if (repeat == cb.repeats && cb.current_cc > cb.r) {
      moves.traverse(a, b, cb.current_cc);
      moves.traverse(a, b, cb.r);
    } else {
      moves.traverse(a, b, cb.clear);
      if (cb.clear > cb.r) moves.traverse(a, b, cb.r);
    }
    hole(moves, cb, modal, a, b);
  }
  Pose& cur = st.position.current;
  cur[cb.ax.a] = a;
  cur[cb.ax.b] = b;
  cur[cb.ax.c] = cb.clear;   // also after G88, whose retract is left to the operator
  restore_path_mode(ctx, saved);
  CycleState& sticky = st.cycle;
  sticky.r = cb.r_word;
  sticky.bottom = cb.bottom_word;
  if (code == 730 || code == 830) sticky.q = cb.peck;
  if (code == 740 || code == 840 || code == 820 || code == 860 || code == 880 || code == 890) sticky.p = cb.dwell;
  st.modal.motion = code;
}

}  // namespace

void add_canned_cycles(Extensions& ext) {
  auto cycle = std::make_shared<CannedCycle>();
  for (int code : {730, 740, 810, 820, 830, 840, 850, 860, 870, 880, 890}) ext.g[static_cast<std::size_t>(code)] = cycle;
}

}  // namespace opencnc::gcode
