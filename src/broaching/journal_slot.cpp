// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint journal's slot files: refused when not a slot, sized and written out once when
// opened, a direct descriptor for the writes; the writer thread's I/O priority.
#include "journal_slot.hpp"

#include <fcntl.h>
#include <linux/ioprio.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include <fmt/format.h>

#include "opencnc/broaching/journal.hpp"

namespace opencnc::recovery {

namespace detail {

namespace {

std::string reason(const char* what, const std::string& path) {
  return std::string(what) + " " + path + ": " + std::strerror(errno);
}

// Rewrites the first `bytes` of the file as they read (a hole or the part past the end reads as
// zeros), so every block is allocated and written and a record already there stays whole even if
// this write is torn; then fsync (the new size and the block map are metadata).
bool write_out(int fd, std::size_t bytes) {
  std::vector<std::byte> content(bytes);
  std::size_t got = 0;
  while (got < bytes) {
    const ssize_t n = ::pread(fd, content.data() + got, bytes - got, static_cast<off_t>(got));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    if (n == 0) break;  // the end of the file: the rest stays zeros
    got += static_cast<std::size_t>(n);
  }
  std::size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::pwrite(fd, content.data() + done, bytes - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return ::fsync(fd) == 0;
}

}  // namespace

std::string refuse_slot_file(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    return errno == ENOENT ? std::string{} : reason("cannot inspect the journal slot", path);
  }
  if (!S_ISREG(st.st_mode)) {
    return fmt::format("{} is not a regular file, so not a journal slot: move it away (nothing was changed)",
                       path);
  }
  if (static_cast<std::uintmax_t>(st.st_size) > Journal::kMaxSlotBytes) {
    return fmt::format(
        "{} is {} bytes, more than a journal slot ever holds ({} bytes): not a journal slot, move it away "
        "(nothing was changed)",
        path, st.st_size, Journal::kMaxSlotBytes);
  }
  return {};
}

int open_slot(const std::string& path, std::string* error) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) {
    if (error) *error = reason("cannot open", path);
    return -1;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    if (error) *error = reason("cannot inspect", path);
    ::close(fd);
    return -1;
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  const std::size_t blocks =
      std::max<std::size_t>(1, (size + Journal::kBlockBytes - 1) / Journal::kBlockBytes);
  const std::size_t bytes = blocks * Journal::kBlockBytes;
  const bool whole = size == bytes && static_cast<std::size_t>(st.st_blocks) * 512 >= bytes;
  if (!whole && !write_out(fd, bytes)) {
    if (error) *error = reason("cannot size", path);
    ::close(fd);
    return -1;
  }
  return fd;
}

int open_direct(const std::string& path) {
  return ::open(path.c_str(), O_RDWR | O_DIRECT | O_DSYNC | O_CLOEXEC | O_NOFOLLOW);
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

}  // namespace detail

bool raise_io_priority() noexcept {
  // The thread's own I/O priority (IOPRIO_WHO_PROCESS with 0: the calling thread); level 0 is the
  // highest of the class. The kernel asks CAP_SYS_ADMIN or CAP_SYS_NICE for the RT class.
  return ::syscall(SYS_ioprio_set, IOPRIO_WHO_PROCESS, 0, IOPRIO_PRIO_VALUE(IOPRIO_CLASS_RT, 0)) == 0;
}

void reset_io_priority() noexcept {
  ::syscall(SYS_ioprio_set, IOPRIO_WHO_PROCESS, 0, IOPRIO_PRIO_VALUE(IOPRIO_CLASS_NONE, 0));
}

std::string_view to_string(JournalSync s) noexcept {
  switch (s) {
    case JournalSync::Direct:
      return "direct";
    case JournalSync::Fdatasync:
      return "fdatasync";
    case JournalSync::Dsync:
      return "dsync";
  }
  return "?";
}

}  // namespace opencnc::recovery
