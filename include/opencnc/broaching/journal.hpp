// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::Journal — the breakpoint journal's storage: two checksummed slots written in turn and
// made durable before the write returns, so that a cut mid-write (power, SIGKILL) always leaves the
// last good record.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::recovery {

/// One record as read back: its sequence number (1, 2, … in write order) and its bytes.
struct JournalRecord {
  std::uint64_t sequence = 0;
  std::vector<std::byte> payload;
};

/// How a record is made durable. All three do the same I/O on this machine's ext4 (one data write
/// and one cache flush of the device per record); they differ in the kernel's path to it. Dsync is
/// the default: the fastest of the three here, by a tenth of a millisecond or less
/// (docs/broaching.md, "The breakpoint journal's storage").
enum class JournalSync : std::uint8_t {
  /// One buffered pwritev2 with RWF_DSYNC: the write and the sync of its range in one call.
  /// Where the kernel refuses the flag (before Linux 4.7), the journal falls back to Fdatasync
  /// and says so in how().
  Dsync,
  /// A buffered pwrite of the slot's blocks, then fdatasync.
  Fdatasync,
  /// The slot's 4 KiB blocks written with O_DIRECT|O_DSYNC from an aligned buffer, past the page
  /// cache. Where the file system refuses O_DIRECT (EINVAL), the journal falls back to Fdatasync
  /// and says so in how().
  Direct,
};

/// Name of a way of writing ("direct", "fdatasync", "dsync"). Any thread.
std::string_view to_string(JournalSync s) noexcept;

/// How a journal is opened.
struct JournalOptions {
  JournalSync sync = JournalSync::Dsync;
};

/// Two files in a folder (`slot-a.jrn`, `slot-b.jrn`), each holding one record: a header (magic,
/// format version, payload length, sequence), the payload and a CRC-32 of both, zeros to the end
/// of its last 4 KiB block. The slot files are whole 4 KiB blocks, allocated and written when the
/// journal opens them, so a record changes no metadata. A write goes to the slot that does not
/// hold the newest good record on the disk (both are read first), in one write of whole blocks at
/// offset 0, durable before it returns (JournalSync); a torn or corrupt slot fails its checksum
/// and the other one is read. Not thread-safe: one writer thread (the journal feature's), never
/// the servo thread (it blocks on the disk).
class Journal {
 public:
  /// Largest payload accepted (a breakpoint record is a few kilobytes).
  static constexpr std::size_t kMaxPayload = 1 << 20;

  /// Bytes of a slot block: the unit of the slot files' size and of every write.
  static constexpr std::size_t kBlockBytes = 4096;
  /// Largest slot file: the largest record rounded up to whole blocks. A bigger file in the
  /// journal's place is not a slot, and the journal refuses to open rather than overwrite it.
  static constexpr std::size_t kMaxSlotBytes =
      ((24 + kMaxPayload + 4 + kBlockBytes - 1) / kBlockBytes) * kBlockBytes;

  /// Opens the journal in `dir` (created with its slot files if missing, the folder synced), or
  /// nullptr with the reason in `error` (a slot file that is not a regular file or is larger
  /// than kMaxSlotBytes is refused before anything is written). Any thread; blocks on the disk.
  static std::unique_ptr<Journal> open(const std::string& dir, std::string* error,
                                       JournalOptions options = {});
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  /// Writes `payload` as the next record and makes it durable before returning true; false with
  /// the reason (the last good record is still there). The writer thread.
  bool write(std::span<const std::byte> payload, std::string* error);
  /// The newest record whose checksum holds, or nullopt (none written, or both slots bad).
  std::optional<JournalRecord> read() const;
  /// Sequence of the newest good record (0: none).
  std::uint64_t sequence() const noexcept { return sequence_; }
  /// The way records are written now (after a fallback, the one in use). The writer thread.
  JournalSync sync() const noexcept { return sync_; }
  /// How records are written, in words: the way, and why it is not the one asked for if the
  /// file system refused it ("fdatasync (O_DIRECT refused by the file system: Invalid
  /// argument)"). The writer thread.
  const std::string& how() const noexcept { return how_; }

 private:
  struct Slot {
    int fd = -1;         ///< buffered, read and write
    int direct_fd = -1;  ///< O_DIRECT|O_DSYNC (JournalSync::Direct), else -1
  };
  Journal(Slot a, Slot b, JournalSync sync, std::string how);
  std::optional<JournalRecord> read_slot(int fd) const;
  bool write_blocks(const Slot& slot, std::span<const std::byte> blocks, std::string* error);
  void fall_back(const std::string& why);

  Slot slots_[2];
  JournalSync sync_ = JournalSync::Dsync;
  std::string how_;
  std::uint64_t sequence_ = 0;   ///< of the newest record written or found
  std::byte* buffer_ = nullptr;  ///< kBlockBytes-aligned, buffer_bytes_ long (O_DIRECT needs it)
  std::size_t buffer_bytes_ = 0;
};

/// The calling thread's I/O priority to the real-time class (IOPRIO_CLASS_RT, level 0), so that
/// the I/O scheduler (mq-deadline since Linux 5.14, bfq) dispatches its requests before other
/// threads' writes; false where not permitted (no CAP_SYS_ADMIN or CAP_SYS_NICE): the thread keeps
/// its priority. Any thread, for itself; not RT-safe (a system call).
bool raise_io_priority() noexcept;
/// The calling thread's I/O priority back to the default (its CPU scheduling's). Any thread.
void reset_io_priority() noexcept;

/// CRC-32 (IEEE 802.3, the polynomial of zlib and PNG) of `bytes`, continuing from `crc`. Any thread.
std::uint32_t crc32(std::span<const std::byte> bytes, std::uint32_t crc = 0) noexcept;

}  // namespace opencnc::recovery
