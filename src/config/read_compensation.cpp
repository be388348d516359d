// SPDX-License-Identifier: GPL-3.0-or-later
// Reading `[axis.<letter>.compensation]`: backlash, its take-up limits, and the pitch-error table
// given at equal intervals (one table or one per direction) or imported from a LinuxCNC comp file.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "opencnc/core/atomic_file.hpp"

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

/// Largest |dE/dx| a lead-screw table may have: a screw 1 % off its pitch is not an error to
/// compensate but a wrong pitch (or a table in the wrong unit).
constexpr double kMaxSlope = 0.01;

/// Reads an array of finite numbers; reports and returns false otherwise.
bool read_numbers(Section& s, std::string_view key, std::vector<double>& out) {
  const toml::node* n = s.find(key);
  const toml::array* a = n != nullptr ? n->as_array() : nullptr;
  if (a == nullptr) {
    s.error(key, fmt::format("{} must be an array of numbers", s.key_path(key)), "config.type");
    return false;
  }
  for (const toml::node& e : *a) {
    const std::optional<double> v = e.value<double>();
    if (!v || !std::isfinite(*v)) {
      s.reporter().error(&e.source(), fmt::format("{} must hold finite numbers", s.key_path(key)),
                         "config.type");
      return false;
    }
    out.push_back(*v);
  }
  return true;
}

/// start + k·interval, k = 0 … n−1.
void equal_intervals(Section& s, std::size_t n, CompensationProfile& c) {
  const double start = s.number_or("start", 0);
  const auto interval = s.number("interval", Bound::Positive);
  if (!interval) {
    if (!s.has("interval")) s.missing("interval");
    return;
  }
  for (std::size_t k = 0; k < n; ++k) c.positions.push_back(start + static_cast<double>(k) * *interval);
}

/// A position in a comp file, for diagnostics.
toml::source_region at_line(const std::shared_ptr<const std::string>& file, std::uint32_t line,
                            std::uint32_t col) {
  toml::source_region r;
  r.begin = {line, col};
  r.end = r.begin;
  r.path = file;
  return r;
}

/// The error of a type 0 line (actual − nominal), rounded to 1e-9 units: the difference of two
/// positions carries their rounding (99.996 − 100 is −0.00400000000000489 in binary), which would
/// make a table written back and read again differ from the one written.
double reached_error(double reached, double nominal) {
  return std::round((reached - nominal) * 1e9) / 1e9;
}

/// A LinuxCNC comp file: "nominal forward reverse" per line, nominals increasing. Type 0 gives
/// where the axis actually is moving up and moving down; type 1 the trims LinuxCNC adds to the
/// command (the negative of the error). Blank lines and lines starting with '#' are skipped;
/// anything else that is not three numbers is an error at its line.
void read_comp_file(Section& s, const std::filesystem::path& path, int type, CompensationProfile& c,
                    std::span<const FileText> files) {
  std::string all;
  const auto given = std::find_if(files.begin(), files.end(), [&](const FileText& f) {
    return std::filesystem::path(f.path).lexically_normal() == path.lexically_normal();
  });
  if (given != files.end()) {
    all = given->text;
  } else if (std::string why; !read_file(path.string(), all, &why)) {
    s.error("comp_file",
            fmt::format("{}: cannot read the comp file {}: {}", s.key_path("comp_file"), path.string(), why),
            "config.file");
    return;
  }
  c.comp_digest = text_digest(all);
  std::istringstream in(all);
  const auto file = std::make_shared<const std::string>(path.string());
  Reporter& r = s.reporter();
  std::string text;
  std::uint32_t line = 0;
  while (std::getline(in, text)) {
    ++line;
    const std::size_t first = text.find_first_not_of(" \t\r");
    if (first == std::string::npos || text[first] == '#') continue;
    std::istringstream fields(text);
    double nominal = 0, up = 0, down = 0;
    std::string extra;
    if (!(fields >> nominal >> up >> down) || (fields >> extra) || !std::isfinite(nominal) ||
        !std::isfinite(up) || !std::isfinite(down)) {
      const auto where = at_line(file, line, static_cast<std::uint32_t>(first + 1));
      r.error(&where, "a comp file line must be three numbers: nominal, forward, reverse",
              "config.comp-file");
      return;
    }
    if (!c.positions.empty() && nominal <= c.positions.back()) {
      const auto where = at_line(file, line, static_cast<std::uint32_t>(first + 1));
      r.error(&where,
              fmt::format("nominal positions must increase ({} follows {})", show(nominal),
                          show(c.positions.back())),
              "config.comp-file");
      return;
    }
    if (c.positions.size() == static_cast<std::size_t>(kMaxCompensationPoints)) {
      const auto where = at_line(file, line, static_cast<std::uint32_t>(first + 1));
      r.error(&where, fmt::format("a comp file holds at most {} points", kMaxCompensationPoints),
              "config.comp-file");
      return;
    }
    c.positions.push_back(nominal);
    c.forward.push_back(type == 0 ? reached_error(up, nominal) : -up);
    c.reverse.push_back(type == 0 ? reached_error(down, nominal) : -down);
  }
  if (c.positions.empty()) {
    s.error("comp_file", fmt::format("{}: {} holds no points", s.key_path("comp_file"), path.string()),
            "config.comp-file");
  }
}

/// The table from `errors` (both ways) or `forward` and `reverse`, at `start` + k·`interval`.
void read_table(Section& s, CompensationProfile& c) {
  const bool one = s.has("errors"), two = s.has("forward") || s.has("reverse");
  if (one && two) {
    s.error("errors",
            fmt::format("{}: give errors (both directions) or forward and reverse, not both", s.path()),
            "config.not-applicable");
    return;
  }
  if (one) {
    if (!read_numbers(s, "errors", c.forward)) return;
    c.reverse = c.forward;
    c.one_table = true;
  } else {
    if (!s.has("forward") || !s.has("reverse")) {
      s.missing(s.has("forward") ? "reverse" : "forward");
      return;
    }
    if (!read_numbers(s, "forward", c.forward) || !read_numbers(s, "reverse", c.reverse)) return;
    if (c.forward.size() != c.reverse.size()) {
      s.error("reverse",
              fmt::format("{}: forward has {} values and reverse {}; they are errors at the same points",
                          s.path(), c.forward.size(), c.reverse.size()),
              "config.range");
      return;
    }
  }
  if (c.forward.empty() || c.forward.size() > static_cast<std::size_t>(kMaxCompensationPoints)) {
    s.error(one ? "errors" : "forward",
            fmt::format("{}: a table has 1 to {} points (it has {})", s.path(), kMaxCompensationPoints,
                        c.forward.size()),
            "config.range");
    return;
  }
  equal_intervals(s, c.forward.size(), c);
}

/// Every segment's slope must be that of a screw error, not of a wrong pitch.
void check_slopes(Section& s, std::string_view key, const CompensationProfile& c) {
  for (std::size_t i = 0; i + 1 < c.positions.size(); ++i) {
    for (const std::vector<double>* t : {&c.forward, &c.reverse}) {
      const double slope = ((*t)[i + 1] - (*t)[i]) / (c.positions[i + 1] - c.positions[i]);
      if (std::abs(slope) > kMaxSlope) {
        s.error(
            key,
            fmt::format("{}: the error changes by {:.4g} per unit between {} and {}, more than a lead-screw "
                        "error can ({}); is the table in the axis' units?",
                        s.path(), slope, show(c.positions[i]), show(c.positions[i + 1]), kMaxSlope),
            "config.range");
        return;
      }
    }
  }
}

void read_axis_compensation(Section& s, AxisProfile& a, double period_s,
                            const std::filesystem::path& base_dir, std::span<const FileText> files) {
  CompensationProfile& c = a.compensation;
  c.present = true;
  c.backlash = s.number_or("backlash", 0, Bound::NonNegative);
  c.takeup_velocity = s.number_or("takeup_velocity", 0.1 * a.max_velocity, Bound::Positive);
  c.takeup_acceleration = s.number_or("takeup_acceleration", 0.1 * a.max_acceleration, Bound::Positive);
  if (s.has("comp_file")) {
    for (std::string_view k : {"errors", "forward", "reverse", "start", "interval"})
      s.reject(k, "does not apply with comp_file (the file gives the table)");
    const auto type = s.integer("comp_file_type", 0, 1);
    if (!type && !s.has("comp_file_type")) s.missing("comp_file_type");
    if (const auto file = s.string("comp_file"); file && type) {
      c.comp_file = *file;
      c.comp_file_type = static_cast<int>(*type);
      const std::filesystem::path p(*file);
      const std::filesystem::path resolved = p.is_absolute() || base_dir.empty() ? p : base_dir / p;
      c.comp_path = resolved.string();
      read_comp_file(s, resolved, c.comp_file_type, c, files);
    }
  } else {
    s.reject("comp_file_type", "needs comp_file");
    if (s.has("errors") || s.has("forward") || s.has("reverse")) {
      read_table(s, c);
    } else {
      for (std::string_view k : {"start", "interval"})
        s.reject(k, "needs a table (errors, or forward and reverse)");
    }
  }
  check_slopes(s, s.has("comp_file") ? "comp_file" : (s.has("errors") ? "errors" : "forward"), c);
  if (a.max_jerk > 0) {
    s.error("backlash",
            fmt::format("{}: compensation on an axis with a jerk limit is not supported yet (the take-up "
                        "limits acceleration only)",
                        s.path()),
            "config.not-applicable");
  }
  const MotionReserve r = compensation_reserve(a, period_s);
  if (r.velocity > 0.5 * a.max_velocity || r.acceleration > 0.5 * a.max_acceleration) {
    s.error(
        s.has("takeup_velocity") ? "takeup_velocity" : "backlash",
        fmt::format(
            "{}: the compensation would take {} of the axis' {} velocity and {} of its {} acceleration "
            "(at most half of each)",
            s.path(), show(r.velocity), show(a.max_velocity), show(r.acceleration), show(a.max_acceleration)),
        "config.range");
  }
}

}  // namespace

void read_compensation(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir,
                       std::span<const FileText> files) {
  const toml::node* axes_node = top.find("axis");
  const toml::table* axes = axes_node != nullptr ? axes_node->as_table() : nullptr;
  if (axes == nullptr) return;
  for (const auto& [key, node] : *axes) {
    const auto axis = axis_from_letter(key.str());
    const toml::table* t = node.as_table();
    if (!axis || t == nullptr) continue;  // reported by read_axes
    AxisProfile* a = nullptr;
    for (AxisProfile& each : profile.axes) {
      if (each.axis == *axis) a = &each;
    }
    const toml::node* c = t->get("compensation");
    if (a == nullptr || c == nullptr || a->compensation.present) continue;  // the first [axis.x] wins
    const std::string path = "axis." + std::string(key.str()) + ".compensation";
    if (!c->is_table()) {
      top.reporter().error(&c->source(), fmt::format("{} must be a table ([{}])", path, path), "config.type");
      continue;
    }
    Section s(*c->as_table(), path,
              {"backlash", "takeup_velocity", "takeup_acceleration", "start", "interval", "errors", "forward",
               "reverse", "comp_file", "comp_file_type"},
              top.reporter());
    if (a->manual()) {
      top.reporter().error(&c->source(),
                           fmt::format("{} does not apply to a manual axis (nothing drives it)", path),
                           "config.not-applicable");
      continue;
    }
    read_axis_compensation(s, *a, profile.servo_period_s, base_dir, files);
  }
}

}  // namespace opencnc::config::detail
