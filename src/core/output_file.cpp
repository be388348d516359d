// SPDX-License-Identifier: GPL-3.0-or-later
// POSIX implementation of the output-file rules: path checks, symlinks, devices, temporary files
// renamed into place, and records cut back to a whole one when the disk refuses data.
#include "opencnc/core/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>

namespace opencnc {

namespace {

constexpr std::size_t kBufferBytes = 1 << 16;
constexpr int kMaxLinks = 40;  // as the kernel's own limit (ELOOP)

// --- temporaries removed by a fatal signal ---------------------------------------------------
// A fixed table (no allocation, no lock) that a signal handler can walk: 0 free, 1 being
// written, 2 holds a path.
struct TempSlot {
  std::atomic<int> state{0};
  std::array<char, 4096> path{};
};
std::array<TempSlot, 8> g_temps;

int register_temp(const std::string& path) {
  if (path.size() >= g_temps[0].path.size()) return -1;
  for (std::size_t i = 0; i < g_temps.size(); ++i) {
    int expected = 0;
    if (!g_temps[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_temps[i].path.data(), path.c_str(), path.size() + 1);
    g_temps[i].state.store(2, std::memory_order_release);
    return static_cast<int>(i);
  }
  return -1;
}

void release_temp(int slot) {
  if (slot >= 0) g_temps[static_cast<std::size_t>(slot)].state.store(0, std::memory_order_release);
}

// --- paths -------------------------------------------------------------------------------------

std::string folder_of(const std::string& path) {
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string base_of(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string errno_text(int err) {
  const char* name = ::strerrorname_np(err);
  return fmt::format("{} ({})", std::strerror(err), name != nullptr ? name : "?");
}

/// Where writing `path` lands: `st` (and `exists`) from stat(), which follows every link the
/// kernel does (also /proc's links to pipes); `out`, the file a rename must replace: the path with
/// every symlink of its chain followed (the last one may dangle). Returns an errno, or 0.
int resolve(const std::string& path, std::string& out, struct stat& st, bool& exists) {
  exists = ::stat(path.c_str(), &st) == 0;
  if (!exists && errno != ENOENT) return errno;
  out = path;
  struct stat link_st {};
  for (int i = 0; i < kMaxLinks; ++i) {
    if (::lstat(out.c_str(), &link_st) != 0 || !S_ISLNK(link_st.st_mode)) return 0;
    std::string link(4096, '\0');
    const ssize_t n = ::readlink(out.c_str(), link.data(), link.size());
    if (n < 0) return errno;
    link.resize(static_cast<std::size_t>(n));
    out = link.front() == '/' ? link : folder_of(out) + "/" + link;
  }
  return ELOOP;
}

bool same_file(const struct stat& a, int fd) {
  struct stat b {};
  return ::fstat(fd, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

/// What a path names, for comparing paths.
struct Identity {
  bool exists = false, stream = false;
  dev_t dev = 0;
  ino_t ino = 0;
  std::string absolute;  ///< for a path that does not exist yet
};

Identity identify(const std::string& path) {
  Identity id;
  if (path == "-") {
    id.stream = true;
    return id;
  }
  struct stat st {};
  std::string resolved;
  bool exists = false;
  if (resolve(path, resolved, st, exists) == 0 && exists) {
    id.exists = true;
    id.dev = st.st_dev;
    id.ino = st.st_ino;
    id.stream = S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode);
    return id;
  }
  std::error_code ec;
  id.absolute = std::filesystem::weakly_canonical(std::filesystem::absolute(resolved, ec), ec).string();
  return id;
}

bool same(const Identity& a, const Identity& b) {
  if (a.stream || b.stream) return false;
  if (a.exists != b.exists) return false;
  return a.exists ? a.dev == b.dev && a.ino == b.ino : a.absolute == b.absolute;
}

bool write_all(int fd, const char* p, std::size_t size, std::size_t& done, int& err) {
  done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, p + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      err = errno;
      return false;
    }
    if (n == 0) {  // a device that takes nothing more
      err = ENOSPC;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

/// Creates the temporary file next to `target` (its permission bits copied from `old` if
/// given). Returns the fd, or -1 with errno set.
int create_temp(const std::string& target, const struct stat* old, std::string& temp) {
  static std::atomic<unsigned> counter{0};
  const std::string stem = folder_of(target) + "/." + base_of(target) + ".opencnc-";
  for (int attempt = 0; attempt < 100; ++attempt) {
    temp = fmt::format("{}{}-{}", stem, ::getpid(), counter++);
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      if (old != nullptr) (void)::fchmod(fd, old->st_mode & 07777);
      return fd;
    }
    if (errno != EEXIST) return -1;
  }
  errno = EEXIST;
  return -1;
}

}  // namespace

std::string output_conflict(std::span<const NamedPath> inputs, std::span<const NamedPath> outputs) {
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const NamedPath& out = outputs[k];
    if (out.path.empty()) continue;
    const Identity o = identify(out.path);
    for (const NamedPath& in : inputs) {
      if (in.path.empty() || !same(o, identify(in.path))) continue;
      return fmt::format("{} {} is {} ({}): opencnc never writes over an input; choose another file",
                         out.role, out.path, in.role, in.path);
    }
    for (std::size_t j = 0; j < k; ++j) {
      if (outputs[j].path.empty() || !same(o, identify(outputs[j].path))) continue;
      return fmt::format("{} {} and {} {} are the same file: give each output its own file", outputs[j].role,
                         outputs[j].path, out.role, out.path);
    }
  }
  return {};
}

std::unique_ptr<OutputFile> OutputFile::open(const NamedPath& what, std::string* error) {
  auto refuse = [&](const std::string& why) -> std::unique_ptr<OutputFile> {
    if (error != nullptr) *error = fmt::format("{} {}: {}", what.role, what.path, why);
    return nullptr;
  };
  std::unique_ptr<OutputFile> f(new OutputFile);
  f->what_ = what;
  if (what.path.empty()) return refuse("an empty path");
  if (what.path == "-") {
    f->fd_ = ::fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 0);
    if (f->fd_ < 0) return refuse("standard output: " + errno_text(errno));
    return f;
  }
  struct stat st {};
  bool exists = false;
  if (const int err = resolve(what.path, f->target_, st, exists); err != 0) return refuse(errno_text(err));
  if (exists) {
    // Whatever standard output or error already is (a redirection to a file included) is
    // written in place: `--report /dev/stdout > out.txt` appends to out.txt as the shell set up.
    for (const int std_fd : {STDOUT_FILENO, STDERR_FILENO}) {
      if (!same_file(st, std_fd)) continue;
      f->fd_ = ::fcntl(std_fd, F_DUPFD_CLOEXEC, 0);
      f->target_.clear();
      if (f->fd_ < 0) return refuse(errno_text(errno));
      return f;
    }
    if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) {
      f->fd_ = ::open(f->target_.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
      f->target_.clear();
      if (f->fd_ < 0) return refuse(errno_text(errno));
      return f;
    }
    if (S_ISDIR(st.st_mode)) return refuse("is a folder, not a file");
    if (!S_ISREG(st.st_mode))
      return refuse("is not a file, a character device or a pipe: opencnc does not write there");
    if ((st.st_mode & 0222) == 0 || ::access(f->target_.c_str(), W_OK) != 0) {
      return refuse(
          fmt::format("is read-only (mode {:04o}): opencnc replaces no read-only file", st.st_mode & 07777));
    }
  }
  f->fd_ = create_temp(f->target_, exists ? &st : nullptr, f->temp_);
  if (f->fd_ < 0) {
    const int err = errno;
    const std::string folder = folder_of(f->target_);
    if (err == ENOENT) return refuse(fmt::format("the folder {} does not exist", folder));
    if (err == ENOTDIR) return refuse(fmt::format("{} is not a folder", folder));
    return refuse(fmt::format("cannot create a file in {}: {}", folder, errno_text(err)));
  }
  f->slot_ = register_temp(f->temp_);
  return f;
}

OutputFile::~OutputFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temp_.empty()) discard_temp();
  release_temp(slot_);
}

bool OutputFile::write(std::string_view record) {
  if (err_ != 0 || committed_) return false;
  if (!buffer_.empty() && buffer_.size() + record.size() > kBufferBytes && !flush()) return false;
  buffer_.append(record);
  record_ends_.push_back(buffer_.size());
  if (buffer_.size() >= kBufferBytes) return flush();
  return true;
}

bool OutputFile::flush() {
  if (err_ != 0) return false;
  if (buffer_.empty()) return true;
  std::size_t done = 0;
  int err = 0;
  if (!write_all(fd_, buffer_.data(), buffer_.size(), done, err)) {
    fail(err, done);
    return false;
  }
  flushed_bytes_ += buffer_.size();
  records_ += record_ends_.size();
  buffer_.clear();
  record_ends_.clear();
  return true;
}

void OutputFile::fail(int err, std::size_t written) {
  // Keep the records the failed write got out in full; cut the file back to the last one.
  std::size_t kept = 0;
  for (const std::size_t end : record_ends_) {
    if (end > written) break;
    kept = end;
    ++records_;
  }
  flushed_bytes_ += kept;
  if (!temp_.empty()) (void)::ftruncate(fd_, static_cast<off_t>(flushed_bytes_));
  err_ = err;
  buffer_.clear();
  record_ends_.clear();
}

bool OutputFile::commit(std::string* error) {
  if (committed_) return err_ == 0;
  flush();
  committed_ = true;
  const int err = temp_.empty() ? finish_stream() : finish_file();
  if (err == 0) return true;
  if (error != nullptr) *error = fmt::format("{} {}: {}", what_.role, what_.path, errno_text(err));
  return false;
}

int OutputFile::finish_stream() {
  const int rc = ::close(fd_);
  const int close_err = rc == 0 ? 0 : errno;
  fd_ = -1;
  return err_ != 0 ? err_ : close_err;
}

int OutputFile::finish_file() {
  int sync_err = ::fdatasync(fd_) == 0 ? 0 : errno;
  if (::close(fd_) != 0 && sync_err == 0) sync_err = errno;
  fd_ = -1;
  // Nothing whole to show, or not on disk: the old file stays as it was.
  if (sync_err != 0 || (err_ != 0 && records_ == 0)) {
    discard_temp();
    return sync_err != 0 ? sync_err : err_;
  }
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    const int err = errno;
    discard_temp();
    return err;
  }
  release_temp(slot_);
  slot_ = -1;
  // The rename is durable only once the folder entry is on disk too.
  const int dfd = ::open(folder_of(target_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
  return err_;
}

void OutputFile::discard_temp() {
  ::unlink(temp_.c_str());
  release_temp(slot_);
  slot_ = -1;
}

void remove_output_temporaries() noexcept {
  for (TempSlot& s : g_temps) {
    if (s.state.load(std::memory_order_acquire) == 2) ::unlink(s.path.data());
  }
}

}  // namespace opencnc
