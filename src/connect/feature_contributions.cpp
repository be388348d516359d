// SPDX-License-Identifier: GPL-3.0-or-later
// What the machine features add to the MTConnect device: the EDM's gap, the broach's coupling and
// load, the power monitor's mains. Each observes only its own part of the status.
#include "feature_contributions.hpp"

#include <fmt/format.h>

#include "core_contribution.hpp"

namespace opencnc::connect {

namespace {

std::string lower(Axis a) {
  return std::string(1, static_cast<char>(letter(a) - 'A' + 'a'));
}

}  // namespace

// --- EDM ------------------------------------------------------------------------------------

void EdmContribution::describe(DeviceModel& model) {
  const int path = model.find_component("Path");
  gap_voltage_ = model.add_item(
      DataItem{"edm_gap_v", Category::Sample, "VOLTAGE_DC", "ACTUAL", "VOLT", "VoltageDC", path});
  gap_ = model.add_item(DataItem{"edm_gap", Category::Condition, "VOLTAGE_DC", {}, {}, {}, path});
}

void EdmContribution::observe(const controller::ControllerStatus& s, ValueSink& out) const {
  const auto& e = s.servo.edm;
  out.set(gap_voltage_, e.on ? fmt::format("{:.1f}", e.gap_voltage_v) : std::string("UNAVAILABLE"));
  if (!e.on) return;
  if (e.gap_state == machine::GapState::Short)
    out.condition(gap_, Level::Warning, "edm.gap.short",
                  fmt::format("the gap is shorted ({:.3f} s), the servo backs off", e.short_s));
  else if (e.gap_state == machine::GapState::Arc)
    out.condition(gap_, Level::Warning, "edm.gap.arc", "arcing in the gap: debris, the jump should clear it");
}

// --- Plasma torch ------------------------------------------------------------------------------

void TorchContribution::describe(DeviceModel& model) {
  const int auxiliaries = model.add_component(0, "Auxiliaries", "auxiliaries");
  const int torch = model.add_component(auxiliaries, "CuttingTorch", "torch", "torch");
  power_ =
      model.add_item(DataItem{"torch_power", Category::Event, "POWER_STATE", {}, {}, "PowerState", torch});
  arc_voltage_ = model.add_item(
      DataItem{"torch_arc_v", Category::Sample, "VOLTAGE_DC", "ACTUAL", "VOLT", "VoltageDC", torch});
  correction_ = model.add_item(
      DataItem{"torch_thc", Category::Sample, "DISPLACEMENT", {}, "MILLIMETER", "Displacement", torch});
  arc_ = model.add_item(DataItem{"torch_arc", Category::Condition, "VOLTAGE_DC", {}, {}, {}, torch});
}

void TorchContribution::observe(const controller::ControllerStatus& s, ValueSink& out) const {
  const auto& t = s.servo.torch;
  out.set(power_, t.torch_on ? "ON" : "OFF");
  out.set(arc_voltage_, t.torch_on ? fmt::format("{:.1f}", t.arc_voltage_v) : std::string("UNAVAILABLE"));
  out.set(correction_, t.phase == control::TorchPhase::Cutting ? fmt::format("{:.4f}", t.correction_mm)
                                                               : std::string("UNAVAILABLE"));
  if (t.phase == control::TorchPhase::Failed)
    out.condition(arc_, Level::Fault, "plasma.start-failed",
                  fmt::format("no plate found, or the arc did not start ({} failed starts): the run is held",
                              t.failed_starts));
  else if (t.phase == control::TorchPhase::Paused)
    out.condition(arc_, Level::Warning, "plasma.paused",
                  fmt::format("the torch is off and the run held ({} arcs lost): a resume pierces again here",
                              t.arc_losses));
}

// --- Coupling and broaching load ---------------------------------------------------------------

CouplingContribution::CouplingContribution(Axis master, Axis slave, bool load)
    : master_(master), slave_(slave), has_load_(load) {}

void CouplingContribution::describe(DeviceModel& model) {
  auto component = [&](Axis a) {
    for (std::size_t i = 0; i < model.components().size(); ++i)
      if (model.components()[i].id == lower(a)) return static_cast<int>(i);
    throw std::invalid_argument(fmt::format("connect: the coupled axis {} is not in the device", letter(a)));
  };
  const int master = component(master_), slave = component(slave_);
  master_coupling_ = model.add_item(DataItem{
      lower(master_) + "_coupling", Category::Event, "AXIS_COUPLING", {}, {}, "AxisCoupling", master});
  slave_coupling_ = model.add_item(
      DataItem{lower(slave_) + "_coupling", Category::Event, "AXIS_COUPLING", {}, {}, "AxisCoupling", slave});
  coupled_axes_ = model.add_item(
      DataItem{lower(slave_) + "_coupled", Category::Event, "COUPLED_AXES", {}, {}, "CoupledAxes", slave});
  if (has_load_)
    load_ = model.add_item(DataItem{
        lower(master_) + "_force", Category::Sample, "LINEAR_FORCE", {}, "NEWTON", "LinearForce", master});
}

void CouplingContribution::observe(const controller::ControllerStatus& s, ValueSink& out) const {
  const bool coupled = s.servo.coupling.kind != motion::CouplingKind::Off;
  // Uncoupled, the axes have no coupling to report: AXIS_COUPLING has no value for "none".
  out.set(master_coupling_, coupled ? "MASTER" : "UNAVAILABLE");
  out.set(slave_coupling_, coupled ? "SLAVE" : "UNAVAILABLE");
  out.set(coupled_axes_, coupled ? lower(master_) : std::string("UNAVAILABLE"));
  if (has_load_) out.set(load_, s.servo.load_kn * 1000.0, 0);
}

// --- Power monitor -----------------------------------------------------------------------------

void PowerContribution::describe(DeviceModel& model) {
  const int controller = model.find_component("Controller");
  mains_ =
      model.add_item(DataItem{"mains", Category::Event, "POWER_STATE", "LINE", {}, "PowerState", controller});
  power_ = model.add_item(DataItem{"power", Category::Condition, "SYSTEM", {}, {}, {}, controller});
}

void PowerContribution::observe(const controller::ControllerStatus& s, ValueSink& out) const {
  out.set(mains_, s.servo.mains_ok ? "ON" : "OFF");
  if (s.servo.on_battery)
    out.condition(
        power_, Level::Warning, "power.on-battery",
        fmt::format("mains lost: the control runs on its UPS (DC link {:.0f} V)", s.servo.dc_link_v));
}

// --- The set a profile calls for ---------------------------------------------------------------

std::vector<std::unique_ptr<Contribution>> contributions_for(const config::MachineProfile& profile) {
  std::vector<std::unique_ptr<Contribution>> list;
  list.push_back(std::make_unique<CoreContribution>(profile));
  if (profile.power.monitor) list.push_back(std::make_unique<PowerContribution>());
  if (profile.edm.present) list.push_back(std::make_unique<EdmContribution>());
  if (profile.plasma.present) list.push_back(std::make_unique<TorchContribution>());
  if (profile.coupling.present)
    list.push_back(std::make_unique<CouplingContribution>(profile.coupling.master, profile.coupling.slave,
                                                          profile.broaching.present));
  return list;
}

}  // namespace opencnc::connect
