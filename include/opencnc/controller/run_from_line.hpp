// SPDX-License-Identifier: GPL-3.0-or-later
// RunFromLine — start the open program at a chosen line: the line resolved to the first move that
// starts at it, an approach move there (an auxiliary program), then the program resumed at that
// move's segment (requests::ResumeProgram: the interpreter replays quietly up to it).
// Requests: requests::Feature{"run-from-line", "start", RunFromLineArgs}. See docs/hmi.md.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "opencnc/controller/observer.hpp"
#include "opencnc/controller/program_source.hpp"

namespace opencnc::control {

/// Arguments of "start".
struct RunFromLineArgs {
  std::uint32_t line = 0;  ///< 1-based line of the open program's main file
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
  SourceLocation where;          ///< its block, with the calls that led there
};

/// Runs `path` from `program_start` in execute mode without motion, answering stops and tool
/// changes as the machine would, until the first move of `line`. Nothing: `*why` says why — the
/// line makes no move (a comment, a subroutine that is not called), it lies past the last move,
/// or the program reads a probe or an input before it (the replay cannot know its answer).
/// Controller thread (it uses `source`); bounded memory (what it has passed is released).
std::optional<LineStart> find_line_start(ProgramSource& source, const std::string& path,
                                         const Pose& program_start, std::uint32_t line,
                                         const LoadOptions& options, std::string* why);

/// The feature. "start" needs the open program (a file), Auto mode and an idle machine; it
/// answers at once with where the program will start (or why not), then runs the approach
/// (rapid up to the higher of the two Z, across, down at the move's own feed) and, once that has
/// finished, resumes the program there. Controller thread.
class RunFromLineFeature final : public Feature {
 public:
  /// `source`: a program source of the feature's own for its scans (same profile as the
  /// controller's, so the segments are the same).
  explicit RunFromLineFeature(std::shared_ptr<ProgramSource> source) : source_(std::move(source)) {}

  std::string_view name() const override { return "run-from-line"; }
  Outcome handle(const requests::Feature& request, FeatureHost& host) override;
  void on_event(const ControllerEvent& e) override;
  void attached(FeatureHost& host) override { host_ = &host; }

 private:
  std::shared_ptr<const canon::Program> approach(const Pose& from, const LineStart& to) const;

  std::shared_ptr<ProgramSource> source_;
  FeatureHost* host_ = nullptr;
  Pose program_start_{};  ///< where the machine stood when the open program was opened
  /// The resume that follows the approach, while it runs.
  std::optional<LineStart> pending_;
  std::uint32_t pending_line_ = 0;
  std::uint64_t approach_request_ = 0;
  bool resuming_ = false;  ///< the resume was asked: its JobStarted is not the operator's start
};

}  // namespace opencnc::control
