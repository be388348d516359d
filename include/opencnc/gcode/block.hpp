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
  kGroupLatheDiameter = 15, kGGroupCount = 16
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
  Program   ///< a bare O number (Fanuc program number line)
};

/// One parsed block. Letter words are stored by letter; integer words (H, L, M, T) are
/// checked to be integers when read. Not thread-safe; reused for every line.
struct Block {
  std::uint32_t words = 0;                  ///< bit (letter - 'a') set per letter word present
  std::array<double, 26> value{};           ///< value of each letter word
  std::array<std::uint8_t, 26> at{};        ///< where each letter word starts in the normalised line
  std::array<std::int16_t, kGGroupCount> g{};   ///< G code ×10 by group, -1 = none
  std::array<std::int16_t, kMGroupCount> m{};   ///< M code by group, -1 = none
  int m_count = 0;
  int motion = -1;                          ///< motion to perform (G ×10), -1 = none
  bool n_present = false;
  std::string_view comment;                 ///< text of the last ( ) comment
  bool has_comment = false;
  bool radius_flag = false, theta_flag = false;   ///< polar @ and ^ words
  double radius = 0, theta = 0;
  bool dollar_flag = false;                 ///< $ spindle selector
  double dollar = 0;

  OWord o_type = OWord::None;
  std::string o_name;                       ///< label key ("sub#100") or sub name
  std::array<double, kSubArgumentCount> args{};   ///< `call` arguments
  int arg_count = 0;
  double o_value = 0;                       ///< condition of if/while/repeat, value of return
  bool o_has_value = false;

  bool has(char letter) const noexcept { return (words >> (letter - 'a')) & 1u; }
  double get(char letter) const noexcept { return value[static_cast<std::size_t>(letter - 'a')]; }
  /// LinuxCNC's convention for P/Q: absent reads as -1.
  double p_or(double absent) const noexcept { return has('p') ? get('p') : absent; }
  double q_or(double absent) const noexcept { return has('q') ? get('q') : absent; }
  bool any_axis() const noexcept { return (words & kAxisWordBits) != 0; }

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
    has_comment = false;
    comment = {};
    radius_flag = theta_flag = dollar_flag = false;
    o_type = OWord::None;
    arg_count = 0;
    o_has_value = false;
  }
};

}  // namespace opencnc::gcode
