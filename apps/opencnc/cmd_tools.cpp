// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc tools --db FILE list|show|set|backup|check|diff|accept|restore|import|export|audit`:
// the tool store and its guard from the command line.
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "audit_line.hpp"
#include "cli_files.hpp"
#include "commands.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/hmi/store_json.hpp"
#include "opencnc/store/tool_store.hpp"
#include "opencnc/toolguard/tool_guard.hpp"
#include "opencnc/tools/edge_mapping.hpp"
#include "opencnc/tools/tool_text.hpp"

namespace opencnc::cli {

namespace {

constexpr const char* kInterface = "command line";

struct ToolsOptions {
  std::string db, machine;
  bool json = false;
  std::vector<std::string> words;  // the action's arguments
  std::string file, output, format = "text";
  std::int64_t backup = 0;  // 0: the current one
  bool allow_empty = false;  // import: a table without tools may replace the live one
  std::size_t last = 20;
  tools::CheckTolerances tolerances;
};

nlohmann::json edge_json(const tools::Edge& e) {
  nlohmann::json j = {{"d", e.edge}};
  for (const tools::ParamInfo& p : tools::param_table()) j[p.name] = e.get(p.param);
  j["effective_length1"] = e.effective_length(1);
  j["effective_radius"] = e.effective_radius();
  return j;
}

nlohmann::json tool_json(const tools::Tool& t) {
  nlohmann::json edges = nlohmann::json::array();
  for (const tools::Edge& e : t.edges) edges.push_back(edge_json(e));
  return {{"t", t.tool}, {"pocket", t.pocket}, {"comment", t.comment}, {"edges", edges}};
}

nlohmann::json set_json(const tools::ToolSet& s) {
  nlohmann::json tools = nlohmann::json::array();
  for (const tools::Tool& t : s.tools) tools.push_back(tool_json(t));
  return tools;
}

nlohmann::json difference_json(const tools::Difference& d) {
  const char* what = d.what == tools::Difference::What::Added     ? "added"
                     : d.what == tools::Difference::What::Removed ? "removed"
                                                                  : "changed";
  nlohmann::json j = {{"t", d.tool}, {"d", d.edge}, {"what", what}, {"text", d.text()}};
  if (d.param) {
    j["parameter"] = tools::info(*d.param).name;
    j["kind"] = tools::to_string(tools::info(*d.param).kind);
    j["backup"] = d.backup;
    j["live"] = d.live;
    j["tolerance"] = d.tolerance;
    j["tolerated"] = d.tolerated;
  }
  return j;
}

int fail(const std::string& message, int rc = kExitProgram) {
  fmt::print(stderr, "error: {}\n", message);
  return rc;
}

// "T3" → 3, "D2" → 2; nothing when `word` is not `letter` and a whole number.
std::optional<int> numbered(std::string_view word, char letter) {
  if (word.size() < 2 || (word[0] != letter && word[0] != letter + ('a' - 'A'))) return std::nullopt;
  int n = 0;
  const auto [p, ec] = std::from_chars(word.data() + 1, word.data() + word.size(), n);
  if (ec != std::errc() || p != word.data() + word.size()) return std::nullopt;
  return n;
}

// Actions that only look open the store read-only: a store the user may read but not write
// (another user's, read-only media) is listed and checked all the same.
std::shared_ptr<store::ToolStore> open_store(const ToolsOptions& o, bool writes) {
  std::string error;
  std::error_code ec;
  const bool exists = std::filesystem::exists(o.db, ec);
  if (writes && exists && ::access(o.db.c_str(), W_OK) != 0) {
    fail(
        fmt::format("{}: {} (the store is read-only for this user: list, show, check, diff, export and audit "
                    "read it; changes need write access)",
                    o.db, std::strerror(errno)),
        kExitUsage);
    return nullptr;
  }
  auto s = store::ToolStore::open(o.db, &error, writes, !writes);
  if (s) return s;
  if (!exists)
    fail(fmt::format("{} (`opencnc tools --db {} import TABLE` creates a store)", error, o.db), kExitUsage);
  else
    fail(error, kExitUsage);
  return nullptr;
}

/// Backups are numbered from 1: 0 or a negative number names none (it is not "the current one").
const CLI::Validator kBackupNumber(
    [](std::string& value) -> std::string {
      std::int64_t n = 0;
      const auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
      if (ec != std::errc() || p != value.data() + value.size() || n < 1)
        return fmt::format("backups are numbered from 1, not '{}' (without --backup: the current one)",
                           value);
      return {};
    },
    "BACKUP");

void print(const ToolsOptions& o, const nlohmann::json& j, const std::string& text) {
  if (o.json)
    fmt::print("{}\n", j.dump(2));
  else if (!text.empty())
    fmt::print("{}", text.back() == '\n' ? text : text + "\n");
}

int list(store::ToolStore& s, const ToolsOptions& o) {
  std::string error;
  const auto live = s.live(&error);
  if (!live) return fail(error);
  print(o, set_json(*live), tools::format_listing(*live));
  return kExitOk;
}

int show(store::ToolStore& s, const ToolsOptions& o) {
  const std::optional<int> t = o.words.empty() ? std::nullopt : numbered(o.words[0], 'T');
  if (!t) return fail("show wants a tool: opencnc tools --db FILE show T3", kExitUsage);
  std::string error;
  const auto live = s.live(&error);
  if (!live) return fail(error);
  const tools::Tool* tool = live->tool(*t);
  if (tool == nullptr) return fail(fmt::format("there is no T{} in {}", *t, o.db));
  std::string text = fmt::format("T{} pocket {} {}\n", tool->tool, tool->pocket, tool->comment);
  for (const tools::Edge& e : tool->edges) {
    text += fmt::format("  D{}\n", e.edge);
    for (const tools::ParamInfo& p : tools::param_table())
      text += fmt::format("    {:<18} {:>12}  ($TC_DP{}, {})\n", p.name, tools::format_value(e.get(p.param)),
                          p.tc_dp, tools::to_string(p.kind));
  }
  print(o, tool_json(*tool), text);
  return kExitOk;
}

// set T3 D1 length1=139.225 wear_length1=-0.02 | set T3 pocket=4 comment="…": one transaction,
// applied to the table as committed when it is written (a concurrent writer's values stay).
int set(store::ToolStore& s, const ToolsOptions& o) {
  const std::optional<int> t = o.words.empty() ? std::nullopt : numbered(o.words[0], 'T');
  if (!t) return fail("set wants a tool, an edge and values: set T3 D1 length1=139.225", kExitUsage);
  std::size_t next = 1;
  int d = 1;
  if (o.words.size() > 1) {
    if (const auto e = numbered(o.words[1], 'D')) d = *e, next = 2;
  }
  if (next >= o.words.size()) return fail("set names no value: e.g. length1=139.225", kExitUsage);
  // Every word checked before anything is written.
  std::vector<std::function<void(tools::ToolSet&)>> changes;
  for (std::size_t i = next; i < o.words.size(); ++i) {
    const std::string& w = o.words[i];
    const auto eq = w.find('=');
    const std::string name = w.substr(0, eq), value = eq == std::string::npos ? "" : w.substr(eq + 1);
    if (eq == std::string::npos)
      return fail(fmt::format("'{}': a value is written name=value", w), kExitUsage);
    if (name == "comment") {
      if (const auto why = tools::invalid_comment(value))
        return fail(fmt::format("'{}': {}", w, *why), kExitUsage);
      changes.push_back([t = *t, value](tools::ToolSet& set) { set.tool_or_add(t).comment = value; });
      continue;
    }
    double v = 0;
    const auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || p != value.data() + value.size() || value.empty() || !std::isfinite(v))
      return fail(fmt::format("'{}': {} is not a number", w, value), kExitUsage);
    if (name == "pocket") {
      if (v != static_cast<int>(v))
        return fail(fmt::format("'{}': a pocket is a whole number", w), kExitUsage);
      changes.push_back(
          [t = *t, v](tools::ToolSet& set) { set.tool_or_add(t).pocket = static_cast<int>(v); });
      continue;
    }
    const auto param = tools::param_named(name);
    if (!param) {
      std::string names;
      for (const tools::ParamInfo& pi : tools::param_table())
        names += fmt::format("{}{}", names.empty() ? "" : ", ", pi.name);
      return fail(fmt::format("'{}': no parameter '{}' (pocket, comment, {})", w, name, names), kExitUsage);
    }
    if (d < 1 || d > tools::kMaxEdge || *t < 1 || *t > tools::kMaxToolNumber)
      return fail(fmt::format("T{} D{}: tools go from T1 to T{}, edges from D1 to D{}", *t, d,
                              tools::kMaxToolNumber, tools::kMaxEdge),
                  kExitUsage);
    changes.push_back(
        [t = *t, d, param = *param, v](tools::ToolSet& set) { set.edge_or_add(t, d).set(param, v); });
  }
  std::string error;
  std::optional<tools::Tool> written;
  const bool ok = s.modify(
      [&](tools::ToolSet& live) -> std::optional<std::string> {
        for (const auto& change : changes) change(live);
        written = *live.tool(*t);
        return std::nullopt;
      },
      kInterface, "set", &error);
  if (!ok) return fail(error);
  print(o, tool_json(*written), fmt::format("T{} set", *t));
  return kExitOk;
}

int backup(store::ToolStore& s, const ToolsOptions& o, const char* reason) {
  std::string error;
  const auto id = s.backup(kInterface, reason, &error);
  if (!id) return fail(error);
  const auto b = s.current_backup(&error);
  print(o, {{"backup", *id}, {"taken_utc", b ? b->taken_utc : ""}},
        fmt::format("backup {} taken {}{}", *id, b ? b->taken_utc : "",
                    std::string_view(reason) == "accept" ? ": the live values are the backup now" : ""));
  return kExitOk;
}

int check(store::ToolStore& s, const ToolsOptions& o) {
  std::optional<int> tool;
  if (!o.words.empty()) {
    tool = numbered(o.words[0], 'T');
    if (!tool) return fail("check takes a tool (T3) or nothing", kExitUsage);
  }
  const toolguard::CheckResult r = toolguard::check(s, o.tolerances, tool);
  if (o.json) {
    nlohmann::json diffs = nlohmann::json::array();
    for (const tools::Difference& d : r.differences) diffs.push_back(difference_json(d));
    nlohmann::json j = {{"ok", r.ok()}, {"differences", diffs}, {"message", r.report()}};
    if (r.backup) j["backup"] = r.backup->id;
    fmt::print("{}\n", j.dump(2));
  } else if (r.ok()) {
    fmt::print("{}\n", r.report());
  } else {
    fmt::print(stderr, "{}\n", r.report());
  }
  return r.ok() ? kExitOk : kExitProgram;
}

std::optional<std::int64_t> chosen_backup(store::ToolStore& s, const ToolsOptions& o) {
  if (o.backup > 0) return o.backup;
  std::string error;
  const auto b = s.current_backup(&error);
  if (!b) fail(error.empty() ? "there is no backup yet (opencnc tools --db FILE backup)" : error);
  return b ? std::optional(b->id) : std::nullopt;
}

int diff(store::ToolStore& s, const ToolsOptions& o) {
  const auto id = chosen_backup(s, o);
  if (!id) return kExitProgram;
  std::string error;
  const auto b = s.backup_set(*id, &error);
  const auto live = s.live(&error);
  if (!b || !live) return fail(error);
  const auto diffs = tools::compare(*b, *live, o.tolerances);
  nlohmann::json j = nlohmann::json::array();
  std::string text = fmt::format("backup {} against the live table: {} {}\n", *id, diffs.size(),
                                 diffs.size() == 1 ? "difference" : "differences");
  for (const tools::Difference& d : diffs) {
    j.push_back(difference_json(d));
    text += d.text() + (d.tolerated ? "  [within tolerance]\n" : "\n");
  }
  print(o, j, text);
  return kExitOk;
}

int restore(store::ToolStore& s, const ToolsOptions& o) {
  const auto id = chosen_backup(s, o);
  if (!id) return kExitProgram;
  std::string error;
  if (!s.restore(*id, kInterface, &error)) return fail(error);
  print(o, {{"restored", *id}}, fmt::format("backup {} is the live tool table again", *id));
  return kExitOk;
}

int import(store::ToolStore& s, const ToolsOptions& o) {
  if (o.words.size() != 1)
    return fail("import wants one file: a LinuxCNC .tbl or an 840D export", kExitUsage);
  const std::string& path = o.words[0];
  std::string text, error;
  if (!read_file(path, text, &error)) return fail(fmt::format("cannot read {}: {}", path, error), kExitUsage);
  Diagnostics d;
  std::optional<tools::ToolSet> set;
  if (tools::looks_like_840d(text)) {
    set = tools::parse_840d(text, path, d);
  } else {
    const tools::ToolTable table = tools::ToolTable::parse(text, path, d);
    if (d.error_count() == 0) set = tools::from_linuxcnc(table, path, d);
  }
  for (const Diagnostic& x : d.items()) fmt::print(stderr, "{}\n", x.format());
  if (!set || d.error_count() > 0) return fail(fmt::format("{} was not imported: nothing changed", path));
  if (set->tools.empty() && !o.allow_empty)
    return fail(
        fmt::format("{} holds no tools: importing it would empty the live table (nothing changed; "
                    "--allow-empty if that is meant)",
                    path));
  if (!s.write(*set, kInterface, fmt::format("import {}", path), &error)) return fail(error);
  print(o, {{"imported", path}, {"tools", set->tools.size()}, {"edges", set->edge_count()}},
        fmt::format("{}: {} tools, {} edges are the live table now (check against the backup, then accept)",
                    path, set->tools.size(), set->edge_count()));
  return kExitOk;
}

int export_table(store::ToolStore& s, const ToolsOptions& o) {
  std::string error;
  std::optional<tools::ToolSet> set;
  tools::SnapshotHeader header;
  if (o.backup > 0) {
    set = s.backup_set(o.backup, &error);
    for (const store::BackupInfo& b : s.backups()) {
      if (b.id == o.backup) header = {b.id, b.taken_utc};
    }
  } else {
    set = s.live(&error);
    header.taken_utc = store::utc_now();
  }
  if (!set) return fail(error);
  std::string text;
  if (o.format == "840d")
    text = tools::format_840d(*set, header);
  else if (o.format == "tbl")
    text = tools::linuxcnc_table(*set).format();
  else if (o.format == "json" || o.json)
    text = set_json(*set).dump(2) + "\n";
  else
    text = tools::format_listing(*set);
  if (o.output.empty()) {
    fmt::print("{}", text);
    return kExitOk;
  }
  const NamedPath inputs[] = {{"the tool store", o.db}};
  const NamedPath outputs[] = {{"-o", o.output}};
  auto files = open_outputs(inputs, outputs);
  if (files.empty()) return kExitUsage;
  return write_and_commit(*files[0], text) ? kExitOk : kExitUsage;
}

int audit(store::ToolStore& s, const ToolsOptions& o) {
  std::string error;
  const auto entries = s.audit(o.last, &error);
  if (!error.empty()) return fail(error);
  nlohmann::json j = nlohmann::json::array();
  std::string text;
  for (const store::AuditEntry& e : entries) {
    j.push_back(hmi::audit_json(e));
    text += audit_line(e, 24, 22);
  }
  print(o, j, text);
  return kExitOk;
}

int run(const std::string& action, ToolsOptions o) {
  if (!o.machine.empty()) {
    const config::ProfileLoad load = config::load_profile(o.machine, {});
    for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
    if (!load.ok()) return kExitUsage;
    if (!load.profile->tool_guard.present)
      return fail(fmt::format("{} has no [tool_guard]", o.machine), kExitUsage);
    o.tolerances = toolguard::tolerances(load.profile->tool_guard);
    if (o.db.empty()) o.db = load.profile->tool_guard.store;
  }
  if (o.db.empty())
    return fail("name the tool store: --db FILE (or --machine PROFILE with a [tool_guard])", kExitUsage);
  const bool writes = action == "set" || action == "import" || action == "backup" || action == "accept" ||
                      action == "restore";
  // An import whose source cannot be read creates no store.
  if (action == "import" && o.words.size() == 1) {
    if (const std::string why = unreadable_input(o.words[0]); !why.empty())
      return fail(fmt::format("cannot read {}: {}", o.words[0], why), kExitUsage);
  }
  const auto s = open_store(o, writes);
  if (!s) return kExitUsage;
  if (action == "list") return list(*s, o);
  if (action == "show") return show(*s, o);
  if (action == "set") return set(*s, o);
  if (action == "backup") return backup(*s, o, "backup");
  if (action == "accept") return backup(*s, o, "accept");
  if (action == "check") return check(*s, o);
  if (action == "diff") return diff(*s, o);
  if (action == "restore") return restore(*s, o);
  if (action == "import") return import(*s, o);
  if (action == "export") return export_table(*s, o);
  return audit(*s, o);
}

}  // namespace

void add_tools_command(CLI::App& app, Registry& registry) {
  auto o = std::make_shared<ToolsOptions>();
  CLI::App* cmd = app.add_subcommand("tools",
                                     "The tool store (tools with edges, backups, audit) and the check "
                                     "against the backup (docs/tool-guard.md)");
  cmd->require_subcommand(1);
  cmd->add_option("--db", o->db, "The tool store (SQLite)");
  cmd->add_option("--machine,-m", o->machine, "A profile with [tool_guard]: its store and tolerances");
  cmd->add_flag("--json", o->json, "Answer in JSON");
  cmd->add_option("--geometry-tolerance", o->tolerances.geometry_mm,
                  "mm a length or radius may differ (0.001)");
  cmd->add_option("--base-tolerance", o->tolerances.base_mm, "mm a base length may differ (0.001)");
  cmd->add_option("--wear-band", o->tolerances.wear_band_mm, "mm wear may drift from the backup (0.1)");
  const auto add = [&](const char* name, const char* help, const char* words) {
    CLI::App* sub = cmd->add_subcommand(name, help);
    sub->fallthrough();
    if (words != nullptr) sub->add_option("words", o->words, words);
    sub->callback([o, &registry, name] { registry.set_result(run(name, *o)); });
    return sub;
  };
  add("list", "The live tools and edges", nullptr);
  add("show", "One tool with every parameter of its edges", "T<n>");
  add("set", "Change values in one transaction: set T3 D1 length1=139.225 (also pocket=, comment=)",
      "T<n> [D<n>] name=value…");
  add("backup", "Take a snapshot of the live table: the new current backup", nullptr);
  add("check", "Compare the live table with the current backup; exit 1 and one line per difference",
      "[T<n>]");
  add("diff", "Every difference with a backup, tolerated ones marked", nullptr)
      ->add_option("--backup", o->backup, "The backup (default: the current one)")
      ->check(kBackupNumber);
  add("accept", "The live values become the new backup", nullptr);
  add("restore", "The backup's values become live", nullptr)
      ->add_option("--backup", o->backup, "The backup (default: the current one)")
      ->check(kBackupNumber);
  add("import", "Replace the live table by a LinuxCNC .tbl or an 840D export", "FILE")
      ->add_flag("--allow-empty", o->allow_empty, "Let a table without tools empty the live one");
  CLI::App* ex =
      add("export", "Write the live table (or a backup) as text, 840D subprogram, .tbl or JSON", nullptr);
  ex->add_option("--format", o->format, "text, 840d, tbl or json")
      ->check(CLI::IsMember({"text", "840d", "tbl", "json"}));
  ex->add_option("-o,--output", o->output, "The file (default: standard output)");
  ex->add_option("--backup", o->backup, "A backup instead of the live table")->check(kBackupNumber);
  add("audit", "The last changes: when, through which interface, what, old and new value", nullptr)
      ->add_option("--last", o->last, "How many (0: all; default 20)");
}

}  // namespace opencnc::cli
