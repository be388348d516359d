// SPDX-License-Identifier: GPL-3.0-or-later
// G5, G5.1, G5.2 and G5.3 with LinuxCNC's rules: every curve becomes one NURBS_FEED whose
// control points start at the current position (weights 1 for G5/G5.1).
#include "opencnc/gcode/splines.hpp"

#include <array>
#include <memory>
#include <string>

namespace opencnc::gcode {

namespace {

void require_feed(ExecContext& ctx, const Block& b, const char* what) {
  const ModalState& m = ctx.state().modal;
  if (m.feed_mode == canon::FeedMode::UnitsPerMinute && m.feed_rate == 0.0)
    ctx.error(ErrorCode::FeedZero, std::string(what) + " with zero feed rate (program an F word)");
  if (m.feed_mode == canon::FeedMode::InverseTime && !b.has('f'))
    ctx.error(ErrorCode::InverseTimeFeedMissing, std::string(what) + " in inverse time mode (G93) needs an F word");
}

void emit(ExecContext& ctx, int order, std::span<const canon::NurbsPoint> points) {
  ctx.output().nurbs_feed(0, order, points);
  Pose& at = ctx.state().position.current;
  at[0] = points.back().x;
  at[1] = points.back().y;
}

// G5 (cubic: I J to the first control point from the start, P Q to the second from the end)
// and G5.1 (quadratic: I J to the single control point). Neither changes the motion mode.
class Spline final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    InterpState& st = ctx.state();
    if (st.modal.cutter_comp != CutterComp::Off)
      ctx.error(ErrorCode::SplineCompensation, "splines cannot be programmed while cutter compensation is on");
    require_feed(ctx, b, "spline");
    if (st.modal.plane != canon::Plane::XY) ctx.error(ErrorCode::SplinePlane, "splines work only in the XY plane (G17)");
    if (b.has('z') || b.has('a') || b.has('b') || b.has('c'))
      ctx.error(ErrorCode::SplineAxes, "a spline moves X and Y only (no Z, A, B or C words)");
    const double x0 = st.position.current[0], y0 = st.position.current[1];
    if (code == 51) {
      if (!b.has('i') || !b.has('j')) ctx.error(ErrorCode::SplineWords, "G5.1 needs both I and J");
      const Pose end = ctx.end_point(b);
      const std::array<canon::NurbsPoint, 3> p{{{x0, y0, 1}, {x0 + b.get('i'), y0 + b.get('j'), 1}, {end[0], end[1], 1}}};
      emit(ctx, 3, p);
      return;
    }
    double i = st.spline.g5_i, j = st.spline.g5_j;   // continue tangentially from the last G5
    if (b.has('i') != b.has('j')) ctx.error(ErrorCode::SplineWords, "G5 needs both I and J, or neither");
    if (b.has('i')) i = b.get('i'), j = b.get('j');
    const Pose end = ctx.end_point(b);
    if (!b.has('p') || !b.has('q')) ctx.error(ErrorCode::SplineWords, "G5 needs both P and Q");
    const double p = b.get('p'), q = b.get('q');
    const std::array<canon::NurbsPoint, 4> pts{
        {{x0, y0, 1}, {x0 + i, y0 + j, 1}, {end[0] + p, end[1] + q, 1}, {end[0], end[1], 1}}};
    emit(ctx, 4, pts);
    st.spline.g5_i = -p;
    st.spline.g5_j = -q;
  }
};

// G5.2: one control point per block (X Y with weight P; a first block may give only P, the
// start point's weight; L > 3 sets the order). The points stay in the state until G5.3.
class NurbsPoints final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int) override {
    InterpState& st = ctx.state();
    auto& pts = st.spline.points;
    const bool x = b.has('x'), y = b.has('y');
    if (x != y) ctx.error(ErrorCode::NurbsPoint, "a G5.2 control point needs both X and Y");
    const double p = b.p_or(-1.0);
    // LinuxCNC checks against the points kept so far, before a new sequence clears them.
    if (!x && !y && p > 0 && !pts.empty())
      ctx.error(ErrorCode::NurbsWeight, "P without X and Y is only allowed for the first control point of G5.2");
    if (p <= 0 && !pts.empty()) ctx.error(ErrorCode::NurbsWeight, "every G5.2 control point needs a positive weight P");
    if (st.modal.feed_mode == canon::FeedMode::UnitsPerMinute && st.modal.feed_rate == 0.0)
      ctx.error(ErrorCode::FeedZero, "G5.2 with zero feed rate (program an F word)");
    if (st.modal.motion != 52) pts.clear();
    if (pts.empty()) {
      pts.push_back({st.position.current[0], st.position.current[1], (!x && !y && p > 0) ? p : 1.0});
      st.spline.order = 3;
    }
    if (b.has('l') && b.get('l') > 3) st.spline.order = static_cast<int>(b.get('l'));
    if (x && y) {
      const Pose end = ctx.end_point(b);
      pts.push_back({end[0], end[1], p});
    }
    st.modal.motion = 52;
  }
};

// G5.3: the curve through the collected points.
class NurbsEnd final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block&, int) override {
    InterpState& st = ctx.state();
    if (st.modal.motion != 52) ctx.error(ErrorCode::NurbsNotStarted, "G5.3 without a G5.2 before it");
    auto& pts = st.spline.points;
    if (pts.size() < static_cast<std::size_t>(st.spline.order))
      ctx.error(ErrorCode::NurbsTooFewPoints, "a NURBS of order L = " + std::to_string(st.spline.order) +
                                                  " needs at least that many control points");
    emit(ctx, st.spline.order, pts);
    pts.clear();
    st.modal.motion = -1;
  }
};

}  // namespace

void add_splines(Extensions& ext) {
  const auto spline = std::make_shared<Spline>();
  ext.g[50] = spline;
  ext.g[51] = spline;
  ext.g[52] = std::make_shared<NurbsPoints>();
  ext.g[53] = std::make_shared<NurbsEnd>();
}

}  // namespace opencnc::gcode
