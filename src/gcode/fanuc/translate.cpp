// SPDX-License-Identifier: GPL-3.0-or-later
// Fanuc blocks rewritten into the core's terms before LinuxCNC's checks run: lathe words
// (U/W, T0101, G50 S, G98/G99), dwell units (G4 P milliseconds, G4 X seconds), G33 F, G41 H,
// M98/M99 words, and the codes that may not run while a coordinate transform is on.
#include <cmath>

#include "dialect.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {

constexpr std::uint32_t bit(char letter) noexcept {
  return 1u << (letter - 'a');
}

void set_word(Block& b, char letter, double value) noexcept {
  b.value[static_cast<std::size_t>(letter - 'a')] = value;
  b.words |= bit(letter);
}

void drop_word(Block& b, char letter) noexcept {
  b.words &= ~bit(letter);
}

}  // namespace

bool FanucDialect::block_has_content() const noexcept {
  const Block& b = e_.block_;
  if (b.words != 0 || b.m_count != 0 || b.o_type != OWord::None) return true;
  if (!e_.parser_.numbered_assignments.empty() || !e_.parser_.named_assignments.empty()) return true;
  for (const auto g : b.g) {
    if (g != -1) return true;
  }
  return false;
}

void FanucDialect::translate() {
  Block& b = e_.block_;
  if (b.o_type != OWord::Program && block_has_content()) e_.st_.frames.back().fanuc.started = true;
  p_ = l_ = clamp_ = -1;
  if (b.o_type != OWord::None) return;
  // M98 P L and M99 P: the words belong to the call, not to LinuxCNC's word rules.
  if (const int stop = b.m[kGroupStop]; stop == 98 || stop == 99) {
    if (b.has('p')) p_ = b.get('p');
    if (b.has('l')) l_ = b.get('l');
    drop_word(b, 'p');
    drop_word(b, 'l');
  }
  // Fanuc keeps P as the cycles' modal dwell, so drilling cycles that do not dwell (G81,
  // G85) accept it; it waits for the next G82/G89 instead of failing LinuxCNC's word rules.
  if (const int cycle = b.g[kGroupMotion]; (cycle == 810 || cycle == 850) && b.has('p')) {
    e_.st_.cycle.p = b.get('p');
    drop_word(b, 'p');
  }
  if (e_.opt_.machine == MachineKind::Lathe && b.g[kGroupMotion] == 700) {
    // G70 P Q [F]: a run of the program's own blocks (fanuc_range).
    if (!b.has('p') || !b.has('q'))
      fail(ErrorCode::FanucCycleWordMissing,
           "G70 needs P and Q (the first and last block numbers of the profile)");
    b.o_type = OWord::BlockRange;
    b.args[0] = b.get('p');
    b.args[1] = b.get('q');
    if (b.has('f')) {
      b.args[2] = b.get('f');
      b.arg_given = 4u;
    }
    b.g[kGroupMotion] = -1;
    b.words = 0;
    return;
  }
  if (e_.opt_.machine == MachineKind::Lathe) {
    lathe_codes();
    lathe_words();
    if (b.has('t')) lathe_tool();
  }
  if (b.g[kGroupNonModal] == 40) dwell();
  // G33 Z F: Fanuc gives the lead as F, LinuxCNC as K.
  if ((b.g[kGroupMotion] == 330 || (b.g[kGroupMotion] == -1 && e_.st_.modal.motion == 330 && b.any_axis())) &&
      b.has('f') && !b.has('k')) {
    set_word(b, 'k', b.get('f'));
    b.at['k' - 'a'] = b.at['f' - 'a'];
    drop_word(b, 'f');
  }
  // Fanuc 0M names the radius offset of G41/G42 with H as well as D.
  const int comp = b.g[kGroupCutterComp];
  if ((comp == 410 || comp == 420) && b.has('h') && !b.has('d') && b.g[kGroupToolLength] == -1) {
    set_word(b, 'd', b.get('h'));
    b.at['d' - 'a'] = b.at['h' - 'a'];
    drop_word(b, 'h');
  }
  transform_conflicts();
}

// G4 P is in milliseconds unless written with a decimal point (Haas: seconds); G4 X (G4 U on
// a lathe) is in seconds.
void FanucDialect::dwell() {
  Block& b = e_.block_;
  const char seconds_word =
      b.has('x') ? 'x' : (b.has('u') && e_.opt_.machine == MachineKind::Lathe ? 'u' : '\0');
  if (seconds_word != '\0' && !b.has('p')) {
    double s = b.get(seconds_word);
    if (seconds_word == 'x' && e_.st_.modal.lathe_diameter) s *= 2.0;  // the parser halved it
    set_word(b, 'p', s);
    b.at['p' - 'a'] = b.at[static_cast<std::size_t>(seconds_word - 'a')];
    drop_word(b, seconds_word);
  } else if (b.has('p') && (b.decimal & bit('p')) == 0) {
    b.value['p' - 'a'] = b.get('p') / 1000.0;
  }
}

// Lathe G codes that mean something else on a mill (Fanuc lathe G-code system A).
void FanucDialect::lathe_codes() {
  Block& b = e_.block_;
  // G50 S clamps the spindle speed; G50 X Z sets the coordinate system (LinuxCNC's G92).
  if (b.g[kGroupScaling] == 500) {
    b.g[kGroupScaling] = -1;
    if (b.has('s')) {
      clamp_ = b.get('s');
      drop_word(b, 's');
    }
    if (b.any_axis() || b.has('u') || b.has('w')) {
      if (b.g[kGroupNonModal] != -1)
        fail(ErrorCode::ModalGroupConflict, "G50 (coordinate system) with another G code of group 0");
      b.g[kGroupNonModal] = 920;
    }
  }
  // Fanuc lathe cycles this controller does not have (G-code system A's single cycles and
  // G73/G74), named rather than run as the mill codes of the same number.
  const bool axes = b.any_axis() || b.has('u') || b.has('w');
  const int motion = b.g[kGroupMotion];
  const int distance = b.g[kGroupDistance], feed = b.g[kGroupFeedMode];
  const char* missing = motion == 730                              ? "G73 (pattern repeating)"
                        : motion == 740                            ? "G74 (face peck drilling)"
                        : distance == 900 && axes                  ? "G90 X Z (turning cycle)"
                        : feed == 940 && axes                      ? "G94 X Z (facing cycle)"
                        : b.g[kGroupNonModal] == 920 && b.has('f') ? "G92 X Z F (threading cycle)"
                                                                   : nullptr;
  if (missing != nullptr) fail(ErrorCode::Unsupported, "{} of Fanuc lathes is not supported", missing);
  // G92 S alone (Fanuc system B): the spindle clamp.
  if (b.g[kGroupNonModal] == 920 && b.has('s') && !b.any_axis() && !b.has('u') && !b.has('w')) {
    b.g[kGroupNonModal] = -1;
    clamp_ = b.get('s');
    drop_word(b, 's');
  }
  // G98 / G99: feed per minute / per revolution.
  if (const int r = b.g[kGroupRetract]; r != -1) {
    if (b.g[kGroupFeedMode] != -1)
      fail(ErrorCode::ModalGroupConflict, "two feed modes in one block (G{} is a feed mode on a lathe)",
           r / 10);
    b.g[kGroupRetract] = -1;
    b.g[kGroupFeedMode] = static_cast<std::int16_t>(r == 980 ? 940 : 950);
  }
  // G96 without D: the clamp set by G50 S.
  if (b.g[kGroupSpindleMode] == 960 && !b.has('d') && (clamp_ > 0 || e_.st_.fanuc.spindle_clamp_rpm > 0))
    set_word(b, 'd', clamp_ > 0 ? clamp_ : e_.st_.fanuc.spindle_clamp_rpm);
}

// U and W: incremental X and Z (X and Z stay absolute under G90).
void FanucDialect::lathe_words() {
  Block& b = e_.block_;
  if (b.g[kGroupNonModal] == 40) return;  // G4 U: a dwell time
  const int motion = b.g[kGroupMotion];
  if (motion >= 700 && motion <= 730) return;  // G70-G73: U and W are finishing allowances
  const PositionState& s = e_.st_.position;
  const bool middle = e_.st_.modal.cutter_comp != CutterComp::Off && !e_.st_.modal.comp_first_move;
  const std::pair<char, char> pairs[] = {{'u', 'x'}, {'w', 'z'}};
  for (const auto& [inc, abs] : pairs) {
    if (!b.has(inc)) continue;
    if (b.has(abs))
      fail_at(b.at[static_cast<std::size_t>(inc - 'a')], ErrorCode::RepeatedWord,
              "{} and {} in one block (both move {})", static_cast<char>(abs - 32),
              static_cast<char>(inc - 32), static_cast<char>(abs - 32));
    const int axis = abs == 'x' ? 0 : 2;
    double delta = b.get(inc);
    if (axis == 0 && e_.st_.modal.lathe_diameter) delta /= 2.0;
    const double from = middle ? s.programmed[static_cast<std::size_t>(axis)] : s.current[axis];
    set_word(b, abs, e_.st_.modal.distance == DistanceMode::Incremental ? delta : from + delta);
    b.at[static_cast<std::size_t>(abs - 'a')] = b.at[static_cast<std::size_t>(inc - 'a')];
    drop_word(b, inc);
  }
}

// T0101: turret position (tool) 01 with offset 01. A new tool is indexed (M6); offset 00
// cancels the length offset (G49), any other applies that tool's offsets (G43 H).
void FanucDialect::lathe_tool() {
  Block& b = e_.block_;
  const int t = static_cast<int>(b.get('t'));
  const int tool = t >= 100 ? t / 100 : t;
  const int offset = t >= 100 ? t % 100 : t;
  b.value['t' - 'a'] = tool;
  if (tool != 0 && tool != e_.st_.tool.table[0].tool && b.m[kGroupToolChange] == -1) {
    b.m[kGroupToolChange] = 6;
    ++b.m_count;
  }
  if (b.g[kGroupToolLength] != -1) return;
  if (offset == 0) {
    b.g[kGroupToolLength] = 490;
  } else {
    b.g[kGroupToolLength] = 430;
    set_word(b, 'h', offset);
    b.at['h' - 'a'] = b.at['t' - 'a'];
  }
}

// Fanuc: reference returns, machine coordinates and coordinate system changes are not
// allowed while a transform is on; nor is a plane change under G68.
void FanucDialect::transform_conflicts() {
  const Block& b = e_.block_;
  const TransformState& t = e_.st_.fanuc.transform;
  if (!t.active()) return;
  const int g0 = b.g[kGroupNonModal];
  const bool reference = g0 == 280 || g0 == 300 || g0 == 530;
  const bool coordinates = g0 == 520 || g0 == 920 || g0 == 921 || g0 == 922 || g0 == 923 ||
                           (g0 == 100 && (b.get('l') == 2 || b.get('l') == 20)) ||
                           b.g[kGroupCoordSystem] != -1;
  if (reference || coordinates) {
    const char* which = t.rotating ? "G68 rotation" : t.scaling ? "G51 scaling" : "G51.1 mirroring";
    const int code = reference || g0 != -1 ? g0 : b.g[kGroupCoordSystem];
    fail(ErrorCode::FanucTransformActive, "G{}{} cannot be used while {} is on (cancel it first)", code / 10,
         code % 10 ? fmt::format(".{}", code % 10) : std::string(), which);
  }
  if (t.rotating && b.g[kGroupPlane] != -1) {
    const int p = b.g[kGroupPlane];
    const canon::Plane plane = p == 180   ? canon::Plane::XZ
                               : p == 190 ? canon::Plane::YZ
                               : p == 170 ? canon::Plane::XY
                                          : canon::Plane::UV;
    if (plane != t.rotation_plane)
      fail(ErrorCode::FanucRotationPlaneChange,
           "G{} changes the plane while G68 rotates in another one (G69 first)", p / 10);
  }
  const bool scaled = t.scaling && (t.scale[0] != 1.0 || t.scale[1] != 1.0 || t.scale[2] != 1.0);
  const int comp = b.g[kGroupCutterComp];
  if (scaled && comp != -1 && comp != 400)
    fail(ErrorCode::Unsupported,
         "cutter compensation under G51 scaling is not supported (the radius would be scaled)");
}

// After the block: a G50 S / G92 S clamp takes effect (at once if the spindle runs at
// constant surface speed).
void FanucDialect::after_block() {
  if (clamp_ < 0) return;
  e_.st_.fanuc.spindle_clamp_rpm = clamp_;
  if (e_.st_.modal.spindle_mode == SpindleMode::ConstantSurface) e_.out_.set_spindle_mode(0, clamp_);
}

}  // namespace opencnc::gcode
