// SPDX-License-Identifier: GPL-3.0-or-later
// RunRecorder — the report of a run from its per-period trace samples: machining time, path
// length, following error, contour error against the programmed path, per-axis velocity,
// acceleration and jerk, limit violations. And the trace CSV writer.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "opencnc/analysis/trace_checker.hpp"
#include "opencnc/canon/program.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/core/output_file.hpp"
#include "opencnc/plan/machine_limits.hpp"

namespace opencnc::controller {

/// What `opencnc run` reports (docs/controller.md lists the JSON keys).
struct RunReport {
  double machining_time_s = 0;  ///< periods of the run × period (start to program end)
  double motion_time_s = 0;     ///< first to last period in which the commanded position changed
  double path_length_mm = 0;    ///< commanded, XYZ (and UVW)
  double max_following_error_mm = 0;
  int max_following_error_axis = -1;
  double max_contour_error_mm = 0;                     ///< actual (feedback) position to the programmed path
  double max_command_contour_error_mm = 0;             ///< commanded position to the programmed path
  std::array<analysis::AxisStats, kAxisCount> axes{};  ///< of the commanded trajectory
  /// Samples × axes × derivatives above a limit: of the commanded trajectory against the planning
  /// limits, and of the drives' commands (with compensation) against the axes' own limits.
  std::uint64_t limit_violations = 0;
  std::uint64_t output_limit_violations = 0;     ///< the drives' commands' share of them
  analysis::Violation first_output_violation{};  ///< where to look when there are some
  double max_compensation_mm = 0;                ///< largest |output − commanded| of a linear axis
  std::uint64_t samples = 0;
};

/// Accumulates the samples of program runs: attach it to a controller with trace on (it takes
/// the Program activity's samples), or feed it samples with add(). Non-real-time.
class RunRecorder final : public ControllerObserver {
 public:
  /// `limits`: what the commanded trajectory was planned within (controller::machine_limits);
  /// `output_limits`: what the drives' commands, with the compensation, must stay within
  /// (controller::axis_limits; by default `limits`). Axes outside `limits` (hand-fed ones) do not
  /// count: they are taken to stay where the run started.
  RunRecorder(const plan::MachineLimits& limits, double period_s,
              const plan::MachineLimits* output_limits = nullptr);
  /// For samples of one whole program (its moves numbered as in `program`, which must outlive
  /// the recorder).
  RunRecorder(const canon::Program& program, const plan::MachineLimits& limits, double period_s,
              const plan::MachineLimits* output_limits = nullptr);

  /// One period of a run, with the program window its segment ids refer to (null: none; the
  /// contour error is not measured then). In order.
  void add(const control::TraceSample& s, const TraceContext& c);
  /// One period of the run of the program given at construction.
  void add(const control::TraceSample& s);
  RunReport report() const;

  void on_trace(const control::TraceSample& s, const TraceContext& c) override {
    if (s.activity == control::Activity::Program) add(s, c);
  }

 private:
  void begin(const Pose& start);
  control::TraceSample planned_axes(const control::TraceSample& s) const;
  const canon::Program* fixed_ = nullptr;
  bool started_ = false;
  std::uint32_t run_id_ = 0;  ///< the servo run of the last sample (a new one starts at rest)
  plan::MachineLimits limits_;
  double period_s_;
  analysis::TraceChecker commanded_;
  analysis::TraceChecker actual_;
  analysis::TraceChecker output_;
  Pose output_lead_{};  ///< the first sample's output, until the second starts the output check
  Pose start_{};
  RunReport r_;
  Pose last_{};
  std::uint64_t first_move_ = 0, last_move_ = 0;
  bool moved_ = false;
};

/// Writes trace samples as CSV, one row per period (columns in docs/controller.md), each row
/// one whole record of `out` (core::OutputFile: a full disk leaves whole rows). Non-real-time.
class TraceCsvWriter {
 public:
  /// Writes the header for the axes in `axes`; `out` must outlive the writer.
  TraceCsvWriter(OutputFile& out, AxisMask axes, double period_s);
  /// One row; false once the output has failed (OutputFile::commit says why).
  bool add(const control::TraceSample& s);

 private:
  OutputFile& out_;
  AxisMask axes_;
  double period_s_;
  std::string row_;
};

}  // namespace opencnc::controller
