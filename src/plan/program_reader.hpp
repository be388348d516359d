// SPDX-License-Identifier: GPL-3.0-or-later
// Reads a canon::Program in execution order: moves become path elements (with their feed class,
// nominal speed and modal path-control settings), actions become markers; G64 Q merges
// nearly collinear feed lines.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "element.hpp"
#include "opencnc/canon/program.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/plan/machine_limits.hpp"
#include "opencnc/traj/motion_block.hpp"
#include "ring.hpp"
#include "run_smoother.hpp"

namespace opencnc::plan::detail {

/// One item of the program in execution order: a path element, or a marker (in element.b, its
/// position filled in later).
struct Item {
  bool is_marker = false;
  Element element;
};

/// Checks every move of `program` against the machine: finite coordinates, configured axes,
/// positive feeds, valid arcs, supported move kinds. Errors go to `diags` with the move's source
/// position. Returns true when the program can be planned. Non-real-time.
bool check_program(const canon::Program& program, const MachineLimits& limits, Diagnostics& diags);

/// Streams the items of a checked program. The program may be a stream that grows while it is
/// read: then only the moves made readable are read, and the end of the readable part is not
/// the program's end until seal().
class ProgramReader {
 public:
  /// `streaming`: the program grows; nothing is read until readable() says how far.
  explicit ProgramReader(const canon::Program& program, bool streaming = false);

  /// Next item, valid (and the caller's to change) until the following call; null after the
  /// last one (the program end marker), or when a stream has nothing more to read for now.
  Item* next();
  /// Streams: moves [0, moves) may be read (their actions too, and the actions after them).
  void readable(std::size_t moves) noexcept { readable_ = moves; }
  /// Runs of short feed lines are fitted with one curve (run_smoother.hpp) before G64 Q may
  /// merge what is left. Before the first next().
  void set_smoothing(bool on) noexcept { smoothing_ = on; }
  std::uint64_t smoothed_runs() const noexcept { return smoother_.fitted_runs(); }
  /// Streams: no more moves will come; the end of the readable part is the program's end.
  void seal() noexcept { streaming_ = false; }
  /// Streams: hand out what is held back for the next move to decide (a G64 Q merge), as at
  /// a stop: the motion stops at the end of what is readable (a sync point).
  void flush() noexcept { flush_ = true; }
  /// The first move (action) index the reader may still look at.
  std::size_t oldest_move_needed() const noexcept;
  std::size_t oldest_action_needed() const noexcept { return next_action_; }
  std::uint64_t moves_read() const noexcept { return moves_read_; }
  std::uint64_t merged() const noexcept { return merged_; }

 private:
  std::size_t readable_limit() const noexcept;
  bool read_more();
  void read_actions_before(std::uint32_t move);
  void add_marker(std::size_t action, traj::MarkerKind kind);
  traj::MotionBlock& new_marker();
  void read_move(canon::SegmentId id);
  bool make_element(canon::SegmentId id, Element& e) const;
  void push_element(const Element& e);
  void take_element(const Element& e);
  void flush_smoother();
  void put_smoothed();
  bool can_extend_run(const Element& e) const;
  void chord_small_arc(const Pose& start, const Pose& end, double feed, Element& e) const;
  double merge_budget() const noexcept;
  void flush_run();
  std::uint8_t flags() const noexcept;

  const canon::Program* program_;
  std::size_t next_move_ = 0, next_action_ = 0;
  bool done_ = false, ended_ = false;
  bool streaming_ = false;  ///< more moves may come (until seal())
  bool gated_ = false;      ///< built for a stream: only readable() moves are read
  bool flush_ = false;
  bool smoothing_ = false;
  RunSmoother smoother_;
  std::vector<Element> smoothed_;  ///< scratch: what a run became
  std::size_t readable_ = 0;
  Ring<Item> ready_;
  bool handed_out_ = false;  // ready_.front() was returned by next()
  std::uint64_t moves_read_ = 0, merged_ = 0;

  // Modal state from the actions read so far.
  canon::MotionControl mode_ = canon::MotionControl::Continuous;
  double tolerance_ = 0, naive_tolerance_ = 0;
  bool override_enabled_ = true, hold_enabled_ = true;
  double sync_per_rev_ = 0;

  // The run of feed lines being merged (G64 Q).
  bool run_active_ = false;
  Element run_;
  Pose run_start_{};
  double run_feed_ = 0;
  double run_floor_ = 0;          ///< largest deviation of a chorded arc in the run
  /// Inner vertices of the run relative to its start, their squared lengths, and the axes on
  /// which any of them differs from the start (the only ones their dot products need).
  std::vector<Pose> run_points_;
  std::vector<double> run_squares_;
  std::array<int, kAxisCount> run_axes_{};
  int run_axis_count_ = 0;
  void add_run_point(const Pose& rel);
};

}  // namespace opencnc::plan::detail
