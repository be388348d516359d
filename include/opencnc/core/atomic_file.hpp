// SPDX-License-Identifier: GPL-3.0-or-later
// Crash-safe file replacement: temporary file, fdatasync, rename, sync of the folder.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace opencnc {

/// Replaces `path` with `content` so that a crash or power cut at any moment leaves either the old
/// file or the new one, never a mix: writes `path.tmp.<pid>`, fdatasync()s it, renames it over
/// `path` and fsync()s the folder. Returns false and sets `*error` (if given) on any failure; the
/// old file is then untouched. Non-real-time (blocking I/O).
bool write_file_atomically(const std::string& path, std::string_view content, std::string* error);

/// The most read_file() reads by default: profiles, tool tables, compensation tables and tokens
/// are far smaller; a larger file is refused rather than read until memory runs out.
inline constexpr std::size_t kMaxInputBytes = 64u << 20;

/// Reads a whole regular file of at most `max_bytes`. Anything else is refused before a byte is
/// read — a folder, a FIFO (which would block), a device such as /dev/zero (which never ends), a
/// socket —, as is a larger file. Returns false and sets `*error` (if given) to the reason
/// (`strerror`: "No such file or directory"…, "it is a folder, not a file", "it is a FIFO, not a
/// file", "it is larger than 64 MiB"). Non-real-time.
bool read_file(const std::string& path, std::string& out, std::string* error,
               std::size_t max_bytes = kMaxInputBytes);

/// Why `path` cannot be read as an input file (the checks of read_file, without reading it), or
/// "" when it can. Non-real-time.
std::string unreadable_input(const std::string& path, std::size_t max_bytes = kMaxInputBytes);

}  // namespace opencnc
