// SPDX-License-Identifier: GPL-3.0-or-later
// store::Material — one row of a cut chart (a material and thickness with the process settings a
// plasma or oxy-fuel cut of it needs), its checks, and the chart as CSV (docs/cutting.md).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/core/diagnostic.hpp"

namespace opencnc::store {

/// How the chart's row cuts.
enum class CutProcess { Plasma, OxyFuel };

/// One material of a cut chart, selected by its number (`M194 P<number>` or the HMI).
struct Material {
  int number = 0;  ///< 1 … 99999
  std::string name;
  double thickness_mm = 0;
  CutProcess process = CutProcess::Plasma;
  double kerf_width_mm = 0;  ///< drives G41/G42 (radius = kerf / 2)
  double feed_mm_min = 0;    ///< the cut's feed; a program's F is checked against it
  double pierce_height_mm = 0;
  double pierce_delay_s = 0;
  double cut_height_mm = 0;     ///< at most the pierce height
  double arc_voltage_v = 0;     ///< the voltage the height control holds; 0: sampled (auto volts)
  double amperage_a = 0;        ///< for the operator (set on the power source)
  double puddle_height_mm = 0;  ///< a puddle jump after the pierce (0: none)
  double puddle_delay_s = 0;
  double preheat_s = 0;  ///< oxy-fuel: the preheat's time (0: the profile's); a plasma row has none
  bool operator==(const Material&) const = default;
};

/// One field of a Material by name, for CSV columns, audit rows and the HMI's edits.
struct MaterialField {
  const char* name;  ///< CSV column and audit name: "kerf_width_mm"
  bool required;     ///< a CSV must have the column
};
/// The fields in CSV order.
const std::vector<MaterialField>& material_fields();
/// A field's value as text ("plasma", "1.5", the name as is); empty for an unknown field.
std::string field_text(const Material& m, std::string_view field);
/// Sets a field from text; the reason when the text is not a value of that field.
std::optional<std::string> set_field(Material& m, std::string_view field, std::string_view text);

/// A number field's value (0 for a text field or an unknown one).
double field_number(const Material& m, std::string_view field) noexcept;
/// Sets a number field (nothing for a text field or an unknown one).
void set_number(Material& m, std::string_view field, double value) noexcept;

const char* to_string(CutProcess p) noexcept;
std::optional<CutProcess> parse_process(std::string_view text) noexcept;

/// What is wrong with `m` (the field's name first: "cut_height_mm: 4 is above the pierce height
/// 3.8"), or nothing. Any thread.
struct Invalid {
  std::string field, message;
};
std::optional<Invalid> invalid(const Material& m);
/// The same for a whole chart: each row, and no number twice.
std::optional<Invalid> invalid(const std::vector<Material>& chart);

/// The material numbered `number`, or null. Any thread.
const Material* find(const std::vector<Material>& chart, int number) noexcept;

/// A cut chart from CSV text: a header naming the columns (any order; the puddle and preheat columns may be
/// left out), one material a line, `#` comment lines and blank lines skipped, fields quoted with
/// "" when they hold a comma or a quote. Every problem is an error at `file:line:col` in `diags`;
/// with any, nothing is returned. Any thread.
std::optional<std::vector<Material>> parse_cut_chart_csv(std::string_view text, const std::string& file,
                                                         Diagnostics& diags);
/// The chart as CSV (header, then one line per material by number); parse_cut_chart_csv reads
/// it back equal. Any thread.
std::string format_cut_chart_csv(const std::vector<Material>& chart);

}  // namespace opencnc::store
