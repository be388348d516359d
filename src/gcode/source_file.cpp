// SPDX-License-Identifier: GPL-3.0-or-later
// Windowed line reading with pread(); consumed pages of the page cache are released.
#include "source_file.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace opencnc::gcode {

namespace {
constexpr std::size_t kWindow = 1 << 18;   // 256 KiB: far longer than any G-code line
constexpr std::uint64_t kReleaseEvery = 16u << 20;
}  // namespace

std::unique_ptr<SourceFile> SourceFile::open(const std::string& path, std::string* why) {
  // O_NONBLOCK: a FIFO must not hang the open until a writer comes (it is refused below).
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    if (why != nullptr) *why = std::strerror(errno);
    return nullptr;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    if (why != nullptr) {
      *why = S_ISDIR(st.st_mode)
                 ? "it is a folder, not a file"
                 : "it is not a regular file (a program is read more than once: loops, subprograms)";
    }
    ::close(fd);
    return nullptr;
  }
  std::unique_ptr<SourceFile> f(new SourceFile);
  f->fd_ = fd;
  f->window_.resize(kWindow);
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_SEQUENTIAL);
  return f;
}

std::unique_ptr<SourceFile> SourceFile::from_text(std::string text) {
  std::unique_ptr<SourceFile> f(new SourceFile);
  f->text_ = std::move(text);
  f->filled_ = f->text_.size();
  f->eof_ = true;
  return f;
}

SourceFile::~SourceFile() {
  if (fd_ >= 0) ::close(fd_);
}

bool SourceFile::refill() {
  if (fd_ < 0 || eof_) return false;
  // Keep the unread tail at the front of the window and read more behind it.
  const std::size_t tail = filled_ - pos_;
  if (tail > 0 && pos_ > 0) std::memmove(window_.data(), window_.data() + pos_, tail);
  window_start_ += pos_;
  pos_ = 0;
  filled_ = tail;
  while (filled_ < window_.size()) {
    const ssize_t n = ::pread(fd_, window_.data() + filled_, window_.size() - filled_,
                              static_cast<off_t>(window_start_ + filled_));
    if (n <= 0) {
      eof_ = true;
      break;
    }
    filled_ += static_cast<std::size_t>(n);
  }
  // The program is read once front to back in the common case: give the page cache back.
  if (window_start_ - dropped_ >= kReleaseEvery) {
    ::posix_fadvise(fd_, static_cast<off_t>(dropped_), static_cast<off_t>(window_start_ - dropped_),
                    POSIX_FADV_DONTNEED);
    dropped_ = window_start_;
  }
  return true;
}

bool SourceFile::next(RawLine& line) {
  const char* base = fd_ >= 0 ? window_.data() : text_.data();
  for (;;) {
    const char* start = base + pos_;
    const std::size_t avail = filled_ - pos_;
    if (const void* nl = std::memchr(start, '\n', avail)) {
      const auto len = static_cast<std::size_t>(static_cast<const char*>(nl) - start);
      line = {std::string_view(start, len), window_start_ + pos_, true};
      pos_ += len + 1;
      skip_byte_order_mark(line);
      return true;
    }
    if (eof_ || (fd_ >= 0 && avail == window_.size())) {
      if (avail == 0) return false;
      // Last line without '\n', or a line longer than the window (returned cut).
      line = {std::string_view(start, avail), window_start_ + pos_, false};
      pos_ += avail;
      skip_byte_order_mark(line);
      return true;
    }
    refill();
  }
}

// Editors on Windows may start a UTF-8 file with a byte-order mark; it is no part of the first
// line (columns count from the character after it).
void SourceFile::skip_byte_order_mark(RawLine& line) noexcept {
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  if (line.offset == 0 && line.text.starts_with(kBom)) line.text.remove_prefix(kBom.size());
}

void SourceFile::seek(std::uint64_t offset) {
  if (fd_ < 0) {
    pos_ = static_cast<std::size_t>(offset < text_.size() ? offset : text_.size());
    return;
  }
  if (offset >= window_start_ && offset <= window_start_ + filled_) {
    pos_ = static_cast<std::size_t>(offset - window_start_);
    return;
  }
  window_start_ = offset;
  pos_ = 0;
  filled_ = 0;
  eof_ = false;
  if (dropped_ > offset) dropped_ = offset;
}

}  // namespace opencnc::gcode
