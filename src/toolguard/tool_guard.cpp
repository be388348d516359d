// SPDX-License-Identifier: GPL-3.0-or-later
// The tool guard's check, its Feature (refuse at start, hold at a tool change, accept, restore)
// and the source and feature for a profile.
#include "opencnc/toolguard/tool_guard.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "check_code.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "opencnc/tools/edge_mapping.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::toolguard {

tools::CheckTolerances tolerances(const config::ToolGuardProfile& p) noexcept {
  tools::CheckTolerances t;
  t.geometry_mm = p.geometry_tolerance_mm;
  t.base_mm = p.base_tolerance_mm;
  t.wear_band_mm = p.wear_band_mm;
  return t;
}

std::string CheckResult::report() const {
  if (!error.empty()) return fmt::format("the tool store cannot be read: {}", error);
  if (!backup)
    return "the tool table has no backup to check against: take one once the offsets are known to be right "
           "(opencnc tools --db STORE backup)";
  if (differences.empty())
    return fmt::format("the live tool table matches backup {} of {}", backup->id, backup->taken_utc);
  std::string out =
      fmt::format("the live tool table differs from backup {} of {} in {} {}:", backup->id, backup->taken_utc,
                  differences.size(), differences.size() == 1 ? "place" : "places");
  for (const tools::Difference& d : differences) out += "\n" + d.text();
  return out;
}

CheckResult check(store::ToolStore& store, const tools::CheckTolerances& tolerances,
                  std::optional<int> tool) {
  CheckResult r;
  r.backup = store.current_backup(&r.error);
  if (!r.error.empty() || !r.backup) return r;
  const std::optional<tools::ToolSet> backup = store.backup_set(r.backup->id, &r.error);
  const std::optional<tools::ToolSet> live = store.live(&r.error);
  if (!backup || !live) return r;
  r.differences = tools::check(*backup, *live, tolerances, tool);
  return r;
}

ToolGuard::ToolGuard(std::shared_ptr<store::ToolStore> store, const config::ToolGuardProfile& profile,
                     int pockets)
    : store_(std::move(store)), profile_(profile), tolerances_(tolerances(profile)), pockets_(pockets) {}

namespace {

// Tools whose pocket the magazine does not have: the changer would reach for nothing.
std::string beyond_magazine(store::ToolStore& store, int pockets) {
  std::string out;
  if (pockets <= 0) return out;
  const auto live = store.live();
  if (!live) return out;
  for (const tools::Tool& t : live->tools) {
    if (t.pocket > pockets)
      out += fmt::format("\nT{}: pocket {}, but the magazine has {}", t.tool, t.pocket, pockets);
  }
  return out;
}

}  // namespace

bool ToolGuard::allow_start(const controller::StartCheck& /*start*/, controller::FeatureHost& /*host*/,
                            std::string* why) {
  held_ = false;
  if (!profile_.check_at_start) return true;
  const CheckResult r = check(*store_, tolerances_);
  const std::string pockets = beyond_magazine(*store_, pockets_);
  if (r.ok() && pockets.empty()) return true;
  *why = r.ok() ? "tools are in pockets the magazine does not have:" + pockets : r.report() + pockets;
  return false;
}

// At the tool change the check covers the edges of the tool going into the spindle: the
// program stands there until they pass (the note is repeated only when the table changed).
bool ToolGuard::allow_continue(const controller::SyncCheck& sync, controller::FeatureHost& host) {
  if (!profile_.check_at_tool_change || sync.kind != controller::SyncKind::ToolChange || sync.tool_index <= 0)
    return true;
  const std::uint64_t v = store_->changes();
  if (held_ && v == held_version_) return false;
  if (!held_) {
    // The index is the entry of the table the program was reading (edges in T, D order).
    const auto table = store_->snapshot();
    const auto i = static_cast<std::size_t>(sync.tool_index);
    const auto td = i <= table->size() ? tools::tool_and_edge(table->at_index(i).tool) : std::nullopt;
    held_tool_ = td ? td->first : 0;
  }
  if (held_tool_ <= 0) return true;
  const CheckResult r = check(*store_, tolerances_, held_tool_);
  if (r.ok()) {
    if (held_)
      host.note(Severity::Note, "tools.guard-passed",
                fmt::format("T{}: {}; the program goes on", held_tool_, r.report()));
    held_ = false;
    return true;
  }
  held_ = true;
  held_version_ = v;
  host.note(Severity::Error, "tools.guard-hold",
            fmt::format("held before T{} cuts ({}): {}\naccept the live values or restore the backup "
                        "(tool-guard accept|restore)",
                        held_tool_, controller::to_string(sync.where), r.report()));
  return false;
}

controller::Outcome ToolGuard::handle(const controller::requests::Feature& request,
                                      controller::FeatureHost& host) {
  controller::Outcome o;
  if (request.action == "check") {
    const CheckResult r = check(*store_, tolerances_);
    o.accepted = r.ok();
    o.refusal = r.ok() ? control::Refusal::None : control::Refusal::FeatureCheck;
    o.message = r.report();
    return o;
  }
  if (request.action != "accept" && request.action != "restore") {
    o.message = fmt::format("tool-guard knows check, accept and restore, not '{}'", request.action);
    o.refusal = control::Refusal::BadValue;
    return o;
  }
  std::optional<std::int64_t> chosen;
  if (const auto* id = std::any_cast<std::int64_t>(&request.args)) chosen = *id;
  auto out = std::make_shared<controller::Outcome>();
  host.answer_after(
      [out, store = store_, action = request.action, chosen] {
        std::string error;
        if (action == "accept") {
          const auto id = store->backup("controller", "accept", &error);
          out->accepted = id.has_value();
          out->message = id ? fmt::format("the live tool table is backup {} now", *id) : error;
        } else {
          std::optional<store::BackupInfo> b = store->current_backup(&error);
          const std::int64_t id = chosen.value_or(b ? b->id : 0);
          out->accepted = id > 0 && store->restore(id, "controller", &error);
          out->message = out->accepted
                             ? fmt::format("backup {} is the live tool table again", id)
                             : (error.empty() ? std::string("there is no backup to restore") : error);
        }
        if (!out->accepted) out->refusal = control::Refusal::BadValue;
      },
      [out, &host, action = request.action] {
        host.note(out->accepted ? Severity::Note : Severity::Error, "tools.guard-" + action, out->message);
        return *out;
      });
  return o;
}

namespace {

/// The check M-code (M160 or the profile's) on top of the modules the profile already brings.
class CheckModule final : public controller::SourcePart {
 public:
  CheckModule(std::shared_ptr<CheckCode> code, std::size_t m) : code_(std::move(code)), m_(m) {}
  std::shared_ptr<const gcode::Extensions> modules(
      gcode::Dialect, std::shared_ptr<const gcode::Extensions> base) const override {
    auto ext = std::make_shared<gcode::Extensions>(*base);
    ext->m[m_] = code_;
    return ext;
  }

 private:
  std::shared_ptr<CheckCode> code_;
  std::size_t m_;
};

/// While the guard holds the program at a tool change (the controller's wait text names the
/// feature that holds), the differences of the whole live table from the backup, for the dialog.
/// The check reads the store (SQLite): it runs once when the hold begins and again only when the
/// store has changed, not at every status.
class State final : public controller::FeatureState {
 public:
  State(std::shared_ptr<store::ToolStore> store, const config::ToolGuardProfile& guard)
      : store_(std::move(store)), guard_(guard) {}
  std::string state_key() const override { return "tool_guard"; }
  std::string state_json(const controller::ControllerStatus& s) override {
    using nlohmann::json;
    const bool holding = s.wait_text.find("the tool-guard ") != std::string::npos;
    if (!holding) {
      holding_ = false;
      report_ = nullptr;
    } else if (!holding_ || store_->changes() != checked_) {
      holding_ = true;
      checked_ = store_->changes();
      const CheckResult r = check(*store_, tolerances(guard_));
      json lines = json::array(), tools = json::array();
      for (const tools::Difference& d : r.differences) {
        lines.push_back(d.text());
        tools.push_back(d.tool);  // the dialog lists the program's tools first
      }
      report_ = {
          {"ok", r.ok()},
          {"error", r.error},
          {"backup", r.backup ? json{{"id", r.backup->id}, {"taken", r.backup->taken_utc}} : json(nullptr)},
          {"differences", lines},
          {"difference_tools", tools},
          {"report", r.report()}};
    }
    return json{{"store", guard_.store}, {"holding", holding}, {"check", report_}}.dump();
  }

 private:
  std::shared_ptr<store::ToolStore> store_;
  config::ToolGuardProfile guard_;
  bool holding_ = false;
  std::uint64_t checked_ = ~std::uint64_t{0};
  nlohmann::json report_;
};

}  // namespace

bool setup(const config::MachineProfile& profile, controller::MachineSetup& host) {
  const config::ToolGuardProfile& g = profile.tool_guard;
  if (!g.present) return true;
  std::string error;
  std::shared_ptr<store::ToolStore> store = store::ToolStore::open(g.store, &error, false);
  if (!store) {
    host.diagnostics().error(
        profile.source, 0, 0,
        fmt::format("tool_guard.store: {} (create it with `opencnc tools --db {} import TABLE` and back it "
                    "up with `opencnc tools --db {} backup`)",
                    error, g.store, g.store),
        "tools.store");
    return false;
  }
  host.source_config().tools = store;
  if (g.check_mcode > 0)
    host.add_source_part(std::make_shared<CheckModule>(std::make_shared<CheckCode>(store, tolerances(g)),
                                                       static_cast<std::size_t>(g.check_mcode)));
  host.add_feature(std::make_shared<ToolGuard>(store, g, profile.tool_changer_pockets),
                   controller::ObserverOptions{profile.servo_period_s, false});
  host.add_state(std::make_shared<State>(store, g));
  return true;
}

}  // namespace opencnc::toolguard
