// SPDX-License-Identifier: GPL-3.0-or-later
// SourceFile — streams the lines of a program from disk (or memory) through a fixed
// window, so a program of any size needs only the window's memory; lines can be re-read
// from a remembered offset (loops, subprogram returns).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::gcode {

/// One line as read: its bytes (without '\n') and where it starts.
struct RawLine {
  std::string_view text;      ///< valid until the next read or seek
  std::uint64_t offset = 0;   ///< byte offset of the line start
  bool newline = false;       ///< the line ended with '\n' (counts toward the length limit)
};

/// Sequential line reader over a file descriptor or an in-memory text. Not thread-safe.
class SourceFile {
 public:
  /// Opens `path`; returns nullptr if it cannot be read, with the reason in `*why` (if given):
  /// `strerror`, or that it is a folder or not a regular file (a pipe or a device cannot be
  /// read again from a remembered offset).
  static std::unique_ptr<SourceFile> open(const std::string& path, std::string* why = nullptr);
  /// A program held in memory (MDI, tests).
  static std::unique_ptr<SourceFile> from_text(std::string text);
  ~SourceFile();
  SourceFile(const SourceFile&) = delete;
  SourceFile& operator=(const SourceFile&) = delete;

  /// Reads the next line; false at end of file. Lines longer than the window are returned
  /// truncated to the window (they are rejected as too long anyway).
  bool next(RawLine& line);
  /// Continues reading at byte `offset` (a line start returned earlier).
  void seek(std::uint64_t offset);
  /// Offset of the next line to be read.
  std::uint64_t tell() const noexcept { return window_start_ + pos_; }

 private:
  SourceFile() = default;
  bool refill();
  static void skip_byte_order_mark(RawLine& line) noexcept;

  int fd_ = -1;
  std::string text_;                 ///< in-memory program (fd_ < 0)
  std::vector<char> window_;
  std::uint64_t window_start_ = 0;   ///< file offset of window_[0]
  std::size_t pos_ = 0;              ///< read position in the window
  std::size_t filled_ = 0;           ///< bytes valid in the window
  bool eof_ = false;                 ///< the window reaches the end of the file
  std::uint64_t dropped_ = 0;        ///< bytes of page cache released so far
};

}  // namespace opencnc::gcode
