// SPDX-License-Identifier: GPL-3.0-or-later
// ControllerStatus — what a front end shows: the servo's snapshot plus what the controller knows
// (the open program, the job running, where the machine and the interpreter are, what they wait for).
#pragma once

#include <cstdint>
#include <string>

#include "opencnc/control/status.hpp"
#include "opencnc/controller/program_source.hpp"

namespace opencnc::controller {

/// What a run executes.
enum class JobKind : std::uint8_t {
  None,
  Program,    ///< the open (main) program, in Auto mode
  Mdi,        ///< an MDI line
  Auxiliary,  ///< a program of its own beside the main one (a check routine, an approach move)
};

/// "program", "mdi", "auxiliary" ("" for None). Any thread.
const char* to_string(JobKind k) noexcept;

/// How a job ended.
enum class JobEnd : std::uint8_t {
  Finished,  ///< the program's end was reached
  Aborted,   ///< the operator aborted it (or a mode change did)
  Error,     ///< the program failed while it ran (a check with a real value, a probe without contact)
  Fault,     ///< a fault, e-stop or machine off stopped it
};

/// "finished", "aborted", "error", "fault". Any thread.
const char* to_string(JobEnd e) noexcept;

/// The offsets the interpreter applies to a move (mm, or degrees on a rotary axis; machine axes):
/// machine = rotate_xy(work + g92) + g5x + tool, the program builder's transform.
struct WorkOffsets {
  std::uint8_t system = 1;     ///< 1 … 9: G54, G55, … G59, G59.1, G59.2, G59.3
  Pose g5x{};                  ///< the active coordinate system's origin
  Pose g92{};                  ///< G92 / G52 shift
  Pose tool{};                 ///< tool length offset (G43)
  double xy_rotation_deg = 0;  ///< the coordinate system's XY rotation (G10 L2 R)
};

/// "G54" … "G59.3" for WorkOffsets::system (1 … 9). Any thread.
const char* work_system_name(std::uint8_t system) noexcept;
/// The work coordinates of machine position `machine` under `o` (the builder's transform
/// inverted). Any thread; does not allocate.
Pose work_position(const Pose& machine, const WorkOffsets& o) noexcept;

/// The status a front end shows (Controller::status()).
struct ControllerStatus {
  control::ServoStatus servo;

  // The open (main) program.
  std::string program_name;        ///< "" = none
  std::uint64_t program_moves = 0;  ///< as the preflight counted them
  double program_length_mm = 0;    ///< as the preflight measured it

  // The job running, if any.
  bool run_active = false;  ///< a job was started and has not ended
  JobKind job = JobKind::None;
  std::uint32_t job_id = 0;
  std::string job_name;
  /// Move of the job at the commanded position (counted from the job's start, across the legs
  /// a probe trip makes), and the path length from that move's start to the commanded position:
  /// together, exactly where in the program the machine is (what recovery needs).
  std::uint64_t run_segment = 0;
  double segment_offset = 0;
  double progress = 0;  ///< 0 … 1 of the main program's path length
  /// The offsets of the move at the commanded position (after a job: the last job's, as they
  /// stay in the interpreter's state); work position = work_position(servo.actual, offsets).
  WorkOffsets offsets;
  /// The current move's end minus the commanded position, per axis (machine coordinates; 0
  /// without a run moving).
  Pose distance_to_go{};
  /// The source at the commanded position: file, line and the calls that led there.
  SourceLocation location;
  /// Where the interpreter reads (ahead of the machine), and the moves it has made so far.
  SourceLocation interpreter;
  std::uint64_t interpreter_moves = 0;
  /// The sync point the interpreter waits at for the machine (None: it does not).
  SyncKind sync_wait = SyncKind::None;
  SourceLocation sync_location;
  /// What the job waits for, in words ("" = nothing): "the operator (M0 at part.ngc:12)".
  std::string wait_text;

  bool block_delete = false;  ///< the block-delete switch ('/' lines skipped by the programs started now)
  std::string fault_text;           ///< servo.fault in words ("" = none)
  std::uint64_t runs_finished = 0;  ///< jobs that reached their program end
  /// Counts the machine parameters' changes applied (EditProfile): a front end that shows the
  /// soft limits reads them again when it changes.
  std::uint32_t limits_version = 0;
};

}  // namespace opencnc::controller
