// SPDX-License-Identifier: GPL-3.0-or-later
// Cut chart rows: fields by name, their checks, and the chart as CSV with errors at line:col.
#include "opencnc/store/cut_chart.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

#include <fmt/format.h>

namespace opencnc::store {

namespace {

// A number field of Material by its name (the text fields are handled apart).
double* number_field(Material& m, std::string_view f) noexcept {
  if (f == "thickness_mm") return &m.thickness_mm;
  if (f == "kerf_width_mm") return &m.kerf_width_mm;
  if (f == "feed_mm_min") return &m.feed_mm_min;
  if (f == "pierce_height_mm") return &m.pierce_height_mm;
  if (f == "pierce_delay_s") return &m.pierce_delay_s;
  if (f == "cut_height_mm") return &m.cut_height_mm;
  if (f == "arc_voltage_v") return &m.arc_voltage_v;
  if (f == "amperage_a") return &m.amperage_a;
  if (f == "puddle_height_mm") return &m.puddle_height_mm;
  if (f == "puddle_delay_s") return &m.puddle_delay_s;
  if (f == "preheat_s") return &m.preheat_s;
  return nullptr;
}

std::optional<double> parse_number(std::string_view t) noexcept {
  while (!t.empty() && (t.front() == ' ' || t.front() == '\t')) t.remove_prefix(1);
  while (!t.empty() && (t.back() == ' ' || t.back() == '\t')) t.remove_suffix(1);
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  double v = 0;
  const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec != std::errc() || p != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string number_text(double v) {
  return fmt::format("{}", v);
}

// One CSV field: its text (quotes removed) and its 1-based column.
struct Field {
  std::string text;
  std::uint32_t col = 0;
};

// Splits one line into fields; the reason and column when a quote is not closed or text
// follows a closing quote.
bool split(std::string_view line, std::vector<Field>& out, std::string& why, std::uint32_t& at) {
  out.clear();
  std::size_t i = 0;
  for (;;) {
    Field f;
    f.col = static_cast<std::uint32_t>(i + 1);
    std::size_t j = i;
    while (j < line.size() && (line[j] == ' ' || line[j] == '\t')) ++j;
    if (j < line.size() && line[j] == '"') {
      const std::size_t open = j;
      ++j;
      for (;;) {
        if (j >= line.size()) {
          why = "a quoted field is not closed";
          at = static_cast<std::uint32_t>(open + 1);
          return false;
        }
        if (line[j] == '"') {
          if (j + 1 < line.size() && line[j + 1] == '"') {
            f.text += '"';
            j += 2;
            continue;
          }
          ++j;
          break;
        }
        f.text += line[j++];
      }
      while (j < line.size() && (line[j] == ' ' || line[j] == '\t')) ++j;
      if (j < line.size() && line[j] != ',') {
        why = "text after a closing quote (quote the whole field)";
        at = static_cast<std::uint32_t>(j + 1);
        return false;
      }
    } else {
      const std::size_t end = std::min(line.find(',', i), line.size());
      f.text = std::string(line.substr(i, end - i));
      j = end;
    }
    out.push_back(std::move(f));
    if (j >= line.size()) return true;
    i = j + 1;  // past the comma
  }
}

std::string quoted(const std::string& s) {
  if (s.find_first_of(",\"\n#") == std::string::npos && (s.empty() || (s.front() != ' ' && s.back() != ' ')))
    return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

const std::vector<MaterialField>& material_fields() {
  static const std::vector<MaterialField> fields = {
      {"number", true},           {"name", true},           {"thickness_mm", true},
      {"process", true},          {"kerf_width_mm", true},  {"feed_mm_min", true},
      {"pierce_height_mm", true}, {"pierce_delay_s", true}, {"cut_height_mm", true},
      {"arc_voltage_v", true},    {"amperage_a", true},     {"puddle_height_mm", false},
      {"puddle_delay_s", false},  {"preheat_s", false}};
  return fields;
}

double field_number(const Material& m, std::string_view field) noexcept {
  if (field == "number") return m.number;
  const double* v = number_field(const_cast<Material&>(m), field);
  return v != nullptr ? *v : 0.0;
}

void set_number(Material& m, std::string_view field, double value) noexcept {
  if (double* v = number_field(m, field)) *v = value;
}

const char* to_string(CutProcess p) noexcept {
  return p == CutProcess::Plasma ? "plasma" : "oxy-fuel";
}

std::optional<CutProcess> parse_process(std::string_view t) noexcept {
  if (t == "plasma") return CutProcess::Plasma;
  if (t == "oxy-fuel" || t == "oxyfuel" || t == "flame") return CutProcess::OxyFuel;
  return std::nullopt;
}

std::string field_text(const Material& m, std::string_view f) {
  if (f == "number") return std::to_string(m.number);
  if (f == "name") return m.name;
  if (f == "process") return to_string(m.process);
  if (double* v = number_field(const_cast<Material&>(m), f)) return number_text(*v);
  return {};
}

std::optional<std::string> set_field(Material& m, std::string_view f, std::string_view text) {
  if (f == "name") {
    m.name = std::string(text);
    return std::nullopt;
  }
  if (f == "process") {
    const auto p = parse_process(text);
    if (!p) return fmt::format("\"{}\" is not a process (plasma or oxy-fuel)", text);
    m.process = *p;
    return std::nullopt;
  }
  const auto v = parse_number(text);
  if (f == "number") {
    if (!v || *v != std::floor(*v) || *v < 1 || *v > 99999)
      return fmt::format("\"{}\" is not a material number (a whole number from 1 to 99999)", text);
    m.number = static_cast<int>(*v);
    return std::nullopt;
  }
  double* slot = number_field(m, f);
  if (slot == nullptr) return fmt::format("no field \"{}\"", f);
  if (!v) return fmt::format("\"{}\" is not a number", text);
  *slot = *v;
  return std::nullopt;
}

std::optional<Invalid> invalid(const Material& m) {
  const auto bad = [](const char* field, std::string message) {
    return std::optional<Invalid>(Invalid{field, std::move(message)});
  };
  if (m.number < 1 || m.number > 99999)
    return bad("number", fmt::format("{} is not from 1 to 99999", m.number));
  if (m.name.empty()) return bad("name", "a material needs a name");
  if (m.name.find('\n') != std::string::npos) return bad("name", "a name is one line");
  const auto positive = [&](const char* f, double v, double max) -> std::optional<Invalid> {
    if (!(v > 0) || v > max)
      return Invalid{f, fmt::format("{} is not above 0 and at most {}", number_text(v), max)};
    return std::nullopt;
  };
  const auto non_negative = [&](const char* f, double v, double max) -> std::optional<Invalid> {
    if (!(v >= 0) || v > max) return Invalid{f, fmt::format("{} is not from 0 to {}", number_text(v), max)};
    return std::nullopt;
  };
  for (auto r :
       {positive("thickness_mm", m.thickness_mm, 500), positive("kerf_width_mm", m.kerf_width_mm, 20),
        positive("feed_mm_min", m.feed_mm_min, 100000), positive("pierce_height_mm", m.pierce_height_mm, 100),
        non_negative("pierce_delay_s", m.pierce_delay_s, 600),
        positive("cut_height_mm", m.cut_height_mm, 100), non_negative("arc_voltage_v", m.arc_voltage_v, 1000),
        non_negative("amperage_a", m.amperage_a, 2000),
        non_negative("puddle_height_mm", m.puddle_height_mm, 100),
        non_negative("puddle_delay_s", m.puddle_delay_s, 600), non_negative("preheat_s", m.preheat_s, 600)}) {
    if (r) return r;
  }
  if (m.cut_height_mm > m.pierce_height_mm)
    return bad("cut_height_mm", fmt::format("{} is above the pierce height {}", number_text(m.cut_height_mm),
                                            number_text(m.pierce_height_mm)));
  if (m.puddle_delay_s > 0 && m.puddle_height_mm == 0)
    return bad("puddle_delay_s", "a puddle delay needs a puddle height");
  if (m.preheat_s > 0 && m.process == CutProcess::Plasma)
    return bad("preheat_s", "a plasma material has no preheat (oxy-fuel only)");
  return std::nullopt;
}

std::optional<Invalid> invalid(const std::vector<Material>& chart) {
  std::set<int> seen;
  for (const Material& m : chart) {
    if (auto r = invalid(m)) {
      r->message = fmt::format("material {}: {}", m.number, r->message);
      return r;
    }
    if (!seen.insert(m.number).second)
      return Invalid{"number", fmt::format("material {} is in the chart twice", m.number)};
  }
  return std::nullopt;
}

const Material* find(const std::vector<Material>& chart, int number) noexcept {
  for (const Material& m : chart)
    if (m.number == number) return &m;
  return nullptr;
}

std::optional<std::vector<Material>> parse_cut_chart_csv(std::string_view text, const std::string& file,
                                                         Diagnostics& diags) {
  const std::size_t errors_before = diags.error_count();
  const auto error = [&](std::uint32_t line, std::uint32_t col, std::string message, const char* code) {
    diags.error(file, line, col, std::move(message), code);
  };
  std::vector<std::string> columns;  // the header's, in its order
  std::vector<Material> chart;
  std::vector<std::uint32_t> number_line;
  std::vector<Field> fields;
  std::uint32_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t eol = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line_no == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // a BOM
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string_view::npos || line[first] == '#') continue;
    std::string why;
    std::uint32_t at = 0;
    if (!split(line, fields, why, at)) {
      error(line_no, at, why, "cutchart.csv-syntax");
      continue;
    }
    if (columns.empty()) {  // the header
      std::set<std::string> seen;
      for (const Field& f : fields) {
        std::string name = f.text;
        name.erase(0, name.find_first_not_of(" \t"));
        name.erase(name.find_last_not_of(" \t") + 1);
        const auto known = std::find_if(material_fields().begin(), material_fields().end(),
                                        [&](const MaterialField& m) { return name == m.name; });
        if (known == material_fields().end())
          error(line_no, f.col, fmt::format("unknown column \"{}\"", name), "cutchart.csv-column");
        else if (!seen.insert(name).second)
          error(line_no, f.col, fmt::format("column \"{}\" is named twice", name), "cutchart.csv-column");
        columns.push_back(name);
      }
      for (const MaterialField& m : material_fields())
        if (m.required && seen.count(m.name) == 0)
          error(line_no, 1, fmt::format("the header has no column \"{}\"", m.name), "cutchart.csv-column");
      if (diags.error_count() > errors_before) return std::nullopt;
      continue;
    }
    if (fields.size() != columns.size()) {
      const std::uint32_t col = fields.size() > columns.size() ? fields[columns.size()].col
                                                               : static_cast<std::uint32_t>(line.size() + 1);
      error(line_no, col,
            fmt::format("{} fields where the header has {} columns", fields.size(), columns.size()),
            "cutchart.csv-fields");
      continue;
    }
    Material m;
    bool ok = true;
    std::uint32_t col_of_number = 1;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      std::string value = fields[i].text;
      if (columns[i] != "name") {
        value.erase(0, value.find_first_not_of(" \t"));
        value.erase(value.find_last_not_of(" \t") + 1);
      }
      if (columns[i] == "number") col_of_number = fields[i].col;
      if (const auto why_not = set_field(m, columns[i], value)) {
        error(line_no, fields[i].col, fmt::format("{}: {}", columns[i], *why_not), "cutchart.csv-value");
        ok = false;
      }
    }
    if (!ok) continue;
    if (const auto bad = invalid(m)) {
      const auto it = std::find(columns.begin(), columns.end(), bad->field);
      const std::uint32_t col =
          it == columns.end() ? 1 : fields[static_cast<std::size_t>(it - columns.begin())].col;
      error(line_no, col, fmt::format("{}: {}", bad->field, bad->message), "cutchart.csv-value");
      continue;
    }
    for (std::size_t k = 0; k < chart.size(); ++k) {
      if (chart[k].number == m.number) {
        error(line_no, col_of_number,
              fmt::format("material {} is already on line {}", m.number, number_line[k]),
              "cutchart.csv-duplicate");
        ok = false;
      }
    }
    if (!ok) continue;
    chart.push_back(std::move(m));
    number_line.push_back(line_no);
  }
  if (columns.empty())
    error(line_no == 0 ? 1 : line_no, 1, "no header line (number,name,…)", "cutchart.csv-column");
  if (diags.error_count() > errors_before) return std::nullopt;
  std::sort(chart.begin(), chart.end(),
            [](const Material& a, const Material& b) { return a.number < b.number; });
  return chart;
}

std::string format_cut_chart_csv(const std::vector<Material>& chart) {
  std::string out;
  for (const MaterialField& f : material_fields()) out += fmt::format("{}{}", out.empty() ? "" : ",", f.name);
  out += '\n';
  std::vector<const Material*> sorted;
  for (const Material& m : chart) sorted.push_back(&m);
  std::sort(sorted.begin(), sorted.end(), [](auto* a, auto* b) { return a->number < b->number; });
  for (const Material* m : sorted) {
    std::string line;
    for (const MaterialField& f : material_fields()) {
      const std::string v = field_text(*m, f.name);
      line +=
          fmt::format("{}{}", line.empty() ? "" : ",", std::string_view(f.name) == "name" ? quoted(v) : v);
    }
    out += line + '\n';
  }
  return out;
}

}  // namespace opencnc::store
