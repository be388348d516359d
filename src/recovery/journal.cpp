// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint journal's two slots: layout, CRC-32, write in turn with fdatasync, read the newest
// good one.
#include "opencnc/recovery/journal.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace opencnc::recovery {

namespace {

constexpr std::array<char, 8> kMagic = {'O', 'C', 'N', 'C', 'J', 'R', 'N', 'L'};
constexpr std::uint32_t kVersion = 1;
/// magic, version (u32), payload length (u32), sequence (u64); then payload, then CRC-32 (u32).
constexpr std::size_t kHeader = 8 + 4 + 4 + 8;
/// Size a slot file is given when opened (a breakpoint record is about 600 bytes).
constexpr off_t kPresize = 4096;

std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}

void put(std::vector<std::byte>& out, const void* p, std::size_t n) {
  const auto* b = static_cast<const std::byte*>(p);
  out.insert(out.end(), b, b + n);
}

std::string reason(const char* what, const std::string& path) {
  return std::string(what) + " " + path + ": " + std::strerror(errno);
}

bool sync_folder(const std::string& dir, std::string* error) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    if (error) *error = reason("cannot sync the folder", dir);
    if (fd >= 0) ::close(fd);
    return false;
  }
  ::close(fd);
  return true;
}

// A slot file is made kPresize bytes long and its blocks allocated and written, once, when opened
// shorter or sparse: a record that fits then changes neither the file's size nor its block map, so
// the fdatasync of a record has no metadata to commit, only the data block to write (ftruncate
// alone leaves a hole, whose first write allocates a block: an extent change for the file
// system's journal inside the signal's fdatasync). The bytes there are written back as they
// read (a hole reads as zeros: no record), so a slot that holds a record keeps it even if this
// write is torn.
bool presize(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return false;
  if (st.st_size >= kPresize && st.st_blocks * 512 >= kPresize) return true;
  std::array<std::byte, kPresize> bytes{};
  const ssize_t got = ::pread(fd, bytes.data(), bytes.size(), 0);
  if (got < 0) return false;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd, bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return ::fsync(fd) == 0;
}

}  // namespace

std::uint32_t crc32(std::span<const std::byte> bytes, std::uint32_t crc) noexcept {
  static const std::array<std::uint32_t, 256> table = make_crc_table();
  crc = ~crc;
  for (std::byte b : bytes) crc = table[(crc ^ static_cast<std::uint32_t>(b)) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

std::unique_ptr<Journal> Journal::open(const std::string& dir, std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    if (error) *error = "cannot create the journal folder " + dir + ": " + ec.message();
    return nullptr;
  }
  int fds[2] = {-1, -1};
  const char* names[2] = {"slot-a.jrn", "slot-b.jrn"};
  for (int s = 0; s < 2; ++s) {
    const std::string path = (std::filesystem::path(dir) / names[s]).string();
    fds[s] = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fds[s] < 0 || !presize(fds[s])) {
      if (error) *error = reason(fds[s] < 0 ? "cannot open" : "cannot size", path);
      if (fds[s] >= 0) ::close(fds[s]);
      if (s == 1) ::close(fds[0]);
      return nullptr;
    }
  }
  if (!sync_folder(dir, error)) {  // the slot files themselves survive a power cut
    ::close(fds[0]);
    ::close(fds[1]);
    return nullptr;
  }
  std::unique_ptr<Journal> j(new Journal(fds[0], fds[1]));
  for (int s = 0; s < 2; ++s) {
    const auto r = j->read_slot(j->fds_[s]);
    if (r && r->sequence > j->sequence_) j->sequence_ = r->sequence;
  }
  return j;
}

Journal::Journal(int fd_a, int fd_b) : fds_{fd_a, fd_b} {}

Journal::~Journal() {
  for (int fd : fds_) {
    if (fd >= 0) ::close(fd);
  }
}

bool Journal::write(std::span<const std::byte> payload, std::string* error) {
  if (payload.size() > kMaxPayload) {
    if (error) *error = "a journal record holds at most 1 MiB";
    return false;
  }
  const std::uint64_t seq = sequence_ + 1;
  const auto size = static_cast<std::uint32_t>(payload.size());
  std::vector<std::byte> buf;
  buf.reserve(kHeader + payload.size() + 4);
  put(buf, kMagic.data(), kMagic.size());
  put(buf, &kVersion, 4);
  put(buf, &size, 4);
  put(buf, &seq, 8);
  buf.insert(buf.end(), payload.begin(), payload.end());
  const std::uint32_t crc = crc32(buf);
  put(buf, &crc, 4);
  // Never the slot of the last good record as it is on the disk now (a slot corrupted since the
  // last write is the one to overwrite, whatever this object remembers).
  const auto a = read_slot(fds_[0]), b = read_slot(fds_[1]);
  const int slot = !a ? 0 : !b ? 1 : (a->sequence < b->sequence ? 0 : 1);
  const int fd = fds_[slot];
  std::size_t done = 0;
  while (done < buf.size()) {
    const ssize_t n = ::pwrite(fd, buf.data() + done, buf.size() - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (error) *error = std::string("cannot write the journal: ") + std::strerror(errno);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fdatasync(fd) != 0) {
    if (error) *error = std::string("cannot sync the journal: ") + std::strerror(errno);
    return false;
  }
  sequence_ = seq;
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
  for (int fd : fds_) {
    auto r = read_slot(fd);
    if (r && (!best || r->sequence > best->sequence)) best = std::move(r);
  }
  return best;
}

}  // namespace opencnc::recovery
