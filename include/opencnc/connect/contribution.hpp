// SPDX-License-Identifier: GPL-3.0-or-later
// connect::Contribution — one observer of the controller's status in the MTConnect device: it adds
// its components and data items to the model once, then writes their values each time the agent
// samples the status. The machine's core (axes, controller, path, spindle) is one; each machine
// feature that has something to show (the EDM's gap, the broach's coupling and load) adds its own.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "opencnc/connect/device_model.hpp"
#include "opencnc/connect/observations.hpp"
#include "opencnc/controller/controller_status.hpp"

namespace opencnc::config {
struct MachineProfile;
}

namespace opencnc::connect {

/// What the contributions write in one sample: a text per sample or event item they set, and the
/// conditions active per condition item (none written: Normal). Items not set keep their value.
class ValueSink {
 public:
  explicit ValueSink(std::size_t items);

  /// A sample's or an event's value as text ("UNAVAILABLE": unknown).
  void set(std::size_t item, std::string value);
  /// A number with `decimals` digits after the point (the resolution the document shows).
  void set(std::size_t item, double value, int decimals);
  /// One active condition of a condition item: Warning or Fault, with the native code that tells it
  /// apart from the item's other conditions and the message.
  void condition(std::size_t item, Level level, std::string native_code, std::string text);

  struct Slot {
    bool set = false;
    std::string value;
    std::vector<Observation> conditions;
  };
  const std::vector<Slot>& slots() const noexcept { return slots_; }

 private:
  std::vector<Slot> slots_;
};

class Contribution {
 public:
  virtual ~Contribution() = default;
  /// Adds the components and items this contribution observes. Once, before any observe().
  virtual void describe(DeviceModel& model) = 0;
  /// Writes its items' values from `status`. The agent's sampling thread.
  virtual void observe(const controller::ControllerStatus& status, ValueSink& out) const = 0;
};

/// The contributions a machine profile calls for: the core, then the features the profile has
/// (EDM, coupling and broaching load, power monitor). Non-real-time.
std::vector<std::unique_ptr<Contribution>> contributions_for(const config::MachineProfile& profile);

}  // namespace opencnc::connect
