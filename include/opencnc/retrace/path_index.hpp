// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::PathIndex — the feed path of a whole program (lines, arcs, helices in machine
// coordinates, as they will execute) in a bounding-volume tree, for the nearest point of the
// cutting path to where the operator moved the torch (flame/plasma retrace). See docs/retrace.md.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "opencnc/canon/program.hpp"
#include "opencnc/core/vec3.hpp"

namespace opencnc::recovery {

/// How distance is measured: in the XY plane (torch height ignored, the default) or in space.
enum class Metric : std::uint8_t { Xy, Xyz };

/// A point of the feed path.
struct PathPoint {
  canon::SegmentId segment = 0;  ///< the interpreter's segment id (what replay to segment k uses)
  std::uint64_t move = 0;        ///< the move's number in the scan (job move number)
  std::uint32_t entry = 0;       ///< the index's own number of the move (path order of feed moves)
  double param = 0;              ///< 0 at the move's start, 1 at its end (along the path)
  Vec3 point{};                  ///< machine coordinates X Y Z, mm
  double distance_mm = 0;        ///< from the query point, in the query's metric
  std::uint32_t context = 0;     ///< SourceMap context of the move's block (the call stack)
  std::uint32_t line = 0;        ///< source line of that block
};

/// What a query asks for.
struct QueryOptions {
  Metric metric = Metric::Xy;
  /// Other stretches of the path whose nearest point is within this much of the nearest
  /// distance are returned too (a path that crosses or runs beside itself): the operator picks.
  double margin_mm = 0.5;
};

/// The answer: the nearest point and, nearest first, one candidate per stretch of the path
/// within the margin (candidates[0] == nearest). Empty when the index holds no feed move.
struct Nearest {
  bool found = false;
  PathPoint nearest;
  std::vector<PathPoint> candidates;
};

/// The feed moves of a program (G1, G2/G3 and what cycles and compensation make of them; rapids,
/// probes and taps left out: C never lands on them), added in path order, then finished into a
/// tree. Non-real-time; build on one thread, then query from any number (queries are const).
class PathIndex {
 public:
  PathIndex();
  ~PathIndex();
  PathIndex(PathIndex&&) noexcept;
  PathIndex& operator=(PathIndex&&) noexcept;

  /// Adds move `move` of `program` if it is a feed move (lines, arcs; a window on a stream is
  /// fine: the move and its predecessor's end must be held). Before finish(). Builder thread.
  void add(const canon::Program& program, std::size_t move);
  /// Builds the tree: O(n log n). Queries before it find nothing. Builder thread.
  void finish();

  /// The nearest point of the feed path to `b` (machine coordinates, mm). O(log n) typical.
  /// Any thread after finish().
  Nearest nearest(const Vec3& b, const QueryOptions& options = {}) const;
  /// The same by looking at every move: the reference the tree is tested and measured against.
  Nearest nearest_linear(const Vec3& b, const QueryOptions& options = {}) const;

  /// The point `distance_mm` further along the feed path from `from` (negative: back), stopping
  /// at the path's ends; a gap (a rapid between two feed moves) is jumped over. Any thread.
  PathPoint advance(const PathPoint& from, double distance_mm) const;
  /// The point `offset_mm` along move `move` of the scan (a job's move number and the status'
  /// segment_offset); on a move that is no feed move (a rapid), the start of the next feed move.
  /// Nothing past the last feed move. Any thread after finish().
  std::optional<PathPoint> at_move(std::uint64_t move, double offset_mm) const;
  /// The point at `param` of entry `entry`. Any thread.
  PathPoint point_on(std::uint32_t entry, double param) const;

  std::size_t size() const noexcept;
  /// Bytes held by the moves and the tree.
  std::size_t memory_bytes() const noexcept;
  /// The source map the moves' contexts refer to (the scan's), for file and call stack.
  const std::shared_ptr<const canon::SourceMap>& sources() const noexcept;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace opencnc::recovery
