// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc cutchart --db FILE list|show|set|remove|select|import|export|audit`: the plasma table's cut
// chart from the command line (docs/cutting.md, "Cut charts").
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "audit_line.hpp"
#include "cli_files.hpp"
#include "commands.hpp"
#include "opencnc/config/cut_chart_profile.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/hmi/store_json.hpp"
#include "opencnc/store/cut_chart_store.hpp"

namespace opencnc::cli {

namespace cutchart_cli {  // named: the subcommands are compiled in unity batches

constexpr const char* kInterface = "command line";

struct Options {
  std::string db, machine;
  bool json = false;
  std::vector<std::string> words;
  std::string output;
  std::size_t last = 20;
};

int fail(const std::string& message, int rc = kExitProgram) {
  fmt::print(stderr, "error: {}\n", message);
  return rc;
}

void print(const Options& o, const nlohmann::json& j, const std::string& text) {
  if (o.json)
    fmt::print("{}\n", j.dump(2));
  else if (!text.empty())
    fmt::print("{}", text.back() == '\n' ? text : text + "\n");
}

std::optional<int> material_number(const std::vector<std::string>& words) {
  if (words.empty()) return std::nullopt;
  int n = 0;
  const std::string& w = words[0];
  const auto [p, ec] = std::from_chars(w.data(), w.data() + w.size(), n);
  if (ec != std::errc() || p != w.data() + w.size() || n < 1) return std::nullopt;
  return n;
}

std::shared_ptr<store::CutChartStore> open(const Options& o, bool writes) {
  std::string error;
  std::error_code ec;
  const bool exists = std::filesystem::exists(o.db, ec);
  if (writes && exists && ::access(o.db.c_str(), W_OK) != 0) {
    fail(fmt::format("{}: {} (the cut chart is read-only for this user)", o.db, std::strerror(errno)),
         kExitUsage);
    return nullptr;
  }
  auto s = store::CutChartStore::open(o.db, &error, writes, !writes);
  if (s) return s;
  if (!exists)
    fail(fmt::format("{} (`opencnc cutchart --db {} import CHART.csv` creates a cut chart)", error, o.db),
         kExitUsage);
  else
    fail(error, kExitUsage);
  return nullptr;
}

int list(store::CutChartStore& s, const Options& o) {
  std::string error;
  const auto chart = s.chart(&error);
  if (!chart) return fail(error);
  const int selected = s.selected().value_or(0);
  nlohmann::json j = nlohmann::json::array();
  std::string text =
      fmt::format("{:>6}  {:<28} {:>6} {:<8} {:>5} {:>6} {:>6} {:>5} {:>5} {:>6} {:>5}\n", "number", "name",
                  "mm", "process", "kerf", "feed", "pierce", "delay", "cut", "volts", "amps");
  for (const store::Material& m : *chart) {
    j.push_back(hmi::material_json(m));
    text += fmt::format("{:>6}{} {:<28} {:>6} {:<8} {:>5} {:>6} {:>6} {:>5} {:>5} {:>6} {:>5}\n", m.number,
                        m.number == selected ? "*" : " ", m.name, m.thickness_mm, store::to_string(m.process),
                        m.kerf_width_mm, m.feed_mm_min, m.pierce_height_mm, m.pierce_delay_s, m.cut_height_mm,
                        m.arc_voltage_v, m.amperage_a);
  }
  if (selected != 0)
    text += fmt::format("* selected: programs that select no material cut with {}\n", selected);
  print(o, j, text);
  return kExitOk;
}

int show(store::CutChartStore& s, const Options& o) {
  const auto n = material_number(o.words);
  if (!n) return fail("show wants a material number: opencnc cutchart --db FILE show 6", kExitUsage);
  std::string error;
  const auto m = s.material(*n, &error);
  if (!m) return fail(error.empty() ? fmt::format("there is no material {} in {}", *n, o.db) : error);
  std::string text;
  for (const store::MaterialField& f : store::material_fields())
    text += fmt::format("{:<18} {}\n", f.name, store::field_text(*m, f.name));
  print(o, hmi::material_json(*m), text);
  return kExitOk;
}

// set 6 feed_mm_min=2500 kerf_width_mm=1.6 (a new number: every required field given).
int set(store::CutChartStore& s, const Options& o) {
  const auto n = material_number(o.words);
  if (!n || o.words.size() < 2)
    return fail("set wants a material and values: set 6 feed_mm_min=2500", kExitUsage);
  std::string error;
  store::Material m = s.material(*n, &error).value_or(store::Material{});
  if (!error.empty()) return fail(error);
  m.number = *n;
  for (std::size_t i = 1; i < o.words.size(); ++i) {
    const std::string& w = o.words[i];
    const auto eq = w.find('=');
    if (eq == std::string::npos) return fail(fmt::format("'{}' is not field=value", w), kExitUsage);
    const std::string field = w.substr(0, eq);
    if (field == "number") return fail("the number names the material: it is not set", kExitUsage);
    if (const auto why = store::set_field(m, field, w.substr(eq + 1)))
      return fail(fmt::format("{}: {} (nothing changed)", field, *why), kExitUsage);
  }
  if (!s.put(m, kInterface, &error)) return fail(fmt::format("{} (nothing changed)", error));
  print(o, hmi::material_json(m), fmt::format("material {} set", m.number));
  return kExitOk;
}

int remove(store::CutChartStore& s, const Options& o) {
  const auto n = material_number(o.words);
  if (!n) return fail("remove wants a material number", kExitUsage);
  std::string error;
  if (!s.remove(*n, kInterface, &error)) return fail(error);
  print(o, {{"removed", *n}}, fmt::format("material {} removed", *n));
  return kExitOk;
}

int select(store::CutChartStore& s, const Options& o) {
  const bool none = !o.words.empty() && o.words[0] == "0";
  const auto n = none ? std::optional<int>(0) : material_number(o.words);
  if (!n) return fail("select wants a material number (0: none)", kExitUsage);
  std::string error;
  if (!s.select(*n, kInterface, &error)) return fail(error);
  print(o, {{"selected", *n}}, *n == 0 ? "no material selected" : fmt::format("material {} selected", *n));
  return kExitOk;
}

int import(store::CutChartStore& s, const Options& o) {
  const std::string& path = o.words[0];
  std::string text, error;
  if (!read_file(path, text, &error)) return fail(fmt::format("cannot read {}: {}", path, error), kExitUsage);
  Diagnostics d;
  const auto chart = store::parse_cut_chart_csv(text, path, d);
  for (const Diagnostic& x : d.items()) fmt::print(stderr, "{}\n", x.format());
  if (!chart) return fail(fmt::format("{} was not imported: nothing changed", path));
  if (!s.write(*chart, kInterface, fmt::format("import {}", path), &error))
    return fail(fmt::format("{} (nothing changed)", error));
  print(o, {{"imported", path}, {"materials", chart->size()}},
        fmt::format("{}: {} materials are the cut chart now", path, chart->size()));
  return kExitOk;
}

int export_chart(store::CutChartStore& s, const Options& o) {
  std::string error;
  const auto chart = s.chart(&error);
  if (!chart) return fail(error);
  const std::string text = store::format_cut_chart_csv(*chart);
  if (o.output.empty()) {
    fmt::print("{}", text);
    return kExitOk;
  }
  const NamedPath inputs[] = {{"the cut chart", o.db}, {"the profile", o.machine}};
  const NamedPath outputs[] = {{"-o", o.output}};
  auto files = open_outputs(inputs, outputs);
  if (files.empty()) return kExitUsage;
  return write_and_commit(*files[0], text) ? kExitOk : kExitUsage;
}

int audit(store::CutChartStore& s, const Options& o) {
  std::string error;
  const auto entries = s.audit(o.last, &error);
  if (!error.empty()) return fail(error);
  nlohmann::json j = nlohmann::json::array();
  std::string text;
  for (const store::AuditEntry& e : entries) {
    j.push_back(hmi::audit_json(e));
    text += audit_line(e, 20, 26);
  }
  print(o, j, text);
  return kExitOk;
}

int run(const std::string& action, Options o) {
  if (!o.machine.empty()) {
    const config::ProfileLoad load = config::load_profile(o.machine, {});
    for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
    if (!load.ok()) return kExitUsage;
    Diagnostics d;
    const auto chart = config::cut_chart_profile(*load.profile, d);
    for (const Diagnostic& x : d.items()) fmt::print(stderr, "{}\n", x.format());
    if (!chart) return fail(fmt::format("{} has no [cut_chart]", o.machine), kExitUsage);
    if (o.db.empty()) o.db = chart->store;
  }
  if (o.db.empty())
    return fail("name the cut chart: --db FILE (or --machine PROFILE with a [cut_chart])", kExitUsage);
  const bool writes = action == "set" || action == "remove" || action == "import" || action == "select";
  if (action == "import") {
    if (o.words.size() != 1) return fail("import wants one CSV file", kExitUsage);
    if (const std::string why = unreadable_input(o.words[0]); !why.empty())
      return fail(fmt::format("cannot read {}: {}", o.words[0], why), kExitUsage);
  }
  const auto s = open(o, writes);
  if (!s) return kExitUsage;
  if (action == "list") return list(*s, o);
  if (action == "show") return show(*s, o);
  if (action == "set") return set(*s, o);
  if (action == "remove") return remove(*s, o);
  if (action == "select") return select(*s, o);
  if (action == "import") return import(*s, o);
  if (action == "export") return export_chart(*s, o);
  return audit(*s, o);
}

}  // namespace cutchart_cli

void add_cutchart_command(CLI::App& app, Registry& registry) {
  auto o = std::make_shared<cutchart_cli::Options>();
  CLI::App* cmd = app.add_subcommand(
      "cutchart",
      "The plasma table's cut chart: materials with kerf, feed, heights, arc voltage (docs/cutting.md)");
  cmd->require_subcommand(1);
  cmd->add_option("--db", o->db, "The cut chart (SQLite)");
  cmd->add_option("--machine,-m", o->machine, "A profile with [cut_chart]: its store");
  cmd->add_flag("--json", o->json, "Answer in JSON");
  const auto add = [&](const char* name, const char* help, const char* words) {
    CLI::App* sub = cmd->add_subcommand(name, help);
    sub->fallthrough();
    if (words != nullptr) sub->add_option("words", o->words, words);
    sub->callback([o, &registry, name] { registry.set_result(cutchart_cli::run(name, *o)); });
    return sub;
  };
  add("list", "Every material, by number", nullptr);
  add("show", "One material with every field", "NUMBER");
  add("set", "Add or change a material in one transaction: set 6 feed_mm_min=2500 kerf_width_mm=1.6",
      "NUMBER field=value…");
  add("remove", "Remove a material", "NUMBER");
  add("select", "The material programs that select none use (0: none), as the HMI selects it", "NUMBER");
  add("import", "Replace the chart by a CSV file (errors at file:line:col; nothing changes on any)", "FILE");
  add("export", "Write the chart as CSV", nullptr)
      ->add_option("-o,--output", o->output, "The file (default: standard output; never an input)");
  add("audit", "The last changes: when, through which interface, what, old and new value", nullptr)
      ->add_option("--last", o->last, "How many (0: all; default 20)");
}

}  // namespace opencnc::cli
