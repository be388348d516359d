// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::modal_digest_at — a digest of the interpreter's modal state where a program reaches
// segment k (units, offsets, plane, feed, path control, tool, spindle, coolant, coupling), from a
// replay of the program: the breakpoint record keeps it, resume checks it again.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "opencnc/canon/types.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::recovery {

/// Runs `path` in scan mode (`options`, placed at `program_start`, machine mm) up to the first
/// motion of segment `segment` and digests the canonical state the calls before it set (FNV-1a
/// 64 over the values; never 0). Nullopt with the reason in `*error` if the program fails or
/// ends first. Non-real-time; any thread (its own interpreter); reads the file.
std::optional<std::uint64_t> modal_digest_at(const gcode::Options& options, const std::string& path,
                                             const Pose& program_start, canon::SegmentId segment,
                                             std::string* error);

}  // namespace opencnc::recovery
