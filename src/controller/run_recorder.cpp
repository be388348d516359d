// SPDX-License-Identifier: GPL-3.0-or-later
// Run reports from trace samples (two trace checkers: commanded and actual), and the trace CSV.
#include "opencnc/controller/run_recorder.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace opencnc::controller {

namespace {

const char* motion_name(traj::RunState s) {
  switch (s) {
    case traj::RunState::Idle:
      return "idle";
    case traj::RunState::Running:
      return "running";
    case traj::RunState::Holding:
      return "holding";
    case traj::RunState::Held:
      return "held";
    case traj::RunState::Starved:
      return "starved";
    case traj::RunState::Dwelling:
      return "dwelling";
    case traj::RunState::WaitingCycleStart:
      return "waiting-cycle-start";
    case traj::RunState::WaitingSpindle:
      return "waiting-spindle";
    case traj::RunState::WaitingSync:
      return "waiting-sync";
    case traj::RunState::Aborting:
      return "aborting";
    case traj::RunState::Aborted:
      return "aborted";
    case traj::RunState::Finished:
      return "finished";
  }
  return "?";
}

}  // namespace

RunRecorder::RunRecorder(const plan::MachineLimits& limits, double period_s,
                         const plan::MachineLimits* output_limits)
    : limits_(limits),
      period_s_(period_s),
      commanded_(limits, period_s),
      actual_(limits, period_s),
      output_(output_limits != nullptr ? *output_limits : limits, period_s) {}

RunRecorder::RunRecorder(const canon::Program& program, const plan::MachineLimits& limits, double period_s,
                         const plan::MachineLimits* output_limits)
    : RunRecorder(limits, period_s, output_limits) {
  fixed_ = &program;
  commanded_.set_program(&program);
  actual_.set_program(&program);
  output_.set_program(&program);
  begin(program.start());
}

// Before the first sample the machine stands where the run starts.
void RunRecorder::begin(const Pose& start) {
  commanded_.start_at(start);
  actual_.start_at(start);
  last_ = start;
  start_ = start;
  started_ = true;
}

// Axes nothing plans (hand-fed ones) move as the operator moves them: the path, its contour and
// the limits are those of the planned axes, so the others are held where the run started.
control::TraceSample RunRecorder::planned_axes(const control::TraceSample& in) const {
  control::TraceSample s = in;
  for (int i = 0; i < kAxisCount; ++i) {
    if (limits_.axes.has(static_cast<Axis>(i))) continue;
    s.commanded[i] = s.actual[i] = s.output[i] = start_[i];
    s.following_error[i] = 0;
  }
  return s;
}

void RunRecorder::add(const control::TraceSample& s, const TraceContext& c) {
  if (c.program != commanded_.program()) {
    commanded_.set_program(c.program);
    actual_.set_program(c.program);
    output_.set_program(c.program);
  }
  if (!started_) begin(c.program != nullptr ? c.program->start() : s.commanded);
  // A later run (a program resumed elsewhere, a new leg) starts at rest where its program starts:
  // the machine may have moved in between (jogs, auxiliary programs) without samples here, and
  // that jump is no velocity of the run.
  if (started_ && r_.samples > 0 && s.run_id != run_id_) {
    // Its first period has moved already: before it, each signal stood that much back.
    const Pose at = c.program != nullptr ? c.program->start() : s.commanded;
    Pose actual_at = s.actual, output_at = s.output;
    for (int i = 0; i < kAxisCount; ++i) {
      actual_at[i] -= s.commanded[i] - at[i];
      output_at[i] -= s.commanded[i] - at[i];
    }
    commanded_.start_at(at);
    actual_.start_at(actual_at);
    output_.start_at(output_at);
  }
  run_id_ = s.run_id;
  add(s);
}

void RunRecorder::add(const control::TraceSample& in) {
  if (!started_) begin(in.commanded);
  const control::TraceSample s = planned_axes(in);
  // The compensation may still be taking something up when the run starts (the table switched
  // on at homing a moment ago): the drives' commands are checked from the third period on, with
  // the first two as their history.
  if (r_.samples == 1) output_.start_moving(s.output, output_lead_);
  if (r_.samples == 0) output_lead_ = s.output;
  for (analysis::TraceChecker* c : {&commanded_, &actual_, &output_})
    c->set_acceleration_scale(s.stop_decel_scale);
  commanded_.add(s.commanded, s.segment_first, s.segment_last);
  actual_.add(s.actual, s.segment_first, s.segment_last);
  if (r_.samples >= 2) output_.add(s.output, s.segment_first, s.segment_last);
  for (int i = 0; i < kAxisCount; ++i) {
    if (limits_.axes.has(static_cast<Axis>(i)) && !is_rotary(static_cast<Axis>(i)))
      r_.max_compensation_mm = std::max(r_.max_compensation_mm, std::fabs(s.output[i] - s.commanded[i]));
  }
  for (int i = 0; i < kAxisCount; ++i) {
    if (!limits_.axes.has(static_cast<Axis>(i))) continue;
    const double e = std::fabs(s.following_error[i]);
    if (e > r_.max_following_error_mm) {
      r_.max_following_error_mm = e;
      r_.max_following_error_axis = i;
    }
  }
  if (s.commanded != last_) {
    if (!moved_) first_move_ = r_.samples;
    moved_ = true;
    last_move_ = r_.samples;
    last_ = s.commanded;
  }
  ++r_.samples;
}

RunReport RunRecorder::report() const {
  RunReport r = r_;
  const analysis::TraceReport& c = commanded_.report();
  r.machining_time_s = static_cast<double>(r.samples) * period_s_;
  r.motion_time_s = moved_ ? static_cast<double>(last_move_ - first_move_ + 1) * period_s_ : 0.0;
  r.path_length_mm = c.path_length_mm;
  r.max_command_contour_error_mm = c.max_contour_error_mm;
  r.max_contour_error_mm = actual_.report().max_contour_error_mm;
  r.axes = c.axes;
  r.output_limit_violations = output_.report().limit_violations;
  r.first_output_violation = output_.report().first_violation;
  r.limit_violations = c.limit_violations + r.output_limit_violations;
  return r;
}

TraceCsvWriter::TraceCsvWriter(OutputFile& out, AxisMask axes, double period_s)
    : out_(out), axes_(axes), period_s_(period_s) {
  std::string head = "time_s,state,motion,rapid,line,segment,path_velocity";
  for (int i = 0; i < kAxisCount; ++i) {
    if (!axes_.has(static_cast<Axis>(i))) continue;
    const char a = kAxisLetters[static_cast<std::size_t>(i)];
    head += fmt::format(",cmd_{0},act_{0},ferr_{0},out_{0},phase_{0},level_{0}", a);
  }
  out_.write(head + '\n');
}

bool TraceCsvWriter::add(const control::TraceSample& s) {
  row_.clear();
  fmt::format_to(std::back_inserter(row_), "{:.4f},{},{},{},{},{},{:.6g}",
                 static_cast<double>(s.tick) * period_s_, to_string(s.state), motion_name(s.motion),
                 s.rapid ? 1 : 0, s.line, s.segment, s.path_velocity);
  for (int i = 0; i < kAxisCount; ++i) {
    if (!axes_.has(static_cast<Axis>(i))) continue;
    fmt::format_to(std::back_inserter(row_), ",{:.6f},{:.6f},{:.6f},{:.6f},{},{:.4f}", s.commanded[i],
                   s.actual[i], s.following_error[i], s.output[i],
                   to_string(s.homing_phase[static_cast<std::size_t>(i)]), s.home_level[i]);
  }
  row_ += '\n';
  return out_.write(row_);
}

}  // namespace opencnc::controller
