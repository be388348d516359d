// SPDX-License-Identifier: GPL-3.0-or-later
// POSIX implementation of crash-safe file replacement and whole-file reads.
#include "opencnc/core/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

#include <fmt/format.h>

namespace opencnc {

namespace {

bool fail(std::string* error, const std::string& what, int err) {
  if (error != nullptr) *error = fmt::format("{}: {}", what, std::strerror(err));
  return false;
}

std::string folder_of(const std::string& path) {
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

bool write_all(int fd, std::string_view content) {
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

bool write_file_atomically(const std::string& path, std::string_view content, std::string* error) {
  const std::string tmp = fmt::format("{}.tmp.{}", path, ::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(error, fmt::format("cannot create {}", tmp), errno);
  if (!write_all(fd, content) || ::fdatasync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    return fail(error, fmt::format("cannot write {}", tmp), err);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    return fail(error, fmt::format("cannot close {}", tmp), err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    return fail(error, fmt::format("cannot replace {}", path), err);
  }
  // The rename is durable only once the folder entry is on disk too.
  const int dfd = ::open(folder_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    const int rc = ::fsync(dfd);
    const int err = errno;
    ::close(dfd);
    if (rc != 0 && err != EINVAL) return fail(error, fmt::format("cannot sync the folder of {}", path), err);
  }
  return true;
}

namespace {

/// What kind of file `mode` is, for a refusal.
const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "it is a folder, not a file";
  if (S_ISFIFO(mode)) return "it is a FIFO, not a file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "it is a device, not a file";
  if (S_ISSOCK(mode)) return "it is a socket, not a file";
  return "it is not a regular file";
}

std::string too_large(std::size_t max_bytes) {
  return max_bytes % (1u << 20) == 0 ? fmt::format("it is larger than {} MiB", max_bytes >> 20)
                                     : fmt::format("it is larger than {} bytes", max_bytes);
}

/// Opens `path` for reading without blocking on a FIFO, and checks it is a regular file of at most
/// `max_bytes`: the descriptor, or −1 with the reason in `why`.
int open_input(const std::string& path, std::size_t max_bytes, std::string& why) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) {
    why = std::strerror(errno);
    return -1;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    why = std::strerror(errno);
  } else if (!S_ISREG(st.st_mode)) {
    why = file_kind(st.st_mode);
  } else if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
    why = too_large(max_bytes);
  } else {
    return fd;
  }
  ::close(fd);
  return -1;
}

}  // namespace

std::string unreadable_input(const std::string& path, std::size_t max_bytes) {
  std::string why;
  const int fd = open_input(path, max_bytes, why);
  if (fd >= 0) ::close(fd);
  return why;
}

bool read_file(const std::string& path, std::string& out, std::string* error, std::size_t max_bytes) {
  std::string why;
  const int fd = open_input(path, max_bytes, why);
  if (fd < 0) {
    if (error != nullptr) *error = why;
    return false;
  }
  out.clear();
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      if (error != nullptr) *error = std::strerror(err);
      return false;
    }
    if (n == 0) break;
    if (out.size() + static_cast<std::size_t>(n) > max_bytes) {  // it grew while we read
      ::close(fd);
      if (error != nullptr) *error = too_large(max_bytes);
      return false;
    }
    out.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return true;
}

}  // namespace opencnc
