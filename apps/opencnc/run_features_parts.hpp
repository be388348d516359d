// SPDX-License-Identifier: GPL-3.0-or-later
// The features' parts of `opencnc run`, one file each (run_<feature>.cpp), and what they share.
#pragma once

#include <cmath>
#include <cstdlib>
#include <memory>

#include "run_feature.hpp"

namespace opencnc::cli {

std::unique_ptr<RunFeature> toolguard_run();
std::unique_ptr<RunFeature> broaching_run();
std::unique_ptr<RunFeature> edm_run();
std::unique_ptr<RunFeature> cutting_run();
std::unique_ptr<RunFeature> retrace_run();
std::unique_ptr<RunFeature> process_log_run();

/// The number at `from` up to `stop` (an --inject value's part), `end` after it; −1 when there is
/// none, it is not finite or `stop` does not follow.
inline double injection_number(const char* from, char stop, const char*& end) {
  char* e = nullptr;
  const double v = std::strtod(from, &e);
  end = e;
  return e != from && *e == stop && std::isfinite(v) ? v : -1.0;
}

}  // namespace opencnc::cli
