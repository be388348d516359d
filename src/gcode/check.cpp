// SPDX-License-Identifier: GPL-3.0-or-later
// Block consistency rules applied after reading, before anything executes (LinuxCNC's
// enhance_block and check_items): which motion the block performs and which words are used.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "engine.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {

bool is_cycle(int motion) noexcept { return motion == 730 || motion == 740 || (motion >= 810 && motion <= 890); }
bool is_lathe_cycle(int motion) noexcept { return motion >= 700 && motion <= 722; }
bool is_arc(int motion) noexcept {
  return motion == 20 || motion == 30;
}
char upper(char letter) noexcept {
  return static_cast<char>(letter - 'a' + 'A');
}

// The fifth M code of the line (the first one too many).
int fifth_m_position(const Block& b) noexcept {
  std::array<int, kMGroupCount> at{};
  int n = 0;
  for (int group = 0; group < kMGroupCount; ++group) {
    if (b.m_position(group) != -1) at[static_cast<std::size_t>(n++)] = b.m_position(group);
  }
  std::sort(at.begin(), at.begin() + n);
  return n > 4 ? at[4] : -1;
}

[[noreturn]] void unused_word(const Block& b, char letter, std::string_view users) {
  fail_at(b.word_position(letter), ErrorCode::UnusedWord,
          "{} word used by no code on this line: {} belongs with {}", upper(letter), upper(letter), users);
}

}  // namespace

const CodeHandler* BlockChecks::extension_handler(int code) const noexcept {
  return code >= 0 && e_.ext_ != nullptr ? e_.ext_->g[static_cast<std::size_t>(code)].get() : nullptr;
}

void BlockChecks::enhance_block() {
  Block& b = e_.block_;
  const bool polar = b.radius_flag || b.theta_flag;
  if (polar) {
    const int at = b.polar_position();
    if (!((e_.letters_ >> ('x' - 'a')) & 1u) || !((e_.letters_ >> ('y' - 'a')) & 1u))
      fail_at(at, ErrorCode::PolarNotAvailable,
              "polar coordinates (@ ^) need both an X and a Y axis, which this machine lacks");
    if (e_.st_.modal.plane != canon::Plane::XY)
      fail_at(at, ErrorCode::PolarNotAvailable,
              "polar coordinates (@ ^) work only in the XY plane: select G17 first");
    for (char c : {'x', 'y'}) {
      if (b.has(c))
        fail_at(b.word_position(c), ErrorCode::PolarWithXy,
                "{} word beside a polar coordinate: give the point either as @ and ^ or as X and Y",
                upper(c));
    }
  }
  const bool axis = b.any_axis();
  const bool ijk = b.has('i') || b.has('j') || b.has('k');
  const int mode0 = b.g[kGroupNonModal];
  const int mode1 = b.g[kGroupMotion];
  const ExtensionClaims claims = e_.ext_ != nullptr ? extension_claims() : ExtensionClaims{};
  const bool covets =
      mode0 == 100 || mode0 == 280 || mode0 == 300 || mode0 == 520 || mode0 == 920 || claims.axis_words;
  auto no_polar_offset = [&] {
    if (polar && mode0 == 920)
      fail_at(b.polar_position(), ErrorCode::PolarWithoutMotion,
              "polar coordinates (@ ^) with G92: they give motion end points only");
  };
  auto need_offset_axes = [&] {
    if (!axis && (mode0 == 520 || mode0 == 920))
      fail_at(b.g_position(kGroupNonModal), ErrorCode::AxisWordsMissing,
              "{} needs at least one axis word: the axes to offset", g_name(mode0));
  };
  if (mode1 != -1) {
    if (mode1 == 800) {
      if ((polar || axis) && !covets)
        fail_at(b.first_axis_position(), ErrorCode::AxisWordsWithG80,
                "axis words with G80: G80 cancels the motion mode, so nothing on this line uses them");
      no_polar_offset();
      need_offset_axes();
    } else if (is_lathe_cycle(mode1) || claims.all_words) {
      // G70-G72 take their profile from other blocks; their words are checked by the cycle
      // (so are those of an extension's cycle that checks its own).
    } else {
      if (covets)
        fail_at(
            std::max(b.g_position(kGroupNonModal), b.g_position(kGroupMotion)), ErrorCode::AxisWordsConflict,
            "{} and {} both take the axis words: put them on separate lines", g_name(mode0), g_name(mode1));
      if (!axis && !polar && mode1 != 0 && mode1 != 10 && mode1 != 20 && mode1 != 30 && mode1 != 52)
        fail_at(b.g_position(kGroupMotion), ErrorCode::AxisWordsMissing,
                "{} needs at least one axis word: the end point", g_name(mode1));
    }
    b.motion = mode1;
  } else if (covets) {
    no_polar_offset();
    need_offset_axes();
  } else if (axis || polar) {
    // G43.1 and G43.2 read the axis words themselves.
    const bool tool_offset_axes = b.g[kGroupToolLength] == 431 || b.g[kGroupToolLength] == 432;
    if ((e_.st_.modal.motion == -1 || e_.st_.modal.motion == 800) && !tool_offset_axes)
      fail_at(b.first_axis_position(), ErrorCode::AxisWordsUnused,
              "axis words, but no motion mode is active (G80) and no code on this line uses them: program "
              "G0, G1, G2 or G3");
    if (!tool_offset_axes) b.motion = e_.st_.modal.motion;
  } else if (ijk && is_arc(e_.st_.modal.motion)) {
    b.motion = e_.st_.modal.motion;
  }
  if (polar && b.motion == -1)
    fail_at(b.polar_position(), ErrorCode::PolarWithoutMotion,
            "polar coordinates (@ ^) give motion end points, and this line has no motion");
}

void BlockChecks::check_block() {
  // Tested here, not inside: most blocks have no code of the non-modal group, and the call cost
  // more than the test (gcode_bench, docs/performance.md).
  if (e_.block_.g[kGroupNonModal] != -1) check_g_codes();
  if (e_.block_.m_count > 4)
    fail_at(fifth_m_position(e_.block_), ErrorCode::TooManyMCodes,
            "a fifth M code on this line: a line may hold four at most");
  check_other_codes();
  if (e_.ext_ == nullptr) return;
  // Only groups that can hold an extension's code are looked at, and the test for a handler
  // stays here: a call per group would cost more than the checks of a typical block together.
  for (std::uint32_t groups = e_.extension_groups_; groups != 0; groups &= groups - 1) {
    const int group = std::countr_zero(groups);
    const int code = e_.block_.g[static_cast<std::size_t>(group)];
    if (extension_handler(code) != nullptr) check_extension(code, e_.block_.g_position(group));
  }
  if (e_.block_.motion != e_.block_.g[kGroupMotion] && extension_handler(e_.block_.motion) != nullptr)
    check_extension(e_.block_.motion, e_.block_.first_axis_position());
}

// What the extension codes of the block claim (their Traits): words they take, the axis
// words as their data, or all of their block's words. The motion code and the codes of the
// groups only extensions know are asked.
BlockChecks::ExtensionClaims BlockChecks::extension_claims() const {
  const Block& b = e_.block_;
  ExtensionClaims claims;
  const int motion = b.g[kGroupMotion] != -1 ? b.g[kGroupMotion] : b.motion;
  if (!b.extension_groups && extension_handler(motion) == nullptr) return claims;  // most blocks
  auto ask = [&](int code) {
    const CodeHandler* h = extension_handler(code);
    if (h == nullptr) return;
    const CodeHandler::Traits t = h->traits(code);
    claims.words |= t.words;
    claims.axis_words = claims.axis_words || t.axis_words;
    claims.all_words = claims.all_words || t.all_words;
  };
  if (b.extension_groups) {
    for (int group = kGroupScaling; group < kGGroupCount; ++group) ask(b.g[static_cast<std::size_t>(group)]);
  }
  ask(motion);
  return claims;
}

void BlockChecks::check_extension(int code, int position) {
  if (auto problem = extension_handler(code)->check(e_.block_, code, e_.st_))
    throw GcodeError(problem->code, problem->message, position);
}

void BlockChecks::check_g_codes() {
  const Block& b = e_.block_;
  const int mode0 = b.g[kGroupNonModal];
  const int mode1 = b.g[kGroupMotion];
  const int at0 = b.g_position(kGroupNonModal);
  if (mode0 == 40) {
    if (!b.has('p')) fail_at(at0, ErrorCode::DwellMissing, "G4 needs a P word: the dwell time in seconds");
    if (b.get('p') == -1.0)
      fail_at(b.word_position('p'), ErrorCode::DwellMissing,
              "G4 P-1 reads as no dwell time: give the seconds to wait");
    if (is_arc(mode1))
      fail_at(std::max(at0, b.g_position(kGroupMotion)), ErrorCode::DwellWithArc,
              "G4 and {} on one line: both take P (dwell seconds, arc turns); put them on separate lines",
              g_name(mode1));
  } else if (mode0 == 100) {
    check_g10();
  } else if (mode0 == 53) {
    if (mode1 != 52 && mode1 != -1) fail(ErrorCode::NurbsBlockCodes, "G5.3 can share a block only with G5.2");
  } else if (mode0 == 530) {
    if (b.motion == -1)
      fail_at(at0, ErrorCode::G53Motion, "G53 needs a G0 or G1 move on its line (in machine coordinates)");
    if (b.motion != 0 && b.motion != 10)
      fail_at(at0, ErrorCode::G53Motion, "G53 moves in machine coordinates with G0 or G1 only, not {}",
              g_name(b.motion));
    if (b.g[kGroupDistance] == 910 ||
        (b.g[kGroupDistance] != 900 && e_.st_.modal.distance == DistanceMode::Incremental))
      fail_at(at0, ErrorCode::G53Incremental,
              "G53 takes absolute machine coordinates: it cannot be used in G91 (add G90)");
  }
}

void BlockChecks::check_g10() {
  const Block& b = e_.block_;
  const double p = b.p_or(-1.0);
  const int p_int = round_to_int(p);
  const int l = b.has('l') ? static_cast<int>(b.get('l')) : -1;
  const int at_p = b.has('p') ? b.word_position('p') : b.g_position(kGroupNonModal);
  if (l == 0)
    fail_at(b.word_position('l'), ErrorCode::Unsupported, "G10 L0 (reload the tool table) is not supported");
  if (l != 1 && l != 2 && l != 10 && l != 11 && l != 20) {
    if (l == -1)
      fail_at(b.g_position(kGroupNonModal), ErrorCode::G10LInvalid,
              "G10 needs an L word: L1, L2, L10, L11 or L20");
    fail_at(b.word_position('l'), ErrorCode::G10LInvalid, "G10 L{}: L must be 1, 2, 10, 11 or 20", l);
  }
  if ((p + 0.0001) - p_int > 0.0002)
    fail_at(at_p, ErrorCode::G10PNotInteger, "G10 P{}: P must be a whole number", p);
  if ((l == 2 || l == 20) && (p_int < 0 || p_int > 9)) {
    if (!b.has('p'))
      fail_at(at_p, ErrorCode::G10PRange,
              "G10 L{} needs P: the coordinate system, 1 to 9 (0 = the active one)", l);
    fail_at(at_p, ErrorCode::G10PRange, "G10 L{} P{}: the coordinate system is 1 to 9 (0 = the active one)",
            l, p_int);
  }
  if ((l == 1 || l == 10 || l == 11) && p_int < 1) {
    if (!b.has('p')) fail_at(at_p, ErrorCode::G10PRange, "G10 L{} needs P: the tool number, 1 or more", l);
    fail_at(at_p, ErrorCode::G10PRange, "G10 L{} P{}: the tool number must be 1 or more", l, p_int);
  }
}

void BlockChecks::check_other_codes() {
  // Words that extension codes take are theirs to check: the rules see the block without them.
  if (e_.ext_ != nullptr) {
    const ExtensionClaims claims = extension_claims();
    if (claims.all_words) return;
    if (claims.words != 0) {
      Block without_claimed = e_.block_;
      without_claimed.words &= ~claims.words;
      return check_word_rules(without_claimed);
    }
  }
  check_word_rules(e_.block_);
}

void BlockChecks::check_word_rules(const Block& b) {
  if (b.o_type == OWord::M98) return check_m98(b);
  const int motion = b.motion;
  const int m5 = b.m[kGroupIo], m6 = b.m[kGroupToolChange], m7 = b.m[kGroupSpindle], m9 = b.m[kGroupOverride];
  const int g0 = b.g[kGroupNonModal], g7 = b.g[kGroupCutterComp], g8 = b.g[kGroupToolLength];
  const int g13 = b.g[kGroupControl], g14 = b.g[kGroupSpindleMode];
  const bool user_m = b.m[kGroupUser] != -1;
  const bool lathe = is_lathe_cycle(motion);
  if (user_m) return;   // user M codes take any words
  if (b.dollar_flag && !b.has('s') && m7 != 3 && m7 != 4 && m7 != 5 && m7 != 19 && m9 != 51 &&
      motion != 330 && motion != 331 && motion != 760)
    fail_at(b.dollar_at, ErrorCode::UnusedWord,
            "$ word (spindle number) used by no code on this line: $ belongs with S, M3, M4, M5, M19, M51, "
            "G33, G33.1 or G76");
  // Most blocks carry axis words and F/S only: none of the rules below can apply.
  if (b.has('f') || b.has('k') || b.has('p')) check_per_turn(b);
  constexpr auto bit = [](char c) { return 1u << (c - 'a'); };
  constexpr std::uint32_t kRuledWords = bit('d') | bit('e') | bit('h') | bit('i') | bit('j') | bit('k') | bit('l') |
                                        bit('p') | bit('q') | bit('r');
  if ((b.words & kRuledWords) == 0 && !is_cycle(motion) && g14 != 960 && motion != 330 && motion != 331 && motion != 760)
    return;
  for (char c : {'a', 'b', 'c'}) {
    if (b.has(c) && is_cycle(motion))
      fail_at(b.word_position(c), ErrorCode::CycleRotaryAxis,
              "{} word in a canned cycle: cycles move the linear axes only", upper(c));
  }
  if (b.has('d') && g7 != 410 && g7 != 420 && g7 != 411 && g7 != 421 && g14 != 960 && !lathe)
    unused_word(b, 'd', "G41, G41.1, G42, G42.1, G96 or a lathe cycle");
  if (b.has('e') && motion != 760 && motion != 700 && m5 != 66 && m5 != 67 && m5 != 68)
    unused_word(b, 'e', "M66, M67, M68, G70 or G76");
  if (b.has('h') && g8 != 430 && motion != 760 && g8 != 432) unused_word(b, 'h', "G43, G43.2 or G76");
  const bool arcish = is_arc(motion) || motion == 50 || motion == 51 || motion == 760 || motion == 870;
  if (b.has('i') && !arcish && motion != 331 && g0 != 100 && !lathe)
    unused_word(b, 'i', "G2, G3, G5, G5.1, G10, G33.1, G76, G87 or a lathe cycle");
  if (b.has('j') && !arcish && g0 != 100 && !lathe)
    unused_word(b, 'j', "G2, G3, G5, G5.1, G10, G76, G87 or a lathe cycle");
  if (b.has('k') && !is_arc(motion) && motion != 330 && motion != 331 && motion != 760 && motion != 870 &&
      !lathe)
    unused_word(b, 'k', "G2, G3, G33, G33.1, G76, G87 or a lathe cycle");
  if (b.has('l') && !(motion >= 810 && motion <= 890) && motion != 760 && motion != 52 && motion != 730 &&
      !lathe && g0 != 100 && g7 != 410 && g7 != 411 && g7 != 420 && g7 != 421 && m5 != 66)
    unused_word(b, 'l', "G10, G41, G42, a canned cycle, G5.2, G76 or M66");
  if (b.has('p')) check_p_word();
  if (b.has('q') && b.get('q') != -1.0) {
    if (motion != 830 && motion != 730 && motion != 50 && !lathe && motion != 760 && m5 != 66 && m5 != 67 && m5 != 68 &&
        g0 != 100 && m6 != 61 && g13 != 640 && m7 != 19)
      unused_word(b, 'q', "G5, G10, G64, G73, G76, G83, M19, M61, M66, M67, M68 or a lathe cycle");
  }
  if (b.has('r')) {
    if (!is_arc(motion) && motion != 760 && !(motion >= 810 && motion <= 890) && motion != 730 && !lathe &&
        motion != 740 && g7 != 411 && g7 != 421 && g0 != 100 && m7 != 19)
      unused_word(b, 'r', "G2, G3, G10, G41.1, G42.1, a canned cycle, G76, M19 or a lathe cycle");
    if (m7 == 19 && (b.get('r') > 360.0 || b.get('r') < 0.0))
      fail_at(b.word_position('r'), ErrorCode::M19Angle,
              "M19 R{}: the orientation angle must lie within 0..360 degrees", b.get('r'));
  }
  if (!b.has('s') && g14 == 960)
    fail_at(b.g_position(kGroupSpindleMode), ErrorCode::SurfaceSpeedMissing,
            "G96 needs an S word: the surface speed");
  if (motion == 330 || motion == 331) {
    if (!b.has('k'))
      fail_at(b.motion_position(), ErrorCode::ThreadPitchMissing,
              "{} needs a K word: the distance moved per spindle turn", g_name(motion));
    if (b.has('f'))
      fail_at(b.word_position('f'), ErrorCode::ThreadFeedWord,
              "F word on a {} line: the feed follows the spindle (K per turn), so remove F", g_name(motion));
  }
  if (motion == 760) {
    if (b.p_or(-1.0) == -1.0)
      fail_at(b.motion_position(), ErrorCode::ThreadG76WordMissing, "G76 needs a P word: the thread pitch");
    if (!b.has('i') || !b.has('j') || !b.has('k'))
      fail_at(b.motion_position(), ErrorCode::ThreadG76WordMissing,
              "G76 needs I, J and K words (thread offset, first cut depth, full thread depth): {}{}{}missing",
              b.has('i') ? "" : "I ", b.has('j') ? "" : "J ", b.has('k') ? "" : "K ");
  }
}

// A distance per spindle turn (a thread's pitch, G95's feed) below the least increment a program
// states (0.0001 mm, 0.00001 in) is a move that never ends: K0 would stand still at the spindle's
// full speed for ever. LinuxCNC's rs274 passes them; opencnc refuses them where they are written
// (docs/conformance.md, "Stricter than LinuxCNC").
void BlockChecks::check_per_turn(const Block& b) {
  const int units = b.g[kGroupUnits];
  const bool inch = units == 200 || (units == -1 && e_.st_.modal.units == canon::Units::Inch);
  const double least = inch ? 1e-5 : 1e-4;
  const char* unit = inch ? "in" : "mm";
  const int motion = b.motion;
  const auto small = [least](double v) { return std::fabs(v) < least; };
  if ((motion == 330 || motion == 331) && b.has('k') && small(b.get('k')))
    fail_at(b.word_position('k'), ErrorCode::PerTurnTooSmall,
            "{} K{}: a pitch below {} {} per turn never ends (the least increment a program states)",
            g_name(motion), b.get('k'), least, unit);
  if (motion == 760 && b.has('p') && small(b.get('p')))
    fail_at(b.word_position('p'), ErrorCode::PerTurnTooSmall,
            "G76 P{}: a pitch below {} {} per turn never ends (the least increment a program states)",
            b.get('p'), least, unit);
  const int feed_mode = b.g[kGroupFeedMode];
  const bool per_turn =
      feed_mode == 950 || (feed_mode == -1 && e_.st_.modal.feed_mode == canon::FeedMode::UnitsPerRevolution);
  if (per_turn && b.has('f') && b.get('f') != 0 && small(b.get('f')))
    fail_at(b.word_position('f'), ErrorCode::PerTurnTooSmall,
            "G95 F{}: a feed below {} {} per turn never ends (the least increment a program states)",
            b.get('f'), least, unit);
}

// An M98 line: P (the subprogram's number, whole) and L (calls, 0 or more: the parser refuses
// a negative L) are its words.
// LinuxCNC's word rules apply to the others; what they let through (axis words of a modal
// motion, F, S, T, other codes), LinuxCNC reads and ignores: refused here, since a reader
// would expect it to act.
void BlockChecks::check_m98(const Block& b) {
  const int at = b.o_at;
  if (!b.has('p'))
    fail_at(at, ErrorCode::FanucCallProgramMissing,
            "M98 needs a P word: the number of the subprogram (O number) to call");
  const double p = b.get('p');
  if (std::fabs(p - std::floor(p + 0.5)) > 0.0001)
    fail_at(b.word_position('p'), ErrorCode::NotAnInteger, "M98 P{}: a subprogram's number is a whole number",
            p);
  Block rest = b;
  rest.o_type = OWord::None;
  rest.words &= ~((1u << ('p' - 'a')) | (1u << ('l' - 'a')));
  check_word_rules(rest);
  int first = -1;
  const auto take = [&first](int position) {
    if (position >= 0 && (first < 0 || position < first)) first = position;
  };
  for (int letter = 0; letter < 26; ++letter) {
    if ((rest.words >> letter) & 1u) take(rest.word_position(static_cast<char>('a' + letter)));
  }
  for (int group = 0; group < kGGroupCount; ++group) take(rest.g_position(group));
  for (int group = 0; group < kMGroupCount; ++group) take(rest.m_position(group));
  if (rest.dollar_flag) take(rest.dollar_at);
  if (rest.radius_flag || rest.theta_flag) take(rest.polar_position());
  if (first >= 0)
    fail_at(first, ErrorCode::OwordSyntax,
            "a word other than P and L on an M98 line: the line only calls the subprogram, so put it on a "
            "line of "
            "its own");
}

// P: which codes use it, and the values arcs (turns) and M19 (direction) accept.
void BlockChecks::check_p_word() {
  const Block& b = e_.block_;
  const int motion = b.motion;
  const int m5 = b.m[kGroupIo], m7 = b.m[kGroupSpindle], m9 = b.m[kGroupOverride];
  const int g0 = b.g[kGroupNonModal], g13 = b.g[kGroupControl];
  if (g0 != 100 && g0 != 40 && g13 != 640 && motion != 760 && motion != 820 && motion != 860 &&
      motion != 880 && motion != 890 && motion != 50 && motion != 52 && !is_arc(motion) &&
      !is_lathe_cycle(motion) && motion != 740 && motion != 840 && !(m9 >= 50 && m9 <= 53) &&
      !(m5 >= 62 && m5 <= 66) && m7 != 19)
    unused_word(b, 'p',
                "G2, G3, G4, G5, G5.2, G10, G64, G74, G76, G82, G84, G86, G88, G89, M19, M50-M53, M62-M66 or "
                "a lathe cycle");
  const double p = b.get('p');
  const int p_value = round_to_int(p);
  const int at = b.word_position('p');
  const bool whole = std::fabs(p_value - p) <= 0.001;
  if (is_arc(motion) && !whole)
    fail_at(at, ErrorCode::ArcTurnsNotInteger, "P{}: the number of arc turns must be a whole number", p);
  if (m7 == 19 && (!whole || p_value > 2 || p_value < 0))
    fail_at(at, ErrorCode::M19Direction,
            "M19 P{}: the direction is 0 (either), 1 (clockwise) or 2 (counterclockwise)", p);
  if (is_arc(motion) && p_value < 1)
    fail_at(at, ErrorCode::ArcTurnsRange, "P{}: an arc makes 1 or more turns", p_value);
}

}  // namespace opencnc::gcode
