// SPDX-License-Identifier: GPL-3.0-or-later
// Run reports from trace samples (two trace checkers: commanded and actual), and the trace CSV.
#include "opencnc/controller/run_recorder.hpp"

#include <cmath>

#include <fmt/format.h>

namespace opencnc::control {

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

RunRecorder::RunRecorder(const plan::MachineLimits& limits, double period_s)
    : limits_(limits), period_s_(period_s), commanded_(limits, period_s), actual_(limits, period_s) {}

RunRecorder::RunRecorder(const canon::Program& program, const plan::MachineLimits& limits, double period_s)
    : RunRecorder(limits, period_s) {
  fixed_ = &program;
  commanded_.set_program(&program);
  actual_.set_program(&program);
  begin(program.start());
}

// Before the first sample the machine stands where the run starts.
void RunRecorder::begin(const Pose& start) {
  commanded_.start_at(start);
  actual_.start_at(start);
  last_ = start;
  started_ = true;
}

void RunRecorder::add(const TraceSample& s, const TraceContext& c) {
  if (c.program != commanded_.program()) {
    commanded_.set_program(c.program);
    actual_.set_program(c.program);
  }
  if (!started_) begin(c.program != nullptr ? c.program->start() : s.commanded);
  add(s);
}

void RunRecorder::add(const TraceSample& s) {
  if (!started_) begin(s.commanded);
  commanded_.add(s.commanded, s.segment_first, s.segment_last);
  actual_.add(s.actual, s.segment_first, s.segment_last);
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
  r.limit_violations = c.limit_violations;
  return r;
}

TraceCsvWriter::TraceCsvWriter(const std::string& path, AxisMask axes, double period_s)
    : out_(path), axes_(axes), period_s_(period_s) {
  if (!out_) return;
  std::string head = "time_s,state,motion,rapid,line,segment,path_velocity";
  for (int i = 0; i < kAxisCount; ++i) {
    if (!axes_.has(static_cast<Axis>(i))) continue;
    const char a = kAxisLetters[static_cast<std::size_t>(i)];
    head += fmt::format(",cmd_{0},act_{0},ferr_{0}", a);
  }
  out_ << head << '\n';
}

void TraceCsvWriter::add(const TraceSample& s) {
  row_.clear();
  fmt::format_to(std::back_inserter(row_), "{:.4f},{},{},{},{},{},{:.6g}",
                 static_cast<double>(s.tick) * period_s_, to_string(s.state), motion_name(s.motion),
                 s.rapid ? 1 : 0, s.line, s.segment, s.path_velocity);
  for (int i = 0; i < kAxisCount; ++i) {
    if (!axes_.has(static_cast<Axis>(i))) continue;
    fmt::format_to(std::back_inserter(row_), ",{:.6f},{:.6f},{:.6f}", s.commanded[i], s.actual[i],
                   s.following_error[i]);
  }
  row_ += '\n';
  out_ << row_;
}

bool TraceCsvWriter::close() {
  out_.flush();
  const bool good = static_cast<bool>(out_);
  out_.close();
  return good && !out_.fail();
}

}  // namespace opencnc::control
