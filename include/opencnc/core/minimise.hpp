// SPDX-License-Identifier: GPL-3.0-or-later
// The one one-dimensional minimiser: a golden-section search of a function unimodal on an interval.
#pragma once

namespace opencnc {

/// Where a search ended: the better of its two last inner points and the function's value there.
struct Minimum {
  double x = 0;
  double f = 0;
};

/// Golden-section search of `f` over [lo, hi]: the interval shrinks by the golden ratio each step
/// (one evaluation a step) until it is shorter than `tolerance` or `max_steps` steps were taken.
/// Finds the minimum of a function unimodal on the interval; elsewhere a local one. Real-time safe
/// when `f` is. The caller compares the ends or a start value itself where they may be lower.
template <typename F>
Minimum golden_section(F&& f, double lo, double hi, int max_steps, double tolerance) {
  constexpr double kG = 0.6180339887498949;  // (√5 − 1) / 2
  double x1 = hi - kG * (hi - lo), x2 = lo + kG * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < max_steps && hi - lo > tolerance; ++i) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - kG * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + kG * (hi - lo), f2 = f(x2);
    }
  }
  return f1 < f2 ? Minimum{x1, f1} : Minimum{x2, f2};
}

}  // namespace opencnc
