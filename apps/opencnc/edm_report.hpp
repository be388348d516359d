// SPDX-License-Identifier: GPL-3.0-or-later
// The `edm` part of `opencnc run`'s report: printed and as JSON (docs/edm.md).
#pragma once

#include <nlohmann/json.hpp>

#include "opencnc/controller/edm_recorder.hpp"

namespace opencnc::cli {

nlohmann::json edm_json(const control::EdmReport& e);
void print_edm(const control::EdmReport& e);

}  // namespace opencnc::cli
