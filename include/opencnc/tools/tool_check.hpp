// SPDX-License-Identifier: GPL-3.0-or-later
// The check of a live tool table against its backup: one difference per parameter, edge or tool,
// with a tolerance per parameter kind; wear may drift within a band, geometry may not.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "opencnc/tools/tool_data.hpp"

namespace opencnc::tools {

/// How far a live value may be from the backed-up one without a complaint, per kind (mm).
struct CheckTolerances {
  double geometry_mm = 0.001;  ///< lengths and radius: a typing error is never this small
  double base_mm = 0.001;      ///< adapter dimensions
  double wear_band_mm = 0.1;   ///< wear may grow or be corrected this far from the backup
};

/// One difference between the backup and the live table.
struct Difference {
  enum class What : std::uint8_t {
    Changed,  ///< `param` differs: `backup`, `live`
    Added,    ///< the edge is live but not in the backup
    Removed,  ///< the edge is in the backup but not live
  };
  What what = What::Changed;
  int tool = 0;
  int edge = 0;
  std::optional<Param> param;  ///< Changed only
  double backup = 0, live = 0;
  double tolerance = 0;    ///< what the kind allows (0 for identities)
  bool tolerated = false;  ///< within the tolerance or wear band: listed by diff, not by check

  /// One line naming T, D, the parameter, the backup and the live value:
  /// "T53 D1 length1: backup 193.225, live 139.225 (-54 mm; geometry tolerance 0.001 mm)".
  std::string text() const;
};

/// Every difference between `backup` and `live` (tolerated ones too, marked), in T, D, $TC_DP
/// order. Pockets and comments are not compared (they do not move a cutting edge). Any thread.
std::vector<Difference> compare(const ToolSet& backup, const ToolSet& live,
                                const CheckTolerances& tolerances);
/// compare(), only the differences the check complains about; limited to the edges of tool
/// `tool` when given. Any thread.
std::vector<Difference> check(const ToolSet& backup, const ToolSet& live, const CheckTolerances& tolerances,
                              std::optional<int> tool = std::nullopt, std::optional<int> edge = std::nullopt);

/// A length as the operator typed it: shortest exact decimal ("193.225", "0.1"). Any thread.
std::string format_value(double v);

}  // namespace opencnc::tools
