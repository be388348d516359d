// SPDX-License-Identifier: GPL-3.0-or-later
// ProgramSource and ProgramStream — the seam between G-code and the controller: a preflight scan
// of a whole program, and its execution as a stream of moves that stops at sync points until the
// machine has answered (a probe's trip, an input's value, a tool change, the operator's go-on).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/canon/program.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::config {
struct MachineProfile;
}

namespace opencnc::controller {

/// Ends a long scan early: a halt (e-stop, machine off, abort) was sent after the request that
/// started it. Plain data; reads one atomic.
struct ScanCancel {
  const std::atomic<std::uint64_t>* halt_seq = nullptr;  ///< the send order of the latest halt
  std::uint64_t request_seq = 0;                         ///< the send order of the request scanning
  bool requested() const noexcept {
    return halt_seq != nullptr && halt_seq->load(std::memory_order_relaxed) > request_seq;
  }
};

/// Switches that change how a program is read.
struct LoadOptions {
  bool block_delete = false;  ///< skip lines that start with '/'
  ScanCancel cancel = {};     ///< preflight and resume's replay: stop when it is requested
};

/// What a program waits for at a sync point.
enum class SyncKind : std::uint8_t {
  None,
  Probe,        ///< G38.x: where the probe tripped, and whether it did
  Input,        ///< M66: the value read
  ToolChange,   ///< M6: the tool is in the spindle (the operator may have measured it)
  ProgramStop,  ///< M0, M1, M60: the operator has pressed cycle start
};

/// "probe", "input", "tool change", "program stop" ("" for None). Any thread.
const char* to_string(SyncKind k) noexcept;

/// Where a program is: the file and line being read, and the subprogram calls that led there.
struct SourceLocation {
  std::string file;
  std::uint32_t line = 0;
  /// The calls, outermost first ("o<drill> call at part.ngc:12" …); empty in the main program.
  std::vector<std::string> calls;
};

/// A sync point the stream waits at.
struct SyncRequest {
  SyncKind kind = SyncKind::None;
  SourceLocation where;       ///< the block that asked
  bool contact_required = false;  ///< Probe: G38.2/G38.4 fail without a change of the probe
};

/// The machine's answer at a sync point. Positions in machine coordinates (mm, degrees).
struct SyncAnswer {
  SyncKind kind = SyncKind::None;
  Pose position{};        ///< where the machine stands now (every kind)
  Pose probe_position{};  ///< Probe: the actual position where it tripped (or the move's end)
  bool probe_tripped = false;
  double input_value = 0;  ///< Input: the value read (−1: timed out)
};

/// How far a stream has got.
enum class StreamState : std::uint8_t {
  Reading,   ///< more moves may come: call read()
  Sync,      ///< waits at sync_request() for answer()
  Finished,  ///< the program ended: no more moves
  Error,     ///< the program failed: diagnostics() says where; no more moves
};

/// A program being executed: its moves in machine coordinates appear in program(), a window on
/// the stream (canon::Program::release_before). Controller thread only.
class ProgramStream {
 public:
  virtual ~ProgramStream() = default;
  /// The moves and actions of the current leg so far.
  virtual const canon::Program& program() const = 0;
  /// Reads on until `more_moves` more moves are there, a sync point, the end or an error.
  virtual StreamState read(std::size_t more_moves) = 0;
  virtual StreamState state() const = 0;
  /// The sync point the stream waits at (state() == Sync).
  virtual const SyncRequest& sync_request() const = 0;
  /// Releases the sync point with the machine's answer; the stream reads on (or fails: a probe
  /// that had to trip and did not).
  virtual void answer(const SyncAnswer& a) = 0;
  /// A new leg: the machine stopped short of where the moves read so far end (a probe tripped),
  /// so what follows starts at `start` (machine coordinates). program() becomes a new window
  /// whose first move is the next one. `from_move`: the first move of the current leg that
  /// has not run (the others are dropped; a stream that is read up to a sync point has none).
  virtual void restart_at(const Pose& start, std::size_t from_move) = 0;
  /// Frees what every reader has passed (see canon::Program::release_before).
  virtual void release(std::size_t move, std::size_t action) = 0;
  /// Problems found while reading (errors end the stream).
  virtual const Diagnostics& diagnostics() const = 0;
  /// Where the interpreter is now (the line read last).
  virtual SourceLocation location() const = 0;
  /// Where the block of move `move` of the current leg came from (the call stack included).
  virtual SourceLocation location_of(std::size_t move) const = 0;
};

/// Checks one move of a program before it may run (soft limits, the planner's checks). Adds
/// errors with the move's file and line to `diags` and returns false when it may not.
class MoveCheck {
 public:
  virtual ~MoveCheck() = default;
  virtual bool check(const canon::Program& program, canon::SegmentId move, Diagnostics& diags) = 0;
  /// After the last move of a scan: what the checks held back (a count of errors not listed).
  virtual void finish(Diagnostics& /*diags*/) {}
};

/// What the preflight found out about a whole program, without keeping its moves.
struct PreflightSummary {
  std::uint64_t moves = 0;
  double path_length_mm = 0;   ///< along X Y Z (U V W for moves without XYZ motion)
  Pose min{}, max{};           ///< extent of every move (machine coordinates)
  bool has_moves = false;
  /// The sync points met (a program may have millions: the first kMaxListed are listed).
  std::uint64_t sync_points = 0;
  std::vector<std::pair<SyncKind, SourceLocation>> sync_list;
  /// Lines whose moves change when the machine answers differently at a sync point: their
  /// checks rest on an assumed answer and are made again with the real one before they run.
  std::uint64_t assumed_moves = 0;
  std::vector<SourceLocation> assumed_lines;  ///< the first kMaxListed, each line once
  static constexpr std::size_t kMaxListed = 100;
};

/// The preflight's result: no errors means the program may start.
struct Preflight {
  PreflightSummary summary;
  Diagnostics diagnostics;
  bool ok() const noexcept { return !diagnostics.has_errors(); }
};

/// Turns G-code into streams of canonical moves. The controller calls it from its own thread
/// (non-real-time); implementations need not be thread-safe.
class ProgramSource {
 public:
  virtual ~ProgramSource() = default;
  /// Scans the whole file (no motion; the interpreter assumes the machine's answers at sync
  /// points) and checks every move with `check`, in memory bounded by design.
  virtual Preflight preflight(const std::string& path, const Pose& start, const LoadOptions& options,
                              MoveCheck& check) = 0;
  /// Opens `path` for execution from `start` (machine coordinates). Errors in opening show as
  /// state() == Error.
  virtual std::unique_ptr<ProgramStream> execute(const std::string& path, const Pose& start,
                                                 const LoadOptions& options) = 0;
  /// Opens `path` for execution resumed at segment `segment` (the interpreter's segment id):
  /// the program runs from its start, placed at `program_start` (where it started the first
  /// time), quietly up to the segment — modal state, offsets, compensation, parameters and the
  /// call stack as an uninterrupted run has them there; the spindle, coolant and outputs it had
  /// set are repeated before the segment —, and its moves begin with the rest of the segment
  /// from `start` (a point on it, machine coordinates). A probe or an input read before the
  /// segment makes it an error (its answer is not known again). Null: this source cannot resume.
  virtual std::unique_ptr<ProgramStream> resume(const std::string& /*path*/, const Pose& /*program_start*/,
                                                const Pose& /*start*/, canon::SegmentId /*segment*/,
                                                const LoadOptions& /*options*/) {
    return nullptr;
  }
  /// One MDI line from `start`, continuing the modal state the earlier lines left.
  virtual std::unique_ptr<ProgramStream> mdi(std::string_view line, const Pose& start) = 0;
  /// Changes whenever something a program reads besides its file changes (the tool table): a
  /// preflight holds for the version it was made with.
  virtual std::uint64_t version() const { return 0; }
  /// The machine's profile changed (an admin's edit while nothing runs): a source that took
  /// something from it (an EDM's condition numbers, which M180 P must name) takes it again, and
  /// its version() changes when a program may read differently. Controller thread.
  virtual void profile_changed(const config::MachineProfile& /*profile*/) {}
};

/// The location of a block: `line` in the body file of `context` (the main file for context 0),
/// with the calls that led there. Non-real-time.
SourceLocation locate(const canon::SourceMap& map, std::uint32_t context, std::uint32_t line);

/// "part.ngc:12", with " (in o<drill> called at part.ngc:30)" for every call. Any thread.
std::string to_string(const SourceLocation& l);

/// A whole program built from canonical calls, as a stream: no sync points, nothing to read. It
/// starts at `start` (the rest of it moved there when it starts elsewhere); a restart is the rest
/// of the program from a move (program_tail). Controller thread.
std::unique_ptr<ProgramStream> canon_stream(std::shared_ptr<const canon::Program> program, const Pose& start);

}  // namespace opencnc::controller
