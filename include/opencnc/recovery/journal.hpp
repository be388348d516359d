// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::Journal — the breakpoint journal's storage: two checksummed slots written in turn with
// fdatasync, so that a cut mid-write (power, SIGKILL) always leaves the last good record.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace opencnc::recovery {

/// One record as read back: its sequence number (1, 2, … in write order) and its bytes.
struct JournalRecord {
  std::uint64_t sequence = 0;
  std::vector<std::byte> payload;
};

/// Two files in a folder (`slot-a.jrn`, `slot-b.jrn`), each holding one record: a header (magic,
/// format version, payload length, sequence), the payload and a CRC-32 of both. A write goes to the
/// slot that does not hold the newest good record on the disk (both are read first), in one
/// pwrite at offset 0, then fdatasync; a torn or corrupt slot fails its checksum and the other one
/// is read. Not thread-safe: one writer
/// thread (the journal feature's), never the servo thread (it blocks on the disk).
class Journal {
 public:
  /// Largest payload accepted (a breakpoint record is a few kilobytes).
  static constexpr std::size_t kMaxPayload = 1 << 20;

  /// Opens the journal in `dir` (created with its slot files if missing, the folder synced), or
  /// nullptr with the reason in `error`.
  static std::unique_ptr<Journal> open(const std::string& dir, std::string* error);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  /// Writes `payload` as the next record and makes it durable (fdatasync) before returning true;
  /// false with the reason (the last good record is still there).
  bool write(std::span<const std::byte> payload, std::string* error);
  /// The newest record whose checksum holds, or nullopt (none written, or both slots bad).
  std::optional<JournalRecord> read() const;
  /// Sequence of the newest good record (0: none).
  std::uint64_t sequence() const noexcept { return sequence_; }

 private:
  Journal(int fd_a, int fd_b);
  std::optional<JournalRecord> read_slot(int fd) const;

  int fds_[2] = {-1, -1};
  std::uint64_t sequence_ = 0;  ///< of the newest record written or found
};

/// CRC-32 (IEEE 802.3, the polynomial of zlib and PNG) of `bytes`, continuing from `crc`. Any thread.
std::uint32_t crc32(std::span<const std::byte> bytes, std::uint32_t crc = 0) noexcept;

}  // namespace opencnc::recovery
