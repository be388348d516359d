// SPDX-License-Identifier: GPL-3.0-or-later
// G70/G71/G72 in LinuxCNC's form: the profile is the subprogram named by Q, read (not run)
// block by block; the passes come from lathe_roughing and run as the core's G0/G1/G2/G3.
#include "opencnc/gcode/lathe_cycles.hpp"

#include <fmt/format.h>
#include <cmath>
#include <memory>
#include <string>

#include "opencnc/gcode/lathe_roughing.hpp"
#include "lathe_errors.hpp"

namespace opencnc::gcode {

namespace {

using lathe::Point;

constexpr std::uint32_t letter_bit(char c) noexcept { return 1u << (c - 'a'); }

// Turns the blocks of the profile subprogram into profile elements, as LinuxCNC reads them:
// X/Z absolute (or incremental when the cycle was programmed in G91), U/W incremental, arcs
// by I/K (absolute centre unless G91.1 was active) or R, A/C round or cut the corner.
class ProfileReader {
 public:
  ProfileReader(Point start, bool incremental, bool incremental_ijk)
      : at_(start), incremental_(incremental), incremental_ijk_(incremental_ijk) {}

  void add(ExecContext& ctx, const Block& b) {
    InterpState& st = ctx.state();
    Point end = incremental_ ? Point(0, 0) : at_;
    Point centre(0, 0);
    if (b.has('u')) {
      if (incremental_) ctx.error(ErrorCode::LatheIncrementalUW, "U cannot be used in a G7x profile programmed in G91");
      if (b.has('x')) ctx.error(ErrorCode::LatheWordConflict, "U and X in the same block of a G7x profile");
      end.imag(end.imag() + (st.modal.lathe_diameter ? b.get('u') / 2 : b.get('u')));
    } else if (b.has('x')) {
      end.imag(b.get('x'));
    }
    if (b.has('w')) {
      if (incremental_) ctx.error(ErrorCode::LatheIncrementalUW, "W cannot be used in a G7x profile programmed in G91");
      if (b.has('z')) ctx.error(ErrorCode::LatheWordConflict, "W and Z in the same block of a G7x profile");
      end.real(end.real() + b.get('w'));
    } else if (b.has('z')) {
      end.real(b.get('z'));
    }
    if (b.has('i')) centre.imag(b.get('i'));
    if (b.has('k')) centre.real(b.get('k'));
    if (incremental_) end += at_;
    if (b.g[kGroupMotion] != -1) st.modal.motion = b.g[kGroupMotion];
    if (at_ == end) return;
    const int motion = st.modal.motion;
    if (motion == 0 || motion == 10) {
      profile.push_back({lathe::ProfileElement::Kind::Line, at_, end, {}, false, 0});
    } else if (motion == 20 || motion == 30) {
      profile.push_back(arc(ctx, b, motion == 30, end, centre));
    }
    if (motion == 0 || motion == 10 || motion == 20 || motion == 30) corner(ctx, b, end);
    st.position.current[0] = end.imag();
    st.position.current[2] = end.real();
    at_ = end;
  }

  lathe::Profile profile;

 private:
  lathe::ProfileElement arc(ExecContext& ctx, const Block& b, bool ccw, Point end, Point centre) const {
    if (b.has('r')) {
      if (b.has('i') || b.has('k')) ctx.error(ErrorCode::LatheWordConflict, "an arc of a G7x profile with both R and I/K");
      // The centre on the chord's perpendicular bisector, to the left for G3 (LinuxCNC takes
      // the short arc whatever the sign of R).
      const double r = b.get('r');
      const Point chord = end - at_;
      const Point normal = Point(0, 1) * std::sqrt((r * r - std::norm(chord) / 4) / std::norm(chord)) * chord;
      centre = (at_ + end) / 2.0 + (ccw ? normal : -normal);
    } else {
      if (!b.has('i') && !b.has('k')) ctx.error(ErrorCode::LatheArcCentre, "an arc of a G7x profile needs I or K (or R)");
      if (incremental_ijk_) centre += at_;
    }
    return {lathe::ProfileElement::Kind::Arc, at_, end, centre, ccw, 0};
  }

  void corner(ExecContext& ctx, const Block& b, Point end) {
    if (b.has('a') && b.has('c')) ctx.error(ErrorCode::LatheWordConflict, "A (fillet) and C (chamfer) on the same corner of a G7x profile");
    if (b.has('a')) profile.push_back({lathe::ProfileElement::Kind::Fillet, end, end, end, false, b.get('a')});
    if (b.has('c')) profile.push_back({lathe::ProfileElement::Kind::Chamfer, end, end, end, false, b.get('c')});
  }

  Point at_;
  bool incremental_;
  bool incremental_ijk_;
};

// The cycle's moves as the core's G0/G1/G2/G3 (absolute XZ words: the cycle runs in G90 and
// G90.1 like LinuxCNC's).
class CycleMoves final : public lathe::PathSink {
 public:
  explicit CycleMoves(ExecContext& ctx) : ctx_(ctx) {}
  void rapid(Point end) override { move(0, end); }
  void feed(Point end) override { move(10, end); }
  void arc(Point end, Point centre, bool ccw) override {
    // Arcs that end where they start are left out (LinuxCNC compares with its 0.0001 EQ tolerance).
    const Pose& at = ctx_.state().position.current;
    if (std::fabs(at[2] - end.real()) < 1e-4 && std::fabs(at[0] - end.imag()) < 1e-4) return;
    Block b = words(end);
    set(b, 'i', centre.imag());
    set(b, 'k', centre.real());
    ctx_.programmed_move(ccw ? 30 : 20, b);
  }

 private:
  static void set(Block& b, char letter, double v) {
    b.words |= letter_bit(letter);
    b.value[static_cast<std::size_t>(letter - 'a')] = v;
  }
  static Block words(Point end) {
    Block b;
    b.clear();
    set(b, 'x', end.imag());
    set(b, 'z', end.real());
    return b;
  }
  void move(int motion, Point end) { ctx_.programmed_move(motion, words(end)); }

  ExecContext& ctx_;
};

// LinuxCNC names the sub "O<q>": Q printed with six decimals, then read as a whole number.
std::string sub_name(ExecContext& ctx, double q) {
  const double v = std::round(q * 1e6) / 1e6;
  double whole = std::floor(v);
  if (v - whole > 0.9999) whole = std::ceil(v);
  else if (v - whole > 0.0001) ctx.error(ErrorCode::NotAnInteger, "Q (the profile subprogram) must be a whole number");
  return fmt::format("{:.0f}", whole);   // exact for any size (no conversion to an integer type)
}

// The G7x words, read before the profile lends the block to the profile's lines.
constexpr int kMaxFinishingPasses = 10000;

struct CycleWords {
  Block block;
  double d = 0, e = 0, i = 1, p = 1, r = 0.5, u = 0, w = 0;
  explicit CycleWords(const Block& b) : block(b) {
    if (b.has('d')) d = b.get('d');
    if (b.has('e')) e = b.get('e');
    if (b.has('i')) i = b.get('i');
    if (b.has('p')) p = b.get('p');
    if (b.has('r')) r = b.get('r');
    if (b.has('u')) u = b.get('u');
    if (b.has('w')) w = b.get('w');
  }
};

class LatheCycle final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& block, int code) override;

 private:
  static void run(ExecContext& ctx, const CycleWords& w, int code, const lathe::Profile& profile, Point start);
};

void LatheCycle::execute(ExecContext& ctx, const Block& block, int code) {
  const int cycle = code / 10, variant = code % 10;
  if (!block.has('q')) ctx.error(ErrorCode::LatheProfileMissing, "G7x needs Q, the number of the profile subprogram");
  InterpState& st = ctx.state();
  if (st.modal.cutter_comp != CutterComp::Off && cycle != 70)
    ctx.error(ErrorCode::LatheCompensation, "G" + std::to_string(cycle) + "." + std::to_string(variant) +
                                                " cannot run while cutter compensation is on (G70 can)");
  if (st.modal.plane != canon::Plane::XZ)
    ctx.error(ErrorCode::LathePlane, "G" + std::to_string(cycle) + "." + std::to_string(variant) +
                                         " works only in the XZ plane (program G18)");
  const CycleWords words(block);
  // The cycle runs in absolute distance modes (restored afterwards, also after an error, as
  // LinuxCNC's cycle does); the programmed ones decide how its words are read.
  struct Modes {
    ModalState& m;
    DistanceMode distance, ijk;
    ~Modes() {
      m.distance = distance;
      m.ijk_distance = ijk;
    }
  } modes{st.modal, st.modal.distance, st.modal.ijk_distance};
  st.modal.distance = DistanceMode::Absolute;
  st.modal.ijk_distance = DistanceMode::Absolute;
  const bool incremental = modes.distance == DistanceMode::Incremental;
  Point start(st.position.current[2], st.position.current[0]);
  if (block.has('x')) start.imag(incremental ? start.imag() + block.get('x') : block.get('x'));
  if (block.has('z')) start.real(incremental ? start.real() + block.get('z') : block.get('z'));

  // The rapid to the cycle's start: the block's own words, read as absolute (LinuxCNC does
  // so even in G91). Under G70 with compensation on it is an ordinary compensated move (the
  // entry move if compensation has just been turned on), as in rs274 2.9.
  ctx.programmed_move(0, words.block);

  ProfileReader reader(start, incremental, modes.ijk == DistanceMode::Incremental);
  constexpr std::uint32_t kProfileLetters = letter_bit('a') | letter_bit('c') | letter_bit('u') | letter_bit('w');
  ctx.read_subprogram(sub_name(ctx, words.block.get('q')), kProfileLetters,
                      [&](const Block& b) { reader.add(ctx, b); });
  // Reading the profile leaves the position at its end, and rs274 2.9 starts the passes from
  // there. Only compensation can tell: its tool then stands at the profile's end, so the
  // pass's rapid to the start point, which the entry move has already reached as programmed,
  // is a move without motion in the plane and goes to that position.
  if (reader.profile.size() <= 1) return;
  if (words.i <= 0) ctx.error(ErrorCode::LatheDepth, "I (depth of cut) must be greater than zero");
  run(ctx, words, code, reader.profile, start);
}

void LatheCycle::run(ExecContext& ctx, const CycleWords& w, int code, const lathe::Profile& profile, Point start) {
  CycleMoves moves(ctx);
  try {
    if (code == 700) {
      lathe::FinishingParams p;
      p.start = start;
      p.first_allowance = w.d;
      p.last_allowance = w.e;
      p.passes = w.p;
      // LinuxCNC truncates P to an int; past the range that is undefined, and long before it
      // a program error (each pass runs the whole profile).
      if (!(w.p < kMaxFinishingPasses + 1.0))
        ctx.error(ErrorCode::LimitRepeatCount,
                  fmt::format("G70 P{}: more than {} finishing passes", w.p, kMaxFinishingPasses));
      lathe::finish(profile, p, moves);
      return;
    }
    lathe::RoughingParams p;
    p.direction = code / 10 == 72 ? lathe::Direction::Facing : lathe::Direction::Turning;
    p.pockets = static_cast<lathe::Pockets>(code % 10);
    p.start = start;
    p.allowance = w.d;
    p.depth = w.i;
    p.retract = w.r;
    p.shift = Point(w.w, w.u);
    lathe::rough(profile, p, moves);
  } catch (const lathe::RoughingError& e) {
    ctx.error(roughing_error_code(e.kind()), e.what());
  }
}

}  // namespace

ErrorCode roughing_error_code(lathe::RoughingError::Kind kind) noexcept {
  using K = lathe::RoughingError::Kind;
  switch (kind) {
    case K::NotMonotonic: return ErrorCode::LatheNotMonotonic;
    case K::ParallelLines: return ErrorCode::LatheParallel;
    case K::CornerFinish: return ErrorCode::LatheCornerFinish;
    case K::LostPath: return ErrorCode::LatheLostProfile;
    case K::NoProgress: return ErrorCode::LatheNoProgress;
  }
  return ErrorCode::LatheLostProfile;
}

void add_lathe_cycles(Extensions& ext) {
  const auto handler = std::make_shared<LatheCycle>();
  for (int code : {700, 710, 711, 712, 720, 721, 722}) ext.g[static_cast<std::size_t>(code)] = handler;
}

}  // namespace opencnc::gcode
