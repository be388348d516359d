// SPDX-License-Identifier: GPL-3.0-or-later
// Block — one parsed line of G-code: its words, G/M codes by modal group, comment, O-word.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

/// G codes are kept ×10 as integers (G1 = 10, G59.3 = 593), as LinuxCNC does.
constexpr int gcode(int whole, int tenth = 0) noexcept { return whole * 10 + tenth; }

/// LinuxCNC's G modal groups (indices into Block::g).
enum GGroup : int {
  kGroupNonModal = 0, kGroupMotion = 1, kGroupPlane = 2, kGroupDistance = 3, kGroupIjkDistance = 4,
  kGroupFeedMode = 5, kGroupUnits = 6, kGroupCutterComp = 7, kGroupToolLength = 8,
  kGroupRetract = 10, kGroupCoordSystem = 12, kGroupControl = 13, kGroupSpindleMode = 14,
  kGroupLatheDiameter = 15,
  // Groups of codes only extensions know (the Fanuc dialect's G50/G51, G50.1/G51.1, G68/G69).
  kGroupScaling = 16, kGroupMirror = 17, kGroupRotation = 18, kGGroupCount = 19
};
/// LinuxCNC's M modal groups (indices into Block::m).
enum MGroup : int {
  kGroupStop = 4, kGroupIo = 5, kGroupToolChange = 6, kGroupSpindle = 7, kGroupCoolant = 8,
  kGroupOverride = 9, kGroupUser = 10, kMGroupCount = 11
};

/// O-word statement kinds.
enum class OWord : std::uint8_t {
  None, Sub, EndSub, Call, Do, While, If, ElseIf, Else, EndIf, Break, Continue, EndWhile,
  Return, Repeat, EndRepeat,
  Program,     ///< a bare O number: a program number line, or a numbered subprogram's start
  M98,         ///< LinuxCNC dialect: `M98 P L` at the start of a line, a numbered subprogram call
  M99,         ///< LinuxCNC dialect: `M99` at the start of a line in a subprogram, its return
  // Fanuc macro statements (docs/dialects.md):
  Goto,        ///< GOTO n, or IF [..] GOTO n whose condition holds (o_value = n)
  FanucWhile,  ///< WHILE [..] DO m, or DO m alone (o_value = condition, loop_id = m)
  FanucEnd,    ///< END m (loop_id = m)
  MacroCall,   ///< G65 P.. L.. with arguments (o_value = program, args by local variable)
  BlockRange,  ///< Fanuc lathe G70 P Q: run the blocks numbered P to Q (args[0], args[1]; F in args[2])
};

/// One parsed block. Letter words are stored by letter; integer words (H, L, M, T) are
/// checked to be integers when read. Not thread-safe; reused for every line.
struct Block {
  std::uint32_t words = 0;                  ///< bit (letter - 'a') set per letter word present
  std::array<double, 26> value{};           ///< value of each letter word
  std::array<std::uint8_t, 26> at{};        ///< where each letter word starts in the normalised line
  std::array<std::int16_t, kGGroupCount> g{};   ///< G code ×10 by group, -1 = none
  std::array<std::int16_t, kMGroupCount> m{};   ///< M code by group, -1 = none
  std::array<std::uint8_t, kGGroupCount> g_at{};  ///< where each group's G code starts (when present)
  std::array<std::uint8_t, kMGroupCount> m_at{};  ///< where each group's M code starts (when present)
  int m_count = 0;
  int motion = -1;                          ///< motion to perform (G ×10), -1 = none
  bool n_present = false;
  bool extension_groups = false;            ///< a code in a group only extensions know (>= kGroupScaling)
  std::int64_t n_number = -1;               ///< the N word's whole number (-1: none or too long)
  std::uint32_t decimal = 0;                ///< Fanuc: bit per letter word written with a decimal point
  std::string_view comment;                 ///< text of the last ( ) comment
  bool has_comment = false;
  bool radius_flag = false, theta_flag = false;   ///< polar @ and ^ words
  double radius = 0, theta = 0;
  bool dollar_flag = false;                 ///< $ spindle selector
  double dollar = 0;
  std::uint8_t radius_at = 0, theta_at = 0, dollar_at = 0;  ///< where @, ^ and $ start
  std::uint8_t o_at = 0;                                    ///< where the O-word starts

  OWord o_type = OWord::None;
  std::string o_name;                       ///< label key ("sub#100") or sub name
  std::array<double, kSubArgumentCount> args{};   ///< `call` arguments
  int arg_count = 0;
  std::uint32_t arg_given = 0;              ///< G65: bit k set when local #k+1 is an argument
  double o_value = 0;                       ///< condition of if/while/repeat, value of return
  bool o_has_value = false;
  int loop_id = 0;                          ///< Fanuc DO/END number
  int repeat = 1;                           ///< G65 L: times the macro runs

  bool has(char letter) const noexcept { return (words >> (letter - 'a')) & 1u; }
  double get(char letter) const noexcept { return value[static_cast<std::size_t>(letter - 'a')]; }
  /// LinuxCNC's convention for P/Q: absent reads as -1.
  double p_or(double absent) const noexcept { return has('p') ? get('p') : absent; }
  double q_or(double absent) const noexcept { return has('q') ? get('q') : absent; }
  bool any_axis() const noexcept { return (words & kAxisWordBits) != 0; }

  // Where things start in the normalised line, for the column of an error (-1 = absent).
  int word_position(char letter) const noexcept {
    return has(letter) ? at[static_cast<std::size_t>(letter - 'a')] : -1;
  }
  int g_position(int group) const noexcept {
    return g[static_cast<std::size_t>(group)] == -1 ? -1 : g_at[static_cast<std::size_t>(group)];
  }
  int m_position(int group) const noexcept {
    return m[static_cast<std::size_t>(group)] == -1 ? -1 : m_at[static_cast<std::size_t>(group)];
  }
  /// The first axis word or polar word of the line, -1 if none.
  int first_axis_position() const noexcept {
    int first = -1;
    auto take = [&first](int p) { first = (first == -1 || (p != -1 && p < first)) ? p : first; };
    for (char c : {'x', 'y', 'z', 'a', 'b', 'c', 'u', 'v', 'w'}) take(word_position(c));
    if (radius_flag) take(radius_at);
    if (theta_flag) take(theta_at);
    return first;
  }
  /// The first polar word (@ or ^), -1 if none.
  int polar_position() const noexcept {
    if (radius_flag && theta_flag) return radius_at < theta_at ? radius_at : theta_at;
    return radius_flag ? radius_at : theta_flag ? theta_at : -1;
  }
  /// Where the block's motion is named: its motion G code, else (a modal motion) its first axis word.
  int motion_position() const noexcept {
    const int code = g_position(kGroupMotion);
    return code != -1 ? code : first_axis_position();
  }

  /// Bits of the nine axis letters x y z a b c u v w.
  static constexpr std::uint32_t kAxisWordBits =
      (1u << ('x' - 'a')) | (1u << ('y' - 'a')) | (1u << ('z' - 'a')) | (1u << ('a' - 'a')) |
      (1u << ('b' - 'a')) | (1u << ('c' - 'a')) | (1u << ('u' - 'a')) | (1u << ('v' - 'a')) |
      (1u << ('w' - 'a'));

  void clear() noexcept {
    words = 0;
    g.fill(-1);
    m.fill(-1);
    m_count = 0;
    motion = -1;
    n_present = false;
    extension_groups = false;
    n_number = -1;
    decimal = 0;
    has_comment = false;
    comment = {};
    radius_flag = theta_flag = dollar_flag = false;
    o_type = OWord::None;
    arg_count = 0;
    arg_given = 0;
    o_has_value = false;
    loop_id = 0;
    repeat = 1;
  }
};

}  // namespace opencnc::gcode
