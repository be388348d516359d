// SPDX-License-Identifier: GPL-3.0-or-later
// The features a profile calls for, installed on the server's controller, and the board that
// turns their state into JSON on the controller's thread for the status and the stream.
#include "opencnc/hmi/machine_features.hpp"

#include <algorithm>

#include "opencnc/features/features.hpp"

namespace opencnc::hmi {

using nlohmann::json;

/// Follows the status on the controller's thread and stores the features' state for the server.
class MachineFeatures::Board final : public controller::ControllerObserver {
 public:
  explicit Board(MachineFeatures& owner) : owner_(owner) {}
  void on_status(const controller::ControllerStatus& s) override {
    json j = owner_.snapshot(s);
    std::lock_guard lock(owner_.mutex_);
    owner_.state_ = std::move(j);
  }

 private:
  MachineFeatures& owner_;
};

std::unique_ptr<MachineFeatures> MachineFeatures::create(const config::MachineProfile& profile,
                                                         const FeatureOptions& options, Diagnostics& diags) {
  controller::MachineSetup::Options o;
  if (!options.journal_dir.empty()) o.settings["journal"] = options.journal_dir;
  std::unique_ptr<controller::MachineSetup> setup =
      controller::MachineSetup::create(profile, std::move(o), diags);
  if (!setup) return nullptr;
  const bool ok = features::set_up(*setup);
  for (const Diagnostic& d : setup->diagnostics().items()) diags.add(d);
  if (!ok) return nullptr;
  std::unique_ptr<MachineFeatures> f(new MachineFeatures);
  for (const auto& [feature, options_] : setup->features()) f->names_.emplace_back(feature->name());
  f->source_ = setup->source();
  f->setup_ = std::move(setup);
  f->state_ = {{"installed", f->names_}};
  return f;
}

MachineFeatures::~MachineFeatures() = default;

bool MachineFeatures::has(std::string_view name) const {
  return std::find(names_.begin(), names_.end(), name) != names_.end();
}

void MachineFeatures::install(controller::Controller& controller) {
  setup_->install(controller);
  // Attached after the features: it sees their state of the same period. 50 Hz is above the
  // stream's default rate.
  const double period = setup_->profile().servo_period_s;
  controller.attach(std::make_shared<Board>(*this),
                    controller::ObserverOptions{std::max(period, 0.02), false});
}

json MachineFeatures::status() const {
  std::lock_guard lock(mutex_);
  return state_;
}

json MachineFeatures::snapshot(const controller::ControllerStatus& s) {
  json j{{"installed", names_}};
  for (const auto& state : setup_->states()) j[state->state_key()] = json::parse(state->state_json(s));
  return j;
}

}  // namespace opencnc::hmi
