// SPDX-License-Identifier: GPL-3.0-or-later
// The toolpath of a program for the HMI's 3D view: polylines in machine coordinates, rapids and
// feeds apart, arcs as chords; a bounded number of moves.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/gcode_source.hpp"

namespace opencnc::hmi {

/// Scans `path` through `source` (GcodeProgramSource::scan: the interpreter in scan mode with the
/// options the source gives the file, every move through the machine's passes, as the preflight
/// checks it and the machine runs it) from the machine position `start`, at most `max_moves`
/// moves, into
/// `{"polylines": [{"rapid": bool, "points": [x, y, z, …]}], "moves": n, "truncated": bool,
///   "diagnostics": [...], "tools": [the tools its M6/M61 put in the spindle]}`. Non-real-time;
/// any thread but the controller's (it may take a while).
nlohmann::json program_preview(const controller::GcodeProgramSource& source, const std::string& path,
                               const Pose& start, std::size_t max_moves = 200000);

}  // namespace opencnc::hmi
