// SPDX-License-Identifier: GPL-3.0-or-later
// The EDM on a machine: its codes, its reach, its texts, its recorder, its state, the electrode
// setting, added to the hub through its extension points.
#include "opencnc/edm/setup.hpp"

#include <algorithm>
#include <vector>

#include <nlohmann/json.hpp>

#include "edm_reach.hpp"
#include "edm_texts.hpp"
#include "opencnc/edm/edm_codes.hpp"
#include "opencnc/edm/edm_recorder.hpp"
#include "opencnc/edm/electrode_setting.hpp"

namespace opencnc::edm {

namespace {

/// The numbers of the machine's machining conditions, which M180's P must name.
std::vector<int> condition_numbers(const config::MachineProfile& profile) {
  const machine::EdmConfig& edm = profile.edm.config;
  std::vector<int> numbers;
  for (int i = 0; i < edm.condition_count; ++i)
    numbers.push_back(edm.conditions[static_cast<std::size_t>(i)].number);
  return numbers;
}

/// Each condition's orbit radius (0: none), in condition_numbers' order: M180's Q is at most it.
std::vector<double> condition_orbits(const config::MachineProfile& profile) {
  const machine::EdmConfig& edm = profile.edm.config;
  std::vector<double> orbits;
  for (int i = 0; i < edm.condition_count; ++i) {
    const machine::EdmCondition& c = edm.conditions[static_cast<std::size_t>(i)];
    orbits.push_back(c.orbit == machine::OrbitKind::None ? 0.0 : c.orbit_radius_mm);
  }
  return orbits;
}

/// M180/M181 on top of the dialect's modules, M180 P checked against the profile's conditions.
class Codes final : public controller::SourcePart {
 public:
  Codes(std::vector<int> numbers, std::vector<double> orbits)
      : numbers_(std::move(numbers)), orbits_(std::move(orbits)) {}
  std::shared_ptr<const gcode::Extensions> modules(
      gcode::Dialect dialect, std::shared_ptr<const gcode::Extensions> base) const override {
    return gcode::edm_extensions(dialect, numbers_, std::move(base), orbits_);
  }
  // A condition added or deleted: programs opened afterwards read M180 against the new numbers.
  std::shared_ptr<const controller::SourcePart> for_profile(
      const config::MachineProfile& profile) const override {
    std::vector<int> numbers = condition_numbers(profile);
    std::vector<double> orbits = condition_orbits(profile);
    return numbers == numbers_ && orbits == orbits_
               ? nullptr
               : std::make_shared<Codes>(std::move(numbers), std::move(orbits));
  }

 private:
  std::vector<int> numbers_;
  std::vector<double> orbits_;
};

/// The depth burnt as the EDM report counts it (docs/edm.md, `depth_mm`): the electrode's travel
/// into the work along the tool axis from the burn's first discharge; a burn runs from a
/// condition's selection to M181. At the rate the front end asks for its state, so a depth the
/// electrode held between two of its statuses only is missed (the report's, from every period, is
/// exact).
class Depth final : public controller::FeatureState {
 public:
  explicit Depth(const machine::EdmConfig& edm) : edm_(edm) {}
  std::string state_key() const override { return "edm"; }
  std::string state_json(const controller::ControllerStatus& s) override {
    const double along = s.servo.actual[static_cast<std::size_t>(edm_.tool_axis)];
    if (!s.servo.edm.on) {
      burning_ = false;
    } else if (!burning_ && s.servo.edm.gap_state != machine::GapState::Open) {
      burning_ = true;
      start_ = along;
      depth_mm_ = 0;
    }
    if (burning_) depth_mm_ = std::max(depth_mm_, (start_ - along) * edm_.lift_direction);
    return nlohmann::json{{"depth_mm", depth_mm_}, {"burning", burning_}}.dump();
  }

 private:
  machine::EdmConfig edm_;
  bool burning_ = false;
  double start_ = 0, depth_mm_ = 0;
};

}  // namespace

bool setup(const config::MachineProfile& profile, controller::MachineSetup& host) {
  if (profile.edm.present) {
    host.add_source_part(std::make_shared<Codes>(condition_numbers(profile), condition_orbits(profile)));
    host.add_move_reach([](const control::ServoConfig& servo) -> std::unique_ptr<controller::MoveReach> {
      if (!servo.edm.enabled) return nullptr;
      return std::make_unique<ReachCheck>(servo);
    });
    host.add_texts(std::make_shared<Texts>());
    host.add_state(std::make_shared<Depth>(profile.edm.config));
    if (host.reports())
      host.add_observer(std::make_shared<edm::EdmRecorder>(profile.edm.config, profile.servo_period_s),
                        controller::ObserverOptions{0, true});
  }
  // The electrode setting measures into the program source's tool table; it follows the trace
  // (the segment a stopped program stood at).
  if (profile.probe.reference_sphere.present && host.source_config().tools) {
    auto electrode = std::make_shared<edm::ElectrodeSetting>(host.source_config().tools, profile);
    host.add_feature(electrode, controller::ObserverOptions{profile.servo_period_s, true});
    host.add_state(electrode);
  }
  return true;
}

}  // namespace opencnc::edm
