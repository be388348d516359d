// SPDX-License-Identifier: GPL-3.0-or-later
// The features' parts of `opencnc run`, in the order features::set_up sets the features up.
#include "run_feature.hpp"
#include "run_features_parts.hpp"

namespace opencnc::cli {

std::vector<std::unique_ptr<RunFeature>> run_features() {
  std::vector<std::unique_ptr<RunFeature>> out;
  out.push_back(toolguard_run());
  out.push_back(broaching_run());
  out.push_back(edm_run());
  out.push_back(cutting_run());
  out.push_back(retrace_run());
  out.push_back(process_log_run());
  return out;
}

}  // namespace opencnc::cli
