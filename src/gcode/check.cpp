// SPDX-License-Identifier: GPL-3.0-or-later
// Block consistency rules applied after reading, before anything executes (LinuxCNC's
// enhance_block and check_items): which motion the block performs and which words are used.
#include <cmath>

#include "engine.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {

bool is_cycle(int motion) noexcept { return motion == 730 || motion == 740 || (motion >= 810 && motion <= 890); }
bool is_lathe_cycle(int motion) noexcept { return motion >= 700 && motion <= 722; }
// Where a word starts, for the column of an error about it.
int word_at(const Block& b, char letter) noexcept { return b.at[static_cast<std::size_t>(letter - 'a')]; }

}  // namespace

void Engine::enhance_block() {
  Block& b = block_;
  const bool polar = b.radius_flag || b.theta_flag;
  if (polar) {
    if (!((letters_ >> ('x' - 'a')) & 1u) || !((letters_ >> ('y' - 'a')) & 1u))
      fail(ErrorCode::PolarCoordinates, "polar coordinates need X and Y axes");
    if (st_.modal.plane != canon::Plane::XY)
      fail(ErrorCode::PolarCoordinates, "polar coordinates are only available in the G17 (XY) plane");
    if (b.has('x')) fail(ErrorCode::PolarCoordinates, "X word beside a polar coordinate");
    if (b.has('y')) fail(ErrorCode::PolarCoordinates, "Y word beside a polar coordinate");
  }
  const bool axis = b.any_axis();
  const bool ijk = b.has('i') || b.has('j') || b.has('k');
  const int mode0 = b.g[kGroupNonModal];
  const int mode1 = b.g[kGroupMotion];
  const bool covets = mode0 == 100 || mode0 == 280 || mode0 == 300 || mode0 == 520 || mode0 == 920;
  if (mode1 != -1) {
    if (mode1 == 800) {
      if ((polar || axis) && !covets) fail(ErrorCode::AxisWordsWithG80, "axis words with G80 and no G code that uses them");
      if (polar && mode0 == 920) fail(ErrorCode::PolarCoordinates, "polar coordinates are for motion only");
      if (!axis && (mode0 == 520 || mode0 == 920)) fail(ErrorCode::AxisWordsMissing, "G52 and G92 need at least one axis word");
    } else if (is_lathe_cycle(mode1)) {
      // G70-G72 take their profile from other blocks; their words are checked by the cycle.
    } else {
      if (covets) fail(ErrorCode::TwoAxisGCodes, "two G codes in the block both use the axis words");
      if (!axis && !polar && mode1 != 0 && mode1 != 10 && mode1 != 20 && mode1 != 30 && mode1 != 52)
        fail(ErrorCode::AxisWordsMissing, "G{} needs at least one axis word", mode1 / 10.0);
    }
    b.motion = mode1;
  } else if (covets) {
    if (polar && mode0 == 920) fail(ErrorCode::PolarCoordinates, "polar coordinates are for motion only");
    if (!axis && (mode0 == 520 || mode0 == 920)) fail(ErrorCode::AxisWordsMissing, "G52 and G92 need at least one axis word");
  } else if (axis || polar) {
    const bool g43_1 = b.g[kGroupToolLength] == 431;
    if ((st_.modal.motion == -1 || st_.modal.motion == 800) && !g43_1)
      fail(ErrorCode::AxisWordsWithoutMotion, "axis words without a motion mode (G80 is active)");
    if (!g43_1) b.motion = st_.modal.motion;
  } else if (ijk && (st_.modal.motion == 20 || st_.modal.motion == 30)) {
    b.motion = st_.modal.motion;
  }
  if (polar && b.motion == -1) fail(ErrorCode::PolarCoordinates, "polar coordinates are for motion only");
}

void Engine::check_block() {
  check_g_codes();
  if (block_.m_count > 4) fail(ErrorCode::TooManyMCodes, "more than four M codes in one block");
  check_other_codes();
  if (ext_ == nullptr) return;
  for (int group = 0; group < kGGroupCount; ++group) check_extension(block_.g[static_cast<std::size_t>(group)]);
  if (block_.motion != block_.g[kGroupMotion]) check_extension(block_.motion);
}

void Engine::check_extension(int code) {
  if (code < 0 || !ext_->g[static_cast<std::size_t>(code)]) return;
  if (auto problem = ext_->g[static_cast<std::size_t>(code)]->check(block_, code, st_))
    fail(problem->code, "{}", problem->message);
}

void Engine::check_g_codes() {
  const Block& b = block_;
  const int mode0 = b.g[kGroupNonModal];
  const int mode1 = b.g[kGroupMotion];
  if (mode0 == 40) {
    if (!b.has('p') || b.get('p') == -1.0) fail(ErrorCode::MissingWord, "G4 needs a P word (dwell time in seconds)");
    if (mode1 == 20 || mode1 == 30) fail(ErrorCode::MissingWord, "G4 cannot share a block with G2/G3 (both use P)");
  } else if (mode0 == 100) {
    const double p = b.p_or(-1.0);
    const int p_int = round_to_int(p);
    const int l = b.has('l') ? static_cast<int>(b.get('l')) : -1;
    if (l != 1 && l != 2 && l != 10 && l != 11 && l != 20)
      fail(ErrorCode::G10Usage, "G10 needs L1, L2, L10, L11 or L20");
    if ((p + 0.0001) - p_int > 0.0002) fail(ErrorCode::G10Usage, "G10 needs a whole-number P");
    if ((l == 2 || l == 20) && (p_int < 0 || p_int > 9)) fail(ErrorCode::G10Usage, "G10 L{} needs P0..P9", l);
    if ((l == 1 || l == 10 || l == 11) && p_int < 1) fail(ErrorCode::G10Usage, "G10 L{} needs a tool number P1 or more", l);
  } else if (mode0 == 53) {
    if (mode1 != 520 && mode1 != -1) fail(ErrorCode::Unsupported, "G5.3 is not supported yet");
  } else if (mode0 == 530) {
    if (b.motion != 0 && b.motion != 10) fail(ErrorCode::G53Usage, "G53 needs G0 or G1");
    if (b.g[kGroupDistance] == 910 || (b.g[kGroupDistance] != 900 && st_.modal.distance == DistanceMode::Incremental))
      fail(ErrorCode::G53Usage, "G53 cannot be used in incremental distance mode (G91)");
  }
}

void Engine::check_other_codes() {
  const Block& b = block_;
  const int motion = b.motion;
  const int m5 = b.m[kGroupIo], m6 = b.m[kGroupToolChange], m7 = b.m[kGroupSpindle], m9 = b.m[kGroupOverride];
  const int g0 = b.g[kGroupNonModal], g7 = b.g[kGroupCutterComp], g8 = b.g[kGroupToolLength];
  const int g13 = b.g[kGroupControl], g14 = b.g[kGroupSpindleMode];
  const bool user_m = b.m[kGroupUser] != -1;
  const bool lathe = is_lathe_cycle(motion);
  if (user_m) return;   // user M codes take any words
  // Most blocks carry axis words and F/S only: none of the rules below can apply.
  constexpr auto bit = [](char c) { return 1u << (c - 'a'); };
  constexpr std::uint32_t kRuledWords = bit('d') | bit('e') | bit('h') | bit('i') | bit('j') | bit('k') | bit('l') |
                                        bit('p') | bit('q') | bit('r');
  if ((b.words & kRuledWords) == 0 && !is_cycle(motion) && g14 != 960 && motion != 330 && motion != 331 && motion != 760)
    return;
  for (char c : {'a', 'b', 'c'}) {
    if (b.has(c) && is_cycle(motion)) fail_at(word_at(b, c), ErrorCode::UnusedWord, "{} word in a canned cycle", static_cast<char>(c - 32));
  }
  if (b.has('d') && g7 != 410 && g7 != 420 && g7 != 411 && g7 != 421 && g14 != 960 && !lathe)
    fail_at(word_at(b, 'd'), ErrorCode::UnusedWord, "D word with no G41, G41.1, G42, G42.1, G7x or G96 to use it");
  if (b.has('e') && motion != 760 && motion != 700 && m5 != 66 && m5 != 67 && m5 != 68)
    fail_at(word_at(b, 'e'), ErrorCode::UnusedWord, "E word with no G70, G76, M66, M67 or M68 to use it");
  if (b.has('h') && g8 != 430 && motion != 760 && g8 != 432)
    fail_at(word_at(b, 'h'), ErrorCode::UnusedWord, "H word with no G43, G43.2 or G76 to use it");
  const bool arcish = motion == 20 || motion == 30 || motion == 50 || motion == 51 || motion == 760 || motion == 870;
  if (b.has('i') && !arcish && motion != 331 && g0 != 100 && !lathe)
    fail_at(word_at(b, 'i'), ErrorCode::UnusedWord, "I word with no G2, G3, G5, G5.1, G10, G33.1, G76 or G87 to use it");
  if (b.has('j') && !arcish && g0 != 100 && !lathe)
    fail_at(word_at(b, 'j'), ErrorCode::UnusedWord, "J word with no G2, G3, G5, G5.1, G10, G76 or G87 to use it");
  if (b.has('k') && motion != 20 && motion != 30 && motion != 330 && motion != 331 && motion != 760 && motion != 870 && !lathe)
    fail_at(word_at(b, 'k'), ErrorCode::UnusedWord, "K word with no G2, G3, G33, G33.1, G76 or G87 to use it");
  if (b.has('l') && !(motion >= 810 && motion <= 890) && motion != 760 && motion != 52 && motion != 730 && motion != 740 &&
      !lathe && g0 != 100 && g7 != 410 && g7 != 411 && g7 != 420 && g7 != 421 && m5 != 66)
    fail_at(word_at(b, 'l'), ErrorCode::UnusedWord, "L word with no G10, cutter compensation, canned cycle, M66 or NURBS code to use it");
  if (b.has('p')) {
    if (g0 != 100 && g0 != 40 && g13 != 640 && motion != 760 && motion != 820 && motion != 860 && motion != 880 &&
        motion != 890 && motion != 50 && motion != 52 && motion != 20 && motion != 30 && !lathe && motion != 740 &&
        motion != 840 && !(m9 >= 50 && m9 <= 53) && !(m5 >= 62 && m5 <= 66) && m7 != 19)
      fail_at(word_at(b, 'p'), ErrorCode::UnusedWord, "P word with no G2, G3, G4, G10, G64, G5, G5.2, G76, G82, G86, G88, G89 or "
                                  "M50-M53, M62-M66 to use it");
    const double p = b.get('p');
    const int p_value = round_to_int(p);
    if ((motion == 20 || motion == 30 || m7 == 19) && std::fabs(p_value - p) > 0.001)
      fail_at(word_at(b, 'p'), ErrorCode::BadWordValue, "P must be a whole number with G2, G3 and M19");
    if (m7 == 19 && (p_value > 2 || p_value < 0)) fail_at(word_at(b, 'p'), ErrorCode::BadWordValue, "P must be 0, 1 or 2 with M19");
    if ((motion == 20 || motion == 30) && p_value < 1) fail_at(word_at(b, 'p'), ErrorCode::BadWordValue, "P (turns) must be 1 or more with G2/G3");
  }
  if (b.has('q') && b.get('q') != -1.0) {
    if (motion != 830 && motion != 730 && motion != 50 && !lathe && motion != 760 && m5 != 66 && m5 != 67 && m5 != 68 &&
        g0 != 100 && m6 != 61 && g13 != 640 && m7 != 19)
      fail_at(word_at(b, 'q'), ErrorCode::UnusedWord, "Q word with no G5, G10, G64, G73, G76, G83, M19, M61, M66, M67 or M68 to use it");
  }
  if (b.has('r')) {
    if (motion != 20 && motion != 30 && motion != 760 && !(motion >= 810 && motion <= 890) && motion != 730 && !lathe &&
        motion != 740 && g7 != 411 && g7 != 421 && g0 != 100 && m7 != 19)
      fail_at(word_at(b, 'r'), ErrorCode::UnusedWord, "R word with no G code that uses it");
    if (m7 == 19 && (b.get('r') > 360.0 || b.get('r') < 0.0)) fail_at(word_at(b, 'r'), ErrorCode::BadWordValue, "R must be within 0..360 with M19");
  }
  if (!b.has('s') && g14 == 960) fail(ErrorCode::MissingWord, "G96 needs an S word (surface speed)");
  if (motion == 330 || motion == 331) {
    if (!b.has('k')) fail(ErrorCode::MissingWord, "G33/G33.1 need a K word (distance per revolution)");
    if (b.has('f')) fail_at(word_at(b, 'f'), ErrorCode::UnusedWord, "F word cannot be used with G33/G33.1");
  }
  if (motion == 760) {
    if (b.p_or(-1.0) == -1.0) fail(ErrorCode::MissingWord, "G76 needs a P word (pitch)");
    if (!b.has('i') || !b.has('j') || !b.has('k')) fail(ErrorCode::MissingWord, "G76 needs I, J and K words");
  }
}

}  // namespace opencnc::gcode
