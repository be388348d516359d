// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint journal's two slots: layout, CRC-32, written in turn and made durable (direct,
// fdatasync or RWF_DSYNC), the newest good one read.
#include "opencnc/broaching/journal.hpp"

#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "journal_slot.hpp"

namespace opencnc::recovery {

namespace {

constexpr std::array<char, 8> kMagic = {'O', 'C', 'N', 'C', 'J', 'R', 'N', 'L'};
constexpr std::uint32_t kVersion = 1;
/// magic, version (u32), payload length (u32), sequence (u64); then payload, then CRC-32 (u32).
constexpr std::size_t kHeader = 8 + 4 + 4 + 8;

std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}

}  // namespace

std::uint32_t crc32(std::span<const std::byte> bytes, std::uint32_t crc) noexcept {
  static const std::array<std::uint32_t, 256> table = make_crc_table();
  crc = ~crc;
  for (std::byte b : bytes) crc = table[(crc ^ static_cast<std::uint32_t>(b)) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

namespace {

std::string describe(JournalSync sync) {
  switch (sync) {
    case JournalSync::Direct:
      return "direct (O_DIRECT|O_DSYNC, whole 4 KiB blocks)";
    case JournalSync::Fdatasync:
      return "fdatasync";
    case JournalSync::Dsync:
      return "dsync (pwritev2 with RWF_DSYNC)";
  }
  return "?";
}

/// pwritev2's answers where the kernel or the file system does not know RWF_DSYNC.
bool refused(int error) {
  return error == EOPNOTSUPP || error == ENOSYS || error == EINVAL;
}

void close_slot(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

}  // namespace

std::unique_ptr<Journal> Journal::open(const std::string& dir, std::string* error, JournalOptions options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    if (error) *error = "cannot create the journal folder " + dir + ": " + ec.message();
    return nullptr;
  }
  const std::string paths[2] = {(std::filesystem::path(dir) / "slot-a.jrn").string(),
                                (std::filesystem::path(dir) / "slot-b.jrn").string()};
  for (const std::string& path : paths) {  // both checked before either is touched
    if (std::string why = detail::refuse_slot_file(path); !why.empty()) {
      if (error) *error = std::move(why);
      return nullptr;
    }
  }
  Slot slots[2];
  for (int s = 0; s < 2; ++s) {
    slots[s].fd = detail::open_slot(paths[s], error);
    if (slots[s].fd < 0) {
      if (s == 1) close_slot(slots[0].fd);
      return nullptr;
    }
  }
  if (!detail::sync_folder(dir, error)) {  // the slot files themselves survive a power cut
    close_slot(slots[0].fd);
    close_slot(slots[1].fd);
    return nullptr;
  }
  JournalSync sync = options.sync;
  std::string how = describe(sync);
  for (int s = 0; s < 2 && sync == JournalSync::Direct; ++s) {
    slots[s].direct_fd = detail::open_direct(paths[s]);
    if (slots[s].direct_fd < 0) {
      how = describe(JournalSync::Fdatasync) +
            " (O_DIRECT refused by the file system: " + std::strerror(errno) + ")";
      sync = JournalSync::Fdatasync;
      for (Slot& slot : slots) close_slot(slot.direct_fd);
    }
  }
  std::unique_ptr<Journal> j(new Journal(slots[0], slots[1], sync, std::move(how)));
  for (const Slot& slot : j->slots_) {
    const auto r = j->read_slot(slot.fd);
    if (r && r->sequence > j->sequence_) j->sequence_ = r->sequence;
  }
  return j;
}

Journal::Journal(Slot a, Slot b, JournalSync sync, std::string how)
    : slots_{a, b}, sync_(sync), how_(std::move(how)) {}

Journal::~Journal() {
  for (Slot& slot : slots_) {
    close_slot(slot.fd);
    close_slot(slot.direct_fd);
  }
  std::free(buffer_);
}

void Journal::fall_back(const std::string& why) {
  sync_ = JournalSync::Fdatasync;
  how_ = describe(sync_) + " (" + why + ")";
  for (Slot& slot : slots_) close_slot(slot.direct_fd);
}

bool Journal::write(std::span<const std::byte> payload, std::string* error) {
  if (payload.size() > kMaxPayload) {
    if (error) *error = "a journal record holds at most 1 MiB";
    return false;
  }
  const std::uint64_t seq = sequence_ + 1;
  const auto size = static_cast<std::uint32_t>(payload.size());
  const std::size_t record = kHeader + payload.size() + 4;
  const std::size_t bytes = (record + kBlockBytes - 1) / kBlockBytes * kBlockBytes;
  if (buffer_bytes_ < bytes) {  // aligned for O_DIRECT; grows only for a larger record
    std::free(buffer_);
    buffer_ = static_cast<std::byte*>(std::aligned_alloc(kBlockBytes, bytes));
    buffer_bytes_ = buffer_ != nullptr ? bytes : 0;
    if (buffer_ == nullptr) {
      if (error) *error = "cannot write the journal: out of memory";
      return false;
    }
  }
  std::byte* b = buffer_;
  std::memcpy(b, kMagic.data(), kMagic.size());
  std::memcpy(b + 8, &kVersion, 4);
  std::memcpy(b + 12, &size, 4);
  std::memcpy(b + 16, &seq, 8);
  if (!payload.empty()) std::memcpy(b + kHeader, payload.data(), payload.size());
  const std::uint32_t crc = crc32(std::span<const std::byte>(b, kHeader + payload.size()));
  std::memcpy(b + kHeader + payload.size(), &crc, 4);
  // The rest of the last block: zeros, not an older record's tail.
  std::memset(b + record, 0, bytes - record);
  // Never the slot of the last good record as it is on the disk now (a slot corrupted since the
  // last write is the one to overwrite, whatever this object remembers).
  const auto a = read_slot(slots_[0].fd), other = read_slot(slots_[1].fd);
  const int slot = !a ? 0 : !other ? 1 : (a->sequence < other->sequence ? 0 : 1);
  if (!write_blocks(slots_[slot], std::span<const std::byte>(b, bytes), error)) return false;
  sequence_ = seq;
  return true;
}

// One write of whole blocks at offset 0, durable when it returns: one pwritev2 with RWF_DSYNC, a
// buffered write then fdatasync, or with O_DIRECT|O_DSYNC the write itself. A way the kernel or the
// file system refuses at the first write falls back to fdatasync for good.
bool Journal::write_blocks(const Slot& slot, std::span<const std::byte> blocks, std::string* error) {
  const bool direct = sync_ == JournalSync::Direct;
  const int fd = direct ? slot.direct_fd : slot.fd;
  std::size_t done = 0;
  while (done < blocks.size()) {
    ssize_t n = 0;
    if (sync_ == JournalSync::Dsync) {
      iovec iov{const_cast<std::byte*>(blocks.data() + done), blocks.size() - done};
      n = ::pwritev2(fd, &iov, 1, static_cast<off_t>(done), RWF_DSYNC);
    } else {
      n = ::pwrite(fd, blocks.data() + done, blocks.size() - done, static_cast<off_t>(done));
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && done == 0 &&
        ((direct && errno == EINVAL) || (sync_ == JournalSync::Dsync && refused(errno)))) {
      fall_back(std::string(direct ? "O_DIRECT" : "RWF_DSYNC") + " refused: " + std::strerror(errno));
      return write_blocks(slot, blocks, error);
    }
    if (n <= 0) {
      if (error) *error = std::string("cannot write the journal: ") + std::strerror(errno);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  if (sync_ == JournalSync::Fdatasync && ::fdatasync(fd) != 0) {
    if (error) *error = std::string("cannot sync the journal: ") + std::strerror(errno);
    return false;
  }
  return true;
}

std::optional<JournalRecord> Journal::read_slot(int fd) const {
  std::array<std::byte, kHeader> head{};
  if (::pread(fd, head.data(), head.size(), 0) != static_cast<ssize_t>(head.size())) return std::nullopt;
  if (std::memcmp(head.data(), kMagic.data(), kMagic.size()) != 0) return std::nullopt;
  std::uint32_t version = 0, size = 0;
  JournalRecord r;
  std::memcpy(&version, head.data() + 8, 4);
  std::memcpy(&size, head.data() + 12, 4);
  std::memcpy(&r.sequence, head.data() + 16, 8);
  if (version != kVersion || size > kMaxPayload) return std::nullopt;
  std::vector<std::byte> rest(size + 4);
  if (::pread(fd, rest.data(), rest.size(), kHeader) != static_cast<ssize_t>(rest.size()))
    return std::nullopt;
  std::uint32_t stored = 0;
  std::memcpy(&stored, rest.data() + size, 4);
  const std::uint32_t crc = crc32(std::span(rest.data(), size), crc32(head));
  if (crc != stored) return std::nullopt;
  r.payload.assign(rest.begin(), rest.begin() + size);
  return r;
}

std::optional<JournalRecord> Journal::read() const {
  std::optional<JournalRecord> best;
  for (const Slot& slot : slots_) {
    auto r = read_slot(slot.fd);
    if (r && (!best || r->sequence > best->sequence)) best = std::move(r);
  }
  return best;
}

}  // namespace opencnc::recovery
