// SPDX-License-Identifier: GPL-3.0-or-later
// Electrode setting against a reference sphere (sinker EDM): touches from around and above as
// auxiliary programs of probe moves, the sphere's centre fitted, the electrode's offsets into the
// tool table, and the stopped job resumed with the new electrode (docs/electrode-setting.md).
#pragma once

#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/core/vec3.hpp"
#include "opencnc/edm/b_axis_fit.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::edm {

/// One touch of the sphere: the controlled point's machine position where it starts and where
/// its probe move ends if it touches nothing (each `clearance` off the surface, outside and
/// inside), and the direction from the sphere's centre toward the start.
struct SphereTouch {
  std::string name;  ///< "+X", "top", "45°" …
  Vec3 start{}, end{}, direction{};
};

/// The touches for an electrode with tool-table offsets `offset` (X, Y, Z: G43's, the tip's
/// lowest point at controlled point − offset) and a ball tip of `tip_radius` (half the table's
/// diameter; 0: a point): `touches_around` at the height of the sphere's centre, evenly from +X
/// counter-clockwise, then one from above along the tool axis. Any thread.
std::vector<SphereTouch> plan_touches(const config::ReferenceSphereProfile& sphere, const Vec3& offset,
                                      double tip_radius);

/// The auxiliary program of one touch, from `from`: up to the safe height (or over at the height
/// it is at, if higher) and straight down to the start, the probe move (G38.2's: it stops at the contact),
/// back to the start and up. With `turn_b` it first turns B to the sphere's angle at the safe height.
/// With the sphere's `fast_feed` the probe move is the fast one and the program ends at the contact
/// (slow_touch_program goes on from there). Non-real-time.
std::shared_ptr<const canon::Program> touch_program(AxisMask axes, const Pose& from, const SphereTouch& touch,
                                                    const config::ReferenceSphereProfile& sphere,
                                                    bool turn_b);

/// The slow touch after a fast one that closed at `contact` (`from`: where the machine stopped):
/// back along the touch's line to `back_off` before the contact, the probe move at probe_feed to
/// `back_off` past it, then back to the touch's start and up. `slow` gets that probe move's line
/// (its start and end) to check the latch against. Non-real-time.
std::shared_ptr<const canon::Program> slow_touch_program(AxisMask axes, const Pose& from,
                                                         const SphereTouch& touch, const Vec3& contact,
                                                         const config::ReferenceSphereProfile& sphere,
                                                         SphereTouch& slow);

/// What a measurement found.
struct ElectrodeResult {
  bool ok = false;
  /// "" when ok, else electrode.missing-touch, .contact-at-start, .fit, .far, .stopped, .refused, .table
  std::string code;
  std::string message;  ///< in words, for the operator
  int tool = 0;
  double tip_radius = 0;
  std::vector<std::string> names;  ///< of the touches made, in order
  std::vector<Vec3> touched;       ///< the controlled point where each touch closed the contact
  std::vector<Vec3> fast_touched;  ///< with fast_feed: where each fast touch closed it (not fitted)
  Vec3 centre{};                   ///< fitted: the controlled point that puts the tip's ball on the centre
  Vec3 previous{};                 ///< the tool table's X, Y, Z offsets before
  Vec3 offset{};                   ///< … and as measured (Z is the electrode's length)
  double rms_residual_mm = 0, max_residual_mm = 0;
  bool written = false;  ///< the offsets are in the tool table (at once, or by "write" after a look)
};

/// From the touch points: the fit of the points lifted by the tip radius (radius: the sphere's plus
/// the tip's; its centre is then the sphere's plus the offsets), the offsets, and
/// the checks: a residual above the tolerance (`electrode.fit`), offsets farther than
/// `max_deviation` from the table's (`electrode.far`: the sphere is not where the profile says,
/// or the wrong electrode). Any thread.
ElectrodeResult evaluate_touches(const config::ReferenceSphereProfile& sphere, int tool, const Vec3& previous,
                                 double tip_radius, std::span<const std::string> names,
                                 std::span<const Vec3> touched);

/// `requests::Feature{"electrode", "measure", ElectrodeMeasure{tool}}`.
struct ElectrodeMeasure {
  int tool = 0;
  /// Store the offsets when the measurement passes its checks; false: keep them in last() until
  /// the operator has seen them and sends "write" (an HMI's confirmation).
  bool write = true;
  /// Measure with B at this angle, where the profile's (or the last calibrate-b's) B axis turns
  /// the sphere to; absent: at the profile's `b`.
  std::optional<double> b_deg{};
};

/// `requests::Feature{"electrode", "calibrate-b", BAxisCalibrate{tool, angles}}`: B's axis of
/// rotation from the sphere measured with `tool` at each angle (at least three distinct ones).
struct BAxisCalibrate {
  int tool = 0;
  std::vector<double> angles_deg{};
};

/// What calibrate-b found.
struct BAxisResult {
  bool ok = false;
  std::string code;  ///< "" when ok, else electrode.b-axis-fit or a measurement's code
  std::string message;
  int tool = 0;
  std::vector<double> angles_deg;  ///< measured so far, in order
  std::vector<Vec3> centres;       ///< the fitted centre (sphere + electrode) at each
  BAxisLine previous;              ///< the axis the spheres were looked for about
  BAxisFit fit;                    ///< when ok (and when the residual failed, what it was)
};

/// Where the main program stopped (aborted or faulted) before its end: what `resume` needs.
struct ProgramStop {
  canon::SegmentId segment = 0;  ///< the interpreter's segment id at the commanded position
  Pose position{};               ///< the commanded position, machine coordinates
};

enum class ElectrodePhase : std::uint8_t { Idle, Measuring, Approaching, Resuming, Calibrating };
const char* to_string(ElectrodePhase p) noexcept;

/// The feature "electrode". Actions: `measure` (args ElectrodeMeasure): the machine idle and
/// homed, no job running, the tool in the table — the touches run one auxiliary program each
/// (Auto mode), then the offsets are checked and written to the tool table (ChangeSource::Operator,
/// G10 L1's fields X Y Z) and a note `electrode.set` (or the error's code) says what was found;
/// `write`: stores the last measurement's offsets when it passed, was not stored yet, and the
/// tool's offsets in the table are still those it was measured against;
/// `calibrate-b` (args BAxisCalibrate): the sphere measured at each B angle as `measure` does
/// (nothing stored in the tool table), B's axis fitted (`fit_b_axis`), checked against the
/// sphere's `tolerance` and kept for the measurements that follow (`sphere()`); a note
/// `electrode.b-axis` says what was found (the caller writes it into the profile);
/// `resume`: after a measurement, the main program that stopped before its end goes on — an
/// approach to where it stopped, moved by the change of the measured tool's offsets (up to the
/// safe height, over, down), then requests::ResumeProgram at its segment. Attach it with
/// `trace = true` (it follows the main program's segment) and a status period. Controller thread;
/// last() and stop() from any thread.
class ElectrodeSetting final : public controller::Feature, public controller::FeatureState {
 public:
  ElectrodeSetting(std::shared_ptr<tools::ToolTableService> tools, const config::MachineProfile& profile);
  /// The state a front end shows (docs/api.md, "features"): `phase`, the last measurement
  /// (`last`), the last B-axis calibration (`b_axis`), `stopped_program`.
  std::string state_key() const override { return "electrode"; }
  std::string state_json(const controller::ControllerStatus& status) override;

  std::string_view name() const override { return "electrode"; }
  void attached(controller::FeatureHost& host) override { host_ = &host; }
  controller::Outcome handle(const controller::requests::Feature& request,
                             controller::FeatureHost& host) override;
  void on_event(const controller::ControllerEvent& e) override;
  void on_status(const controller::ControllerStatus& s) override;
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override;

  ElectrodePhase phase() const;
  std::optional<ElectrodeResult> last() const;
  /// The sphere as the profile gives it. Any thread.
  const config::ReferenceSphereProfile& profile_sphere() const noexcept { return profile_sphere_; }
  /// The sphere as measurements use it: the profile's, with B's axis from the last calibrate-b
  /// that passed. Any thread.
  config::ReferenceSphereProfile sphere() const;
  std::optional<BAxisResult> last_b_axis() const;
  std::optional<ProgramStop> stop() const;

 private:
  controller::Outcome measure(const ElectrodeMeasure& args, controller::FeatureHost& host);
  controller::Outcome calibrate_b(const BAxisCalibrate& args, controller::FeatureHost& host);
  std::optional<controller::Outcome> start_measurement(int tool, std::optional<double> b_deg,
                                                       controller::FeatureHost& host);
  void next_calibration_angle(const ElectrodeResult& r);
  void finish_calibration();
  controller::Outcome resume(controller::FeatureHost& host);
  controller::Outcome write();
  bool store(ElectrodeResult& r);
  void when_aux_ended(const controller::ControllerEvent& e);
  void next_touch();
  void touched(const Vec3& at);
  void finish_measurement();
  void fail(std::string code, std::string message);
  void set_phase(ElectrodePhase p);

  std::shared_ptr<tools::ToolTableService> tools_;
  config::ReferenceSphereProfile profile_sphere_;
  config::ReferenceSphereProfile sphere_;  ///< with the calibrated B axis (guarded by mutex_)
  config::ReferenceSphereProfile at_;      ///< the sphere where the measurement under way finds it
  AxisMask axes_;
  controller::FeatureHost* host_ = nullptr;

  // The measurement under way.
  int tool_ = 0;
  bool write_ = true;  ///< store the offsets when the measurement ends
  std::size_t tool_index_ = 0;
  tools::ToolEntry entry_;
  std::vector<SphereTouch> plan_;
  std::vector<Vec3> touched_, fast_touched_;
  std::size_t touch_ = 0;
  bool slow_ = false;      ///< the current touch's slow stage runs (after its fast one)
  SphereTouch slow_line_;  ///< the slow stage's probe move
  std::shared_ptr<const canon::Program> next_aux_;
  std::string next_aux_name_;
  std::uint64_t pending_ = 0;  ///< the request whose refusal ends what runs
  BAxisResult calibration_;    ///< calibrate-b under way (phase Calibrating)

  // The main program: its segment at the commanded position while it runs, where it stopped.
  canon::SegmentId running_segment_ = 0;
  Pose running_position_{};
  bool running_seen_ = false;
  /// The measured tool's offsets when the program stopped (the first measurement since the stop
  /// knows them): the approach moves the stop point by what changed since.
  std::optional<Vec3> stop_offset_;

  mutable std::mutex mutex_;  ///< guards what the accessors read
  ElectrodePhase phase_ = ElectrodePhase::Idle;
  std::optional<ElectrodeResult> last_;
  std::optional<BAxisResult> last_b_;
  std::optional<ProgramStop> stop_;
};

}  // namespace opencnc::edm
