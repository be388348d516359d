// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint journal's slot files: what may stand in a slot's place, sizing and allocating a
// slot once when opened, the O_DIRECT descriptor, syncing the folder.
#pragma once

#include <string>

namespace opencnc::recovery::detail {

/// "" if `path` may be a slot (missing, or a regular file of at most Journal::kMaxSlotBytes);
/// else why not, naming the file. Reads nothing but its metadata.
std::string refuse_slot_file(const std::string& path);

/// Opens (creating) the slot at `path` for buffered reading and writing, its size rounded up to
/// whole Journal::kBlockBytes blocks (at least one), every block allocated and written (the bytes
/// there kept, a hole written as zeros) and synced: a record then changes neither the size nor
/// the block map. -1 with the reason in `error`.
int open_slot(const std::string& path, std::string* error);

/// A second descriptor of the slot at `path` with O_DIRECT|O_DSYNC, or -1 with errno set (EINVAL:
/// the file system does not do direct I/O).
int open_direct(const std::string& path);

/// fsync of the folder `dir`, so that the slot files created in it survive a power cut.
bool sync_folder(const std::string& dir, std::string* error);

}  // namespace opencnc::recovery::detail
