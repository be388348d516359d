// SPDX-License-Identifier: GPL-3.0-or-later
// Reads LinuxCNC's `rs274 -g` canonical-call listing into canonical calls on a canon::Sink, so
// that G-code programs can be planned before our own interpreter is on main (measurement tool).
#pragma once

#include <istream>
#include <string>

#include "opencnc/canon/sink.hpp"

namespace opencnc::bench {

/// Feeds every canonical call of an `rs274 -g` listing to `sink`, in order, with segment ids
/// counting the motions. Lines that are not calls and calls the planner does not need (comments,
/// tool length offsets, ...) are skipped. Returns the number of motions.
std::size_t read_rs274_listing(std::istream& in, canon::Sink& sink);

}  // namespace opencnc::bench
