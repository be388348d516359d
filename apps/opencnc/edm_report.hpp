// SPDX-License-Identifier: GPL-3.0-or-later
// The `edm` part of `opencnc run`'s report: printed and as JSON (docs/edm.md).
#pragma once

#include <optional>

#include <nlohmann/json.hpp>

#include "opencnc/edm/edm_recorder.hpp"
#include "run_session.hpp"

namespace opencnc::cli {

/// The recorder's figures, and the simulated gap's (`sim`) where the run had one.
nlohmann::json edm_json(const control::EdmReport& e, const std::optional<SimEdmFigures>& sim);
void print_edm(const control::EdmReport& e, const std::optional<SimEdmFigures>& sim);

}  // namespace opencnc::cli
