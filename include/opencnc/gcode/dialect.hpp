// SPDX-License-Identifier: GPL-3.0-or-later
// Choosing how to read a program: dialect names, a program's own dialect marker, and whether a
// Fanuc program is for a lathe or a mill.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "opencnc/gcode/options.hpp"

namespace opencnc::gcode {

/// "linuxcnc" or "fanuc" (any case). Any thread.
std::optional<Dialect> dialect_from_name(std::string_view name) noexcept;
/// "linuxcnc" / "fanuc". Any thread.
std::string_view dialect_name(Dialect dialect) noexcept;

/// "mill" or "lathe" (any case). Any thread.
std::optional<MachineKind> machine_kind_from_name(std::string_view name) noexcept;

/// The dialect a program names for itself: a comment such as `(dialect: fanuc)` or
/// `; dialect = linuxcnc` among its first 20 lines. nullopt when it names none (or the file
/// cannot be read). Non-real-time (reads the file).
std::optional<Dialect> dialect_marker(const std::string& path);

/// Whether a Fanuc program is for a lathe: it has X (or U) and Z words and no Y word anywhere
/// (comments aside). For front ends that are given no machine; a machine profile says it
/// instead. Non-real-time (reads the file, up to its first Y word).
MachineKind guess_machine_kind(const std::string& path);

}  // namespace opencnc::gcode
