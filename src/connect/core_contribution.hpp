// SPDX-License-Identifier: GPL-3.0-or-later
// connect::CoreContribution — the axes, controller, path and spindle every machine has.
#pragma once

#include <optional>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/connect/contribution.hpp"

namespace opencnc::connect {

class CoreContribution final : public Contribution {
 public:
  explicit CoreContribution(const config::MachineProfile& profile);
  void describe(DeviceModel& model) override;
  void observe(const controller::ControllerStatus& status, ValueSink& out) const override;

 private:
  struct AxisItems {
    int axis = 0, joint = 0;
    bool rotary = false;
    double peak_effort = 0;  ///< the drive's peak force or torque: LOAD's 100 %
    std::size_t actual = 0, commanded = 0, load = 0, travel = 0, actuator = 0;
  };
  struct SpindleItems {
    std::size_t speed = 0, commanded = 0, override_ = 0, mode = 0, load = 0, torque = 0;
    double rated_torque = 0;  ///< the drive's rated torque: LOAD's 100 % (0 = not stated)
  };
  config::MachineProfile profile_;  // a copy: the agent may outlive the caller's
  std::vector<AxisItems> axes_;
  std::optional<SpindleItems> spindle_;
  std::size_t estop_ = 0, system_ = 0, execution_ = 0, mode_ = 0, program_ = 0, line_ = 0, tool_ = 0,
              part_count_ = 0, feed_ = 0, feed_override_ = 0, rapid_override_ = 0, position_ = 0;
};

}  // namespace opencnc::connect
