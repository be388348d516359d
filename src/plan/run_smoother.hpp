// SPDX-License-Identifier: GPL-3.0-or-later
// Runs of short feed lines (CAM output) replaced by one curvature-continuous cubic B-spline that
// stays within the tolerance of the programmed moves.
#pragma once

#include <cstddef>
#include <vector>

#include "element.hpp"
#include "path_geometry.hpp"

namespace opencnc::plan::detail {

/// When a run of moves is smoothed.
struct SmootherParams {
  double max_move = 2.0;        ///< mm: longer moves are kept (their ends are real corners)
  double max_turn = 0.6;        ///< rad: a sharper corner between two moves ends a run
  std::size_t max_moves = 256;  ///< a run is fitted once it has this many moves
  /// Without a tolerance (G64 without P and no default) the fit stays within this share of the
  /// run's shortest move: no farther than the half-move blends that would replace it.
  double free_share = 0.125;
};

/// Collects consecutive short feed lines (XYZ only, one feed, one path mode, no stop between) and
/// replaces each run by the cubic B-spline of uniform knots, natural ends, through the run's first
/// and last point, that fits the run's vertices in the least-squares sense with as few spans as
/// keep every point of the curve within the tolerance of the moves (half the G64 P, less what a
/// G64 Q merge took; the other half is left to the blends at the run's ends). Its spans go out
/// as cubic Bézier elements whose parameter is the knot spacing, so the joins are C2 in s and the
/// planner runs through them without a blend: the curvature follows the programmed shape instead
/// of a bump at every vertex. A run whose fit cannot keep the tolerance goes out as it came.
/// Non-real-time.
class RunSmoother {
 public:
  explicit RunSmoother(const SmootherParams& p = {}) : p_(p) {}

  /// Whether `e` continues the run (or can start one).
  bool accepts(const Element& e) const;
  void add(const Element& e) { run_.push_back(e); }
  bool empty() const noexcept { return run_.empty(); }
  bool full() const noexcept { return run_.size() >= p_.max_moves; }
  /// Fits the run and appends what replaces it to `out`; the run is empty afterwards.
  void flush(std::vector<Element>& out);
  /// A full run: appends the fitted curve up to the run's last quarter, which stays and is fitted
  /// on from there with the curve's point, first and second derivative (no kink, no blend).
  void flush_part(std::vector<Element>& out);
  /// Runs replaced by a fitted curve so far.
  std::size_t fitted_runs() const noexcept { return fitted_; }

 private:
  double fit_tolerance() const;
  void emit(bool partial, std::vector<Element>& out);
  bool fit(std::size_t spans, double tolerance, bool partial, std::vector<Element>& out);

  SmootherParams p_;
  std::vector<Element> run_;
  bool continued_ = false;  ///< the run goes on from a fitted part, which ended at `start_`
  JoinPoint start_{};
  // Scratch of fit(), kept to avoid allocating per run.
  std::vector<Pose> points_, control_, rhs_;
  std::vector<double> u_, band_;
  std::size_t fitted_ = 0;
};

}  // namespace opencnc::plan::detail
