// SPDX-License-Identifier: GPL-3.0-or-later
// MachineSetup: the features' parts collected, the sources made from them, the controller given them.
#include "opencnc/controller/machine_setup.hpp"

namespace opencnc::controller {

std::unique_ptr<MachineSetup> MachineSetup::create(const config::MachineProfile& profile, Options options,
                                                   Diagnostics& diags) {
  std::optional<GcodeSourceConfig> c = GcodeProgramSource::config_for(profile, diags);
  if (!c) return nullptr;
  if (options.tools) c->tools = options.tools;
  // A run that must leave the table's file as it was works on a copy (a feature may still give
  // the source a table of its own).
  if (const auto it = options.settings.find("tool-table");
      it != options.settings.end() && it->second == "memory" && c->tools)
    c->tools = std::make_shared<tools::MemoryToolTable>(*c->tools->snapshot());
  return std::unique_ptr<MachineSetup>(new MachineSetup(profile, std::move(options), std::move(*c)));
}

MachineSetup::MachineSetup(const config::MachineProfile& profile, Options options, GcodeSourceConfig config)
    : profile_(profile), options_(std::move(options)), config_(std::move(config)) {}

MachineSetup::~MachineSetup() = default;

const std::string* MachineSetup::setting(std::string_view name) const {
  const auto it = options_.settings.find(name);
  return it == options_.settings.end() ? nullptr : &it->second;
}

void MachineSetup::add_source_part(std::shared_ptr<const SourcePart> part) {
  config_.parts.push_back(std::move(part));
}

void MachineSetup::add_move_reach(MoveReachFactory reach) {
  reaches_.push_back(std::move(reach));
}

void MachineSetup::add_texts(std::shared_ptr<const EventTexts> texts) {
  texts_.push_back(std::move(texts));
}

void MachineSetup::add_feature(std::shared_ptr<Feature> feature, ObserverOptions options) {
  features_.emplace_back(std::move(feature), options);
}

void MachineSetup::add_observer(std::shared_ptr<ControllerObserver> observer, ObserverOptions options) {
  observers_.emplace_back(std::move(observer), options);
}

void MachineSetup::add_state(std::shared_ptr<FeatureState> state) {
  states_.push_back(std::move(state));
}

std::shared_ptr<GcodeProgramSource> MachineSetup::make_source(
    std::shared_ptr<tools::ToolTableService> tools) const {
  GcodeSourceConfig c = config_;
  if (tools) c.tools = std::move(tools);
  return std::make_shared<GcodeProgramSource>(std::move(c));
}

const std::shared_ptr<GcodeProgramSource>& MachineSetup::source() {
  if (!source_) source_ = std::make_shared<GcodeProgramSource>(config_);
  return source_;
}

void MachineSetup::install(Controller& controller) {
  for (const MoveReachFactory& r : reaches_) controller.add_move_reach(r);
  for (const auto& t : texts_) controller.add_texts(t);
  for (const auto& [f, o] : features_) controller.add_feature(f, o);
  for (const auto& [observer, o] : observers_) controller.attach(observer, o);
}

std::shared_ptr<Feature> MachineSetup::feature(std::string_view name) const {
  for (const auto& [f, o] : features_)
    if (f->name() == name) return f;
  return nullptr;
}

}  // namespace opencnc::controller
