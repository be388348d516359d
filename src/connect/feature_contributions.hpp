// SPDX-License-Identifier: GPL-3.0-or-later
// The machine features' MTConnect contributions (the EDM, the coupling and broaching load, the power
// monitor). They move into the features' own folders with the feature structure.
#pragma once

#include "opencnc/connect/contribution.hpp"
#include "opencnc/core/axes.hpp"

namespace opencnc::connect {

/// The EDM's gap voltage (a sample on the path) and the gap's shorts and arcs (a condition).
class EdmContribution final : public Contribution {
 public:
  void describe(DeviceModel& model) override;
  void observe(const controller::ControllerStatus& status, ValueSink& out) const override;

 private:
  std::size_t gap_voltage_ = 0, gap_ = 0;
};

/// A plasma table's torch (`[process.plasma]`): MTConnect's CuttingTorch among the Auxiliaries, with
/// its power (the torch output), the arc voltage, the height control's correction, and a condition
/// while the torch's sequence holds the run.
class TorchContribution final : public Contribution {
 public:
  void describe(DeviceModel& model) override;
  void observe(const controller::ControllerStatus& status, ValueSink& out) const override;

 private:
  std::size_t power_ = 0, arc_voltage_ = 0, correction_ = 0, arc_ = 0;
};

/// A coupling law's master and slave (AXIS_COUPLING, COUPLED_AXES) and, on a broach, the
/// load cell's force on the master (the stroke).
class CouplingContribution final : public Contribution {
 public:
  CouplingContribution(Axis master, Axis slave, bool load);
  void describe(DeviceModel& model) override;
  void observe(const controller::ControllerStatus& status, ValueSink& out) const override;

 private:
  Axis master_, slave_;
  bool has_load_;
  std::size_t master_coupling_ = 0, slave_coupling_ = 0, coupled_axes_ = 0, load_ = 0;
};

/// The mains (POWER_STATE LINE) and a running-on-battery warning.
class PowerContribution final : public Contribution {
 public:
  void describe(DeviceModel& model) override;
  void observe(const controller::ControllerStatus& status, ValueSink& out) const override;

 private:
  std::size_t mains_ = 0, power_ = 0;
};

}  // namespace opencnc::connect
