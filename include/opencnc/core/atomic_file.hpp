// SPDX-License-Identifier: GPL-3.0-or-later
// Crash-safe file replacement: temporary file, fdatasync, rename, sync of the folder.
#pragma once

#include <string>
#include <string_view>

namespace opencnc {

/// Replaces `path` with `content` so that a crash or power cut at any moment leaves either the old
/// file or the new one, never a mix: writes `path.tmp.<pid>`, fdatasync()s it, renames it over
/// `path` and fsync()s the folder. Returns false and sets `*error` (if given) on any failure; the
/// old file is then untouched. Non-real-time (blocking I/O).
bool write_file_atomically(const std::string& path, std::string_view content, std::string* error);

/// Reads a whole file (or what a pipe gives). Returns false and sets `*error` (if given) to the
/// reason (`strerror`: "No such file or directory", "Is a directory"…) when it cannot be read.
/// Non-real-time.
bool read_file(const std::string& path, std::string& out, std::string* error);

}  // namespace opencnc
