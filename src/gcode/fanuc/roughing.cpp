// SPDX-License-Identifier: GPL-3.0-or-later
// Fanuc G71 (stock removal in turning) and G72 (in facing): the finishing shape is the
// program's own blocks N P .. N Q, read (not run) into a profile for the roughing engine, in
// Fanuc's two-block form (G71 U R / G71 P Q U W F) and the one-block form of Haas and the
// Fanuc 0 (G71 P Q U W D F); afterwards the tool goes back to the cycle's start point.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

#include "codes.hpp"
#include "lathe_errors.hpp"
#include "numeric.hpp"
#include "opencnc/gcode/lathe_roughing.hpp"
#include "parser.hpp"

namespace opencnc::gcode {

namespace {

using lathe::Point;

// Without any R (Fanuc keeps the retract in a parameter): this much, but no more than the
// depth of cut, so that the lift-off stays within the layer just cut.
constexpr double kDefaultRetractMm = 0.5;
constexpr double kDefaultRetractInch = 0.02;

Point zx(const Pose& p) {
  return {p[Axis::Z], p[Axis::X]};
}

// Reads the shape's blocks into a profile, element 0 running from the cycle's start point:
// G0/G1 give lines, G2/G3 arcs, with the core's end points (X a diameter on a diameter lathe,
// U/W incremental, G91) and arc centres (R, or I/K). F, S, T, M functions and G40-G42 belong
// to the finishing pass (G70 runs the blocks): the roughing passes do not use them.
class ShapeReader {
 public:
  ShapeReader(ExecContext& ctx, const char* cycle, const Pose& start)
      : ctx_(ctx), cycle_(cycle), at_(start) {}

  void add(const Block& b) {
    check_codes(b);
    InterpState& st = ctx_.state();
    // The modal motion follows the shape, so that the next block's axis words are read as
    // its continuation (the cycle puts it back afterwards).
    if (b.g[kGroupMotion] != -1) st.modal.motion = b.g[kGroupMotion];
    if (b.motion == -1) return;
    const Pose end = ctx_.end_point(b);
    for (int axis = 0; axis < kAxisCount; ++axis) {
      if (axis != 0 && axis != 2 && end[axis] != at_[axis])  // X and Z
        ctx_.error(ErrorCode::FanucProfileBlock,
                   fmt::format("the shape of {} moves only X and Z: this block moves another axis", cycle_));
    }
    if (b.motion == 0 || b.motion == 10) {
      if (zx(end) != zx(at_))
        profile.push_back({lathe::ProfileElement::Kind::Line, zx(at_), zx(end), {}, false, 0});
    } else {
      const ArcCentre c = ctx_.arc_centre(b, b.motion, at_, end);
      if (std::abs(c.turn) != 1)
        ctx_.error(ErrorCode::FanucProfileBlock,
                   fmt::format("an arc of the shape of {} cannot turn more than once", cycle_));
      profile.push_back(
          {lathe::ProfileElement::Kind::Arc, zx(at_), zx(end), Point(c.first, c.second), b.motion == 30, 0});
    }
    at_ = end;
    st.position.current = end;
  }

  lathe::Profile profile;

 private:
  // Moves along the shape (G0-G3) and what the finishing pass uses (compensation, feed and
  // spindle modes, the tool offset a T word brings) may be in it; other codes would change
  // the machine's state while the cycle only reads the blocks.
  void check_codes(const Block& b) const {
    for (int group = 0; group < kGGroupCount; ++group) {
      const int code = b.g[static_cast<std::size_t>(group)];
      const bool allowed = code == -1 || group == kGroupCutterComp || group == kGroupFeedMode ||
                           group == kGroupSpindleMode || group == kGroupToolLength ||
                           (group == kGroupMotion && (code == 0 || code == 10 || code == 20 || code == 30));
      if (!allowed)
        ctx_.error(
            ErrorCode::FanucProfileBlock,
            fmt::format(
                "{} in the shape of {}: the shape's blocks may hold G0-G3, G40-G42, G96/G97 and G98/G99 only",
                g_name(code), cycle_));
    }
    if (const int stop = b.m[kGroupStop]; stop != -1)
      ctx_.error(ErrorCode::FanucProfileBlock,
                 fmt::format("M{} in the shape of {}: the cycle reads its blocks, it does not run them", stop,
                             cycle_));
  }

  ExecContext& ctx_;
  const char* cycle_;
  Pose at_;
};

constexpr std::uint32_t bit(char letter) noexcept {
  return 1u << (letter - 'a');
}

// The passes as the core's G0/G1/G2/G3 with absolute X (radius) and Z words, under the
// program's transforms and checks. Moves that would not move are left out (the engine's first
// rapid goes to the start point, where the tool is); so are arcs shorter than 0.0001, which
// the core would read as full circles (LinuxCNC's cycle leaves them out the same way).
class FanucMoves final : public lathe::PathSink {
 public:
  explicit FanucMoves(ExecContext& ctx) : ctx_(ctx) {}
  void rapid(Point end) override { move(0, end, {}); }
  void feed(Point end) override { move(10, end, {}); }
  void arc(Point end, Point centre, bool ccw) override {
    const Point at = zx(ctx_.state().position.current);
    if (std::fabs(at.real() - end.real()) < 1e-4 && std::fabs(at.imag() - end.imag()) < 1e-4) return;
    move(ccw ? 30 : 20, end, centre);
  }

 private:
  void move(int motion, Point end, Point centre) {
    if (zx(ctx_.state().position.current) == end) return;
    Block b;
    b.clear();
    const auto set = [&b](char letter, double v) {
      b.words |= bit(letter);
      b.value[static_cast<std::size_t>(letter - 'a')] = v;
    };
    set('x', end.imag());
    set('z', end.real());
    if (motion == 20 || motion == 30) set('i', centre.imag()), set('k', centre.real());
    ctx_.programmed_move(motion, b);
  }

  ExecContext& ctx_;
};

// The distance modes the cycle's moves are made in (absolute), restored also after an error.
struct AbsoluteModes {
  explicit AbsoluteModes(ModalState& m) : modal(m), distance(m.distance), ijk(m.ijk_distance) {
    m.distance = DistanceMode::Absolute;
    m.ijk_distance = DistanceMode::Absolute;
  }
  ~AbsoluteModes() {
    modal.distance = distance;
    modal.ijk_distance = ijk;
  }
  AbsoluteModes(const AbsoluteModes&) = delete;
  AbsoluteModes& operator=(const AbsoluteModes&) = delete;
  ModalState& modal;
  DistanceMode distance, ijk;
};

// G71 (turning) and G72 (facing). Without P and Q the block only sets the depth of cut (G71 U,
// G72 W) and the retract (R) for the cycles that follow.
class FanucRoughing final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupMotion, 0, false, true}; }
  void execute(ExecContext& ctx, const Block& b, int code) override;

 private:
  struct Cut {
    std::int64_t first = 0, last = 0;  // N P, N Q
    double depth = 0, retract = 0;
    Point allowance;  // W, U as a radius
  };
  static void settings(ExecContext& ctx, const Block& b, const char* name, bool facing);
  static Cut cut_of(ExecContext& ctx, const Block& b, const char* name, bool facing);
  static void rough(ExecContext& ctx, const Cut& cut, const char* name, bool facing);
};

void FanucRoughing::execute(ExecContext& ctx, const Block& b, int code) {
  require_lathe(ctx, code);
  const bool facing = code == 720;
  const char* name = facing ? "G72" : "G71";
  if (b.has('x') || b.has('z'))
    ctx.error(
        ErrorCode::FanucCycleWordValue,
        fmt::format("{} starts where the tool is: move to the start point first (X and Z are not its words)",
                    name));
  if (!b.has('p') && !b.has('q')) return settings(ctx, b, name, facing);
  rough(ctx, cut_of(ctx, b, name, facing), name, facing);
}

// The first block of the two-block form: G71 U(depth) R(retract), G72 W(depth) R(retract).
void FanucRoughing::settings(ExecContext& ctx, const Block& b, const char* name, bool facing) {
  FanucCycleSettings& set = ctx.state().fanuc.cycles;
  const char depth = facing ? 'w' : 'u';
  if (!b.has(depth) && !b.has('r'))
    ctx.error(ErrorCode::FanucCycleWordMissing,
              fmt::format("{} needs {} (depth of cut) and R (retract), or P and Q (the finishing shape)",
                          name, facing ? 'W' : 'U'));
  if (b.has(depth) && b.get(depth) <= 0)
    ctx.error(ErrorCode::FanucCycleWordValue,
              fmt::format("{} {}: the depth of cut must be greater than zero", name, facing ? 'W' : 'U'));
  if (b.has('r') && b.get('r') < 0)
    ctx.error(ErrorCode::FanucCycleWordValue, fmt::format("{} R: the retract cannot be negative", name));
  if (b.has(depth)) set.rough_depth = b.get(depth);
  if (b.has('r')) set.rough_retract = b.get('r');
}

// The P/Q block: the shape's numbers, the finishing allowances U (a diameter on a diameter
// lathe) and W, the depth of cut (D in the one-block form, else the first block's), the retract.
FanucRoughing::Cut FanucRoughing::cut_of(ExecContext& ctx, const Block& b, const char* name, bool facing) {
  const InterpState& st = ctx.state();
  const FanucCycleSettings& set = st.fanuc.cycles;
  if (!b.has('p') || !b.has('q'))
    ctx.error(
        ErrorCode::FanucCycleWordMissing,
        fmt::format("{} needs P and Q (the first and last block numbers of the finishing shape)", name));
  if (b.has('i') || b.has('k'))
    ctx.error(ErrorCode::Unsupported,
              fmt::format("{} I/K (Haas's allowances of the last roughing pass) are not supported", name));
  Cut cut;
  cut.first = trunc_to_int(b.get('p'));  // saturated: too large a number names no block
  cut.last = trunc_to_int(b.get('q'));
  cut.depth = b.has('d') ? length_word(ctx, b, 'd') : set.rough_depth;
  if (b.has('d') && cut.depth <= 0)
    ctx.error(ErrorCode::FanucCycleWordValue,
              fmt::format("{} D: the depth of cut must be greater than zero", name));
  if (cut.depth <= 0)
    ctx.error(
        ErrorCode::FanucCycleWordMissing,
        fmt::format("{} needs a depth of cut: D in this block, or a {} {}(depth) R(retract) block before it",
                    name, name, facing ? 'W' : 'U'));
  const bool inch = st.modal.units == canon::Units::Inch;
  cut.retract = set.rough_retract >= 0 ? set.rough_retract
                                       : std::min(cut.depth, inch ? kDefaultRetractInch : kDefaultRetractMm);
  const double u = b.has('u') ? b.get('u') : 0.0;
  cut.allowance = Point(b.has('w') ? b.get('w') : 0.0, st.modal.lathe_diameter ? u / 2 : u);
  if (st.modal.feed_rate <= 0)
    ctx.error(ErrorCode::FeedZero, fmt::format("{} with zero feed rate (program an F word)", name));
  return cut;
}

void FanucRoughing::rough(ExecContext& ctx, const Cut& cut, const char* name, bool facing) {
  InterpState& st = ctx.state();
  if (st.modal.cutter_comp != CutterComp::Off)
    ctx.error(
        ErrorCode::LatheCompensation,
        fmt::format(
            "{} cannot run while cutter compensation is on (G40 first; G41/G42 in the shape apply to G70)",
            name));
  if (st.modal.plane != canon::Plane::XZ)
    ctx.error(ErrorCode::LathePlane, fmt::format("{} works only in the XZ plane (G18)", name));
  const Pose start = st.position.current;
  const int motion = st.modal.motion;
  ShapeReader reader(ctx, name, start);
  ctx.read_block_range(cut.first, cut.last, name, [&](const Block& blk) { reader.add(blk); });
  st.position.current = start;
  st.modal.motion = motion;
  if (reader.profile.size() < 2)
    ctx.error(ErrorCode::FanucProfileBlock,
              fmt::format(
                  "{} P{} Q{}: the shape does not move beyond its first point, so there is nothing to rough",
                  name, cut.first, cut.last));
  lathe::RoughingParams p;
  p.direction = facing ? lathe::Direction::Facing : lathe::Direction::Turning;
  p.pockets = lathe::Pockets::All;
  p.convention = lathe::Convention::Fanuc;
  p.start = zx(start);
  p.depth = cut.depth;
  p.retract = cut.retract;
  p.shift = cut.allowance;
  const AbsoluteModes absolute(st.modal);
  FanucMoves moves(ctx);
  try {
    lathe::rough(reader.profile, p, moves);
  } catch (const lathe::RoughingError& e) {
    ctx.error(roughing_error_code(e.kind()),
              fmt::format("{} P{} Q{}: {}", name, cut.first, cut.last, e.what()));
  }
  moves.rapid(p.start);  // Fanuc ends the cycle at its start point
  st.modal.motion = motion;
}

}  // namespace

void add_fanuc_roughing_cycles(Extensions& ext) {
  const auto handler = std::make_shared<FanucRoughing>();
  ext.g[710] = handler;
  ext.g[720] = handler;
}

}  // namespace opencnc::gcode
