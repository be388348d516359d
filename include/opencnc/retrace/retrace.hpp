// SPDX-License-Identifier: GPL-3.0-or-later
// RetraceFeature — flame/plasma retrace as a feature of the controller hub: pause the cut at A
// (feed hold, torch out), jog freely to B, start: to the nearest point C of the programmed feed
// path at a safe height, the torch lit again (ignite, preheat, pierce), the program resumed at
// C's segment and cut on; optionally stop again at A; step along the path while paused.
// Requests: requests::Feature{"retrace", action, args}. See docs/retrace.md.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/retrace/path_index.hpp"

namespace opencnc::recovery {

/// Arguments of "start" (requests::Feature::args; none: the defaults).
struct RetraceStart {
  Metric metric = Metric::Xy;
  double margin_mm = 0.5;     ///< other stretches this near are candidates
  std::size_t candidate = 0;  ///< which candidate (0: the nearest)
  bool stop_at_a = false;     ///< hold again where the cut was paused
};

/// Arguments of "step": along the feed path from where the cut paused (or the last step).
struct RetraceStep {
  double distance_mm = 0;  ///< negative: back along the path
};

/// One retrace: where the cut paused (A), where the operator put the torch (B), where it went
/// on (C: segment, line, the distance B→C), and how many stretches of the path were candidates.
struct RetraceRecord {
  Vec3 a{}, b{}, c{};
  bool a_known = false;
  canon::SegmentId segment = 0;
  std::uint64_t move = 0;
  std::string line;  ///< "file:line" of C's block (with the calls that led there)
  double distance_mm = 0;
  std::size_t candidates = 0;
};

/// Where the retrace workflow is.
enum class RetracePhase : std::uint8_t {
  Idle,         ///< nothing to do: the program runs or is not started
  Holding,      ///< feed hold asked, waiting for the machine to stand
  Stopping,     ///< the held program is being ended
  TorchOff,     ///< the torch-off sequence runs
  Paused,       ///< Manual mode: jog to B, step, or start
  Stepping,     ///< moving along the path
  Approaching,  ///< B → C, the torch lit again
  Cutting,      ///< the program resumed at C
};

/// "idle", "holding", … Any thread.
const char* to_string(RetracePhase p) noexcept;

/// The feature. Its path index is built on a thread of its own when a program is opened, with
/// a program source of its own (the same profile: dialect, modules, tool table), from where
/// the machine stands. Controller thread for everything but records(), phase() (any thread).
class RetraceFeature final : public controller::Feature {
 public:
  /// `source` is the feature's own (its index is scanned on a thread of its own); the profile
  /// gives the torch sequences ([process.cutting]) and the accelerations to stop at A in. Add it
  /// with Controller::add_feature(feature, {servo period, false}): it follows the status every
  /// period.
  RetraceFeature(std::shared_ptr<controller::ProgramSource> source, const config::MachineProfile& profile);
  ~RetraceFeature() override;

  std::string_view name() const override { return "retrace"; }
  void attached(controller::FeatureHost& host) override { host_ = &host; }
  /// "pause", "start" (RetraceStart), "step" (RetraceStep), "nearest" (Vec3: the answer's message
  /// names C), "index" (waits for the index; the message gives its size).
  controller::Outcome handle(const controller::requests::Feature& request,
                             controller::FeatureHost& host) override;
  void on_event(const controller::ControllerEvent& e) override;
  void on_status(const controller::ControllerStatus& s) override;

  /// Every retrace so far. Any thread.
  std::vector<RetraceRecord> records() const;
  RetracePhase phase() const noexcept { return phase_.load(); }
  /// The index of the open program (waits for its build). Controller thread.
  const PathIndex* index();

 private:
  controller::Outcome pause(controller::FeatureHost& host);
  controller::Outcome start(const RetraceStart& args, controller::FeatureHost& host);
  controller::Outcome step(const RetraceStep& args, controller::FeatureHost& host);
  void build_index(const std::string& path, const Pose& start);
  void join();
  void when_held(const controller::ControllerStatus& s);
  void when_job_ended(const controller::ControllerEvent& e);
  void check_stop_at_a(const controller::ControllerStatus& s);
  void run_auxiliary(const char* name, std::shared_ptr<const canon::Program> program);
  std::shared_ptr<const canon::Program> torch_off_program(const Pose& at) const;
  std::shared_ptr<const canon::Program> approach_program(const Pose& b, const Vec3& c) const;
  std::shared_ptr<const canon::Program> step_program(const Pose& from, const PathPoint& along,
                                                     double distance_mm) const;
  std::string describe(const PathPoint& p) const;
  void set_phase(RetracePhase p) noexcept { phase_.store(p); }

  std::shared_ptr<controller::ProgramSource> source_;
  config::CuttingProfile cutting_;
  double status_period_s_ = 0.001;
  double min_accel_ = 1e300;  ///< the smaller of X's and Y's acceleration limits, mm/s²
  double jerk_filter_s_ = 0;  ///< the planner's moving average for the jerk limits (0: none), s
  controller::FeatureHost* host_ = nullptr;

  std::thread builder_;
  std::unique_ptr<PathIndex> index_, building_;
  Diagnostics index_diags_;

  std::atomic<RetracePhase> phase_{RetracePhase::Idle};
  std::uint64_t pending_ = 0;  ///< the request the phase waits on (refused: back to Paused)
  bool mode_asked_ = false;    ///< Auto (or Manual) asked, waiting for the servo
  std::shared_ptr<const canon::Program> next_aux_;  ///< runs once Auto mode is on
  const char* next_aux_name_ = "";
  std::optional<PathPoint> a_;  ///< where the cut paused, on the path
  Vec3 a_position_{};
  double a_offset_ = 0;  ///< the status' segment_offset at A
  PathPoint cursor_{};   ///< where stepping goes on from
  bool cursor_set_ = false;
  std::uint64_t base_move_ = 0;  ///< scan move of the running job's move 0
  bool stop_at_a_ = false;
  std::optional<PathPoint> c_;  ///< the point the program resumes at

  mutable std::mutex records_mutex_;
  std::vector<RetraceRecord> records_;
};

}  // namespace opencnc::recovery
