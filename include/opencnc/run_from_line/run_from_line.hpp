// SPDX-License-Identifier: GPL-3.0-or-later
// RunFromLine — start the open program at a chosen line: the line resolved to the first move that
// starts at it (a scan on a thread of the feature's own), an approach there (an auxiliary program:
// the line's tool changed in at the tool-change position, its spindle and coolant, the moves),
// then the program resumed at that move's segment (requests::ResumeProgram: the interpreter
// replays quietly up to it).
// Requests: requests::Feature{"run-from-line", "start", RunFromLineArgs}. See docs/hmi.md.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "opencnc/controller/observer.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::run_from_line {

/// Arguments of "start".
struct RunFromLineArgs {
  std::uint32_t line = 0;  ///< 1-based line of the open program's main file
};

/// The tool table a run-from-line scan reads: the live one, while a G10 L1/L10/L11 the scan
/// passes goes to a copy of its own (the program writes the table when it really runs, not when
/// it is scanned), dropped by reset() before the next scan. Any thread.
class ScanToolTable final : public tools::ToolTableService {
 public:
  explicit ScanToolTable(std::shared_ptr<tools::ToolTableService> live) : live_(std::move(live)) {}
  std::shared_ptr<const tools::ToolTable> snapshot() const override;
  std::uint64_t version() const override;
  bool update(std::size_t index, const tools::ToolEntry& entry, tools::ChangeSource source,
              Diagnostics& diags) override;
  /// Drops the scan's changes: the live table again.
  void reset();

 private:
  std::shared_ptr<tools::ToolTableService> live_;
  mutable std::mutex mutex_;
  std::unique_ptr<tools::MemoryToolTable> own_;  ///< the scan's changes (null: none)
  std::uint64_t changes_ = 0;                    ///< updates and resets, added to the live version
};

/// Where a line of a program starts: the first move, in the order the program runs, whose block
/// is on that line of the main file (in the main program or a subroutine of the same file).
struct LineStart {
  canon::SegmentId segment = 0;  ///< the interpreter's segment id (what ResumeProgram takes)
  Pose start{};                  ///< where the move starts (machine coordinates)
  bool rapid = false;            ///< the move is a G0
  /// Its feed in mm/min (0 for a G0): under G93 the move's own (the interpreter's length × F),
  /// under G95 F × the spindle speed set before it.
  double feed_mm_per_min = 0;
  controller::SourceLocation where;  ///< its block, with the calls that led there
  /// The tool the program has in the spindle there: the T of the last M6 (or M61) before the
  /// line; −1 when none comes before it (the program runs with the machine's tool).
  int tool = -1;
  int tool_index = 0;  ///< that M6's tool-table index (LinuxCNC's CHANGE_TOOL argument)
  Pose tool_offset{};  ///< the tool-length offset (G43) in force at the line (mm)
  /// Spindle 0 as the program has set it before the line: 1 clockwise, −1 counterclockwise,
  /// 0 stopped, −2 never set (left as the machine has it).
  int spindle_direction = -2;
  /// Its speed in rpm (0: none set); under G96 the rpm the surface speed gives at the move's
  /// start, at most the G96 D limit.
  double spindle_rpm = 0;
  int flood = -1, mist = -1;  ///< coolant: 1 on, 0 off, −1 never set (left as the machine has it)
};

/// Runs `path` from `program_start` in execute mode without motion, answering stops and tool
/// changes as the machine would, until the first move of `line`. Nothing: `*why` says why — the
/// line makes no move (a comment, a subroutine that is not called), it lies past the last move,
/// or the program reads a probe or an input before it (the replay cannot know its answer), or
/// `cancel` was set. Any one thread at a time per `source`; bounded memory (what it has passed
/// is released).
std::optional<LineStart> find_line_start(controller::ProgramSource& source, const std::string& path,
                                         const Pose& program_start, std::uint32_t line,
                                         const controller::LoadOptions& options, std::string* why,
                                         const std::atomic<bool>* cancel = nullptr);

/// The feature. "start" needs the open program (a file), Auto mode and an idle machine; it
/// scans the program on a thread of its own (the controller answers meanwhile; every start is
/// refused until the scan ends, so the machine stays idle) and answers the request once the scan
/// has found where the program will start (or why not); then it runs the approach (the line's
/// tool changed in if the spindle has another, at the profile's tool-change position when it has
/// one, docs/tool-change.md; the spindle and coolant as the program has them
/// there, rapid up to the higher of the two Z, across, down at the move's own feed) and, once that
/// has finished, resumes the program there. Controller thread.
class RunFromLineFeature final : public controller::Feature {
 public:
  /// `source`: a program source of the feature's own for its scans (same profile and tool table
  /// as the controller's, so the segments and offsets are the same); used by the scan's thread.
  /// `tools`: the scan table behind `source` (reset before each scan), if it has one.
  explicit RunFromLineFeature(std::shared_ptr<controller::ProgramSource> source,
                              std::shared_ptr<ScanToolTable> tools = nullptr)
      : source_(std::move(source)), tools_(std::move(tools)) {}
  ~RunFromLineFeature() override;  ///< stops a scan under way and waits for its thread

  std::string_view name() const override { return "run-from-line"; }
  controller::Outcome handle(const controller::requests::Feature& request,
                             controller::FeatureHost& host) override;
  void poll(controller::FeatureHost& host) override;
  bool allow_start(const controller::StartCheck& start, controller::FeatureHost& host,
                   std::string* why) override;
  void on_event(const controller::ControllerEvent& e) override;
  void attached(controller::FeatureHost& host) override { host_ = &host; }

  /// Whether a scan is under way. Controller thread.
  bool scanning() const noexcept { return scan_ != nullptr; }

 private:
  /// A scan on its thread: the request it answers, and its result once `done`.
  struct Scan {
    std::uint64_t request = 0;
    std::uint32_t line = 0;
    std::uint64_t opened = 0;  ///< opened_ when it began: a program opened since makes it stale
    std::optional<LineStart> at;
    std::string why;
    std::atomic<bool> done{false}, cancel{false};
    std::thread thread;
  };
  std::shared_ptr<const canon::Program> approach(const Pose& machine, int spindle_tool,
                                                 const LineStart& to) const;
  void start_approach(Scan& scan, controller::FeatureHost& host);

  std::shared_ptr<controller::ProgramSource> source_;
  std::shared_ptr<ScanToolTable> tools_;
  std::unique_ptr<Scan> scan_;
  std::uint64_t opened_ = 0;  ///< counts ProgramOpened events
  controller::FeatureHost* host_ = nullptr;
  Pose program_start_{};  ///< where the machine stood when the open program was opened
  /// The resume that follows the approach, while it runs.
  std::optional<LineStart> pending_;
  std::uint32_t pending_line_ = 0;
  std::uint64_t approach_request_ = 0;
  bool resuming_ = false;  ///< the resume was asked: its JobStarted is not the operator's start
};

}  // namespace opencnc::run_from_line
