// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc run --electrode-change`: the scripted operator who replaces a worn EDM electrode mid-job.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "opencnc/controller/controller.hpp"
#include "opencnc/edm/electrode_setting.hpp"

namespace opencnc::machine {
class SimMachine;
}

namespace opencnc::cli {

/// One change: at `at_s` seconds into the program, a new electrode whose true offsets are `offset`.
struct ElectrodeChangeAt {
  double at_s = 0;
  Vec3 offset{};
};

/// "30:0.02,-0.01,0.05" → {30, {0.02, −0.01, 0.05}}; nullopt if it is not that (finite, time ≥ 0).
std::optional<ElectrodeChangeAt> parse_electrode_change(const std::string& text);

/// What one change did.
struct ElectrodeChangeRecord {
  double at_s = 0;            ///< when the operator stopped the job (program time)
  int tool = 0;               ///< the tool in the spindle, replaced and measured
  std::uint64_t segment = 0;  ///< where the job stopped
  edm::ElectrodeResult measured;
  bool resumed = false;  ///< the job went on from the stop point
};

/// The operator of `--electrode-change` (docs/edm.md, "A worn electrode replaced mid-job"): at each
/// time, feed hold then abort, the electrode lifted `lift_mm` along the tool axis (MDI, machine
/// coordinates), a new electrode put in for the tool in the spindle (the simulated machine's),
/// measured on the reference sphere and stored, and the job resumed where it stopped. Controller
/// thread (the session's loop).
class ElectrodeChangeScript {
 public:
  /// `tool_axis` the electrode's axis, `lift_mm` signed (away from the work), the lifted position
  /// kept within [min_mm, max_mm] (the axis' soft limits).
  ElectrodeChangeScript(std::vector<ElectrodeChangeAt> steps, std::shared_ptr<edm::ElectrodeSetting> feature,
                        Axis tool_axis, double lift_mm, double min_mm, double max_mm);

  /// Every period of the run.
  void tick(controller::Controller& c, const controller::ControllerStatus& st, machine::SimMachine* sim);
  /// The program's job ended: the session goes on while a change is under way.
  bool goes_on(const controller::ControllerEvent& e) const;
  const std::vector<ElectrodeChangeRecord>& records() const { return records_; }
  /// The report's `electrode_changes`.
  nlohmann::json json() const;

 private:
  enum class Stage : std::uint8_t { Waiting, Holding, Aborting, Lifting, Measuring, Resuming, Failed };
  void fail(const std::string& why);
  bool answered(controller::Controller& c);

  std::vector<ElectrodeChangeAt> steps_;
  std::shared_ptr<edm::ElectrodeSetting> feature_;
  Axis tool_axis_ = Axis::Z;
  double lift_mm_ = 10, min_mm_ = 0, max_mm_ = 0;
  std::size_t next_ = 0;
  Stage stage_ = Stage::Waiting;
  std::uint64_t asked_ = 0;
  bool mdi_sent_ = false;
  double t0_ = -1;
  std::vector<ElectrodeChangeRecord> records_;
};

}  // namespace opencnc::cli
