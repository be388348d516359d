// SPDX-License-Identifier: GPL-3.0-or-later
// Tools with cutting edges (T/D) and the parameters an 840D operator types per edge: what the tool
// guard keeps, backs up and checks. Plain values; the LinuxCNC view of them is edge_mapping.hpp.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::tools {

/// The parameters of one cutting edge, in the order of Siemens' $TC_DP numbers.
enum class Param : std::uint8_t {
  Type,              ///< $TC_DP1: tool type (120 end mill, 200 twist drill, 500 turning …)
  CuttingDirection,  ///< $TC_DP2: cutting edge position (turning tools 1..9; 0 for milling tools)
  Length1,           ///< $TC_DP3: geometry length 1 (along Z, the spindle axis, in G17)
  Length2,           ///< $TC_DP4: geometry length 2 (along Y)
  Length3,           ///< $TC_DP5: geometry length 3 (along X)
  Radius,            ///< $TC_DP6: geometry radius
  WearLength1,       ///< $TC_DP12
  WearLength2,       ///< $TC_DP13
  WearLength3,       ///< $TC_DP14
  WearRadius,        ///< $TC_DP15
  BaseLength1,       ///< $TC_DP21: base (adapter) dimension 1
  BaseLength2,       ///< $TC_DP22
  BaseLength3,       ///< $TC_DP23
};
inline constexpr std::size_t kParamCount = 13;

/// How a parameter is checked against the backup (tool_check.hpp).
enum class ParamKind : std::uint8_t {
  Identity,  ///< type and cutting direction: whole numbers, equal or not
  Geometry,  ///< lengths and radius: within the geometry tolerance only
  Wear,      ///< may drift within the wear band
  Base,      ///< adapter dimensions: within the base tolerance
};

struct ParamInfo {
  Param param;
  const char* name;  ///< "length1", "wear_radius" … (command line, JSON, audit)
  ParamKind kind;
  int tc_dp;  ///< Siemens $TC_DP number; the 840D export writes it as R<tc_dp>
};

/// Every parameter in $TC_DP order. Any thread.
const std::array<ParamInfo, kParamCount>& param_table() noexcept;
const ParamInfo& info(Param p) noexcept;
/// The parameter named `name` ("length1"), if any. Any thread.
std::optional<Param> param_named(std::string_view name) noexcept;
/// The parameter written as R<n> in the 840D form, if any. Any thread.
std::optional<Param> param_of_r(int r) noexcept;
/// "identity", "geometry", "wear", "base". Any thread.
const char* to_string(ParamKind k) noexcept;

/// Highest tool number and edges per tool (840D: D1..D9 per tool).
inline constexpr int kMaxToolNumber = 9999;
inline constexpr int kMaxEdge = 9;

/// One cutting edge D of a tool. Lengths in mm.
struct Edge {
  int edge = 1;
  std::array<double, kParamCount> values{};

  double get(Param p) const noexcept { return values[static_cast<std::size_t>(p)]; }
  void set(Param p, double v) noexcept { values[static_cast<std::size_t>(p)] = v; }
  /// Geometry + wear + base of length `i` (1..3): what the machine offsets by.
  double effective_length(int i) const noexcept;
  /// Geometry + wear radius.
  double effective_radius() const noexcept;
  bool operator==(const Edge&) const = default;
};

/// A tool T in pocket `pocket` (0: not in the magazine) with its edges, sorted by D.
struct Tool {
  int tool = 0;
  int pocket = 0;
  std::string comment;
  std::vector<Edge> edges;

  const Edge* edge(int d) const noexcept;
  Edge* edge(int d) noexcept;
  bool operator==(const Tool&) const = default;
};

/// A whole tool table (live or a backup): tools sorted by T. Any thread; not thread-safe for writes.
struct ToolSet {
  std::vector<Tool> tools;

  const Tool* tool(int t) const noexcept;
  Tool* tool(int t) noexcept;
  const Edge* edge(int t, int d) const noexcept;
  /// The tool, added in order (pocket 0, no edges) if it is not there.
  Tool& tool_or_add(int t);
  /// The edge, added in order (all parameters 0) if it is not there (and its tool too).
  Edge& edge_or_add(int t, int d);
  std::size_t edge_count() const noexcept;
  bool operator==(const ToolSet&) const = default;
};

/// Why a tool set cannot be stored ("T0: tool numbers go from 1 to 9999"), or nothing. Checks
/// numbers, edges, finite values, comments without line breaks. Any thread.
std::optional<std::string> invalid(const ToolSet& set);

/// The longest comment a tool may carry (bytes).
inline constexpr std::size_t kMaxCommentBytes = 200;
/// Why `comment` cannot be a tool's comment, or nothing: it is one line of at most
/// kMaxCommentBytes, without control characters (a newline would start a new line of the .tbl
/// file, which the interpreter then reads as a tool). Any thread.
std::optional<std::string> invalid_comment(std::string_view comment);

}  // namespace opencnc::tools
