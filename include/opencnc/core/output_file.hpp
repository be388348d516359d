// SPDX-License-Identifier: GPL-3.0-or-later
// Files written for the user (reports, traces, charts, CSV): checked before a run, never over an
// input, a device, a read-only file or another output; whole records only when the disk fills.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc {

/// A path given on the command line and what it is for ("the program", "--report"), so that a
/// message names what the user typed.
struct NamedPath {
  std::string role;
  std::string path;
};

/// The first output that names an input or another output, in words ("" if none). Files that
/// exist are compared by device and inode after following symlinks (so a hard link or a
/// symlink to the program counts as the program); paths that do not exist yet by their absolute
/// form. Character devices and pipes may be shared (`--trace /dev/null --report /dev/null`).
/// Empty paths are skipped. Non-real-time.
std::string output_conflict(std::span<const NamedPath> inputs, std::span<const NamedPath> outputs);

/// One output file. `open` checks the path before anything runs; `write` appends whole records
/// (a CSV row, or a whole document); `commit` makes them the file. The rules:
/// - `-`, a character device or a FIFO (`/dev/stdout`, `/dev/null`, a terminal, a pipe), and
///   whatever standard output or standard error already is, are written in place;
/// - a regular file (existing or new) is written to a temporary file in its own folder, which
///   `commit` syncs and renames over it: a crash leaves the old file or the new one. An existing
///   file keeps its permission bits;
/// - a symlink is followed (as far as 40 links): its target is the file replaced, the link stays;
/// - a read-only file, a folder, a block device, a socket, a missing folder or one opencnc may
///   not write in is refused by `open`, naming the path the user gave;
/// - when the disk refuses data (ENOSPC, EFBIG, EIO…), writing stops, the file is cut back to
///   its last whole record and `commit` says why (`strerror` and the errno name). A file that got
///   no whole record leaves the old one untouched.
/// `core::write_file_atomically` stays for the files opencnc owns. Non-real-time (blocking I/O);
/// one thread per object.
class OutputFile {
 public:
  /// Checks `what.path` and prepares it (creates the temporary file, or opens the device);
  /// nullptr with `*error` set when it cannot be written. Non-real-time.
  static std::unique_ptr<OutputFile> open(const NamedPath& what, std::string* error);
  /// Removes the temporary file if `commit` was not called (the old file stays).
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Appends one whole record. Buffered; false once writing has failed (later records are
  /// dropped, `commit` reports why). Non-real-time.
  bool write(std::string_view record);
  /// Flushes; for a file, syncs it and renames it over the target (also after a failure, if it
  /// holds at least one whole record). False with `*error` set if anything failed.
  bool commit(std::string* error);

  /// Whole records in the output so far (after a failure: those the file keeps).
  std::uint64_t records() const noexcept { return records_; }
  bool failed() const noexcept { return err_ != 0; }
  /// The path as the user gave it.
  const std::string& path() const noexcept { return what_.path; }

 private:
  OutputFile() = default;
  bool flush();
  /// Stops writing after `written` bytes of the buffer got out; cuts back to a whole record.
  void fail(int err, std::size_t written);
  int finish_stream();  ///< errno of the first failure, or 0
  int finish_file();    ///< errno of the first failure, or 0
  void discard_temp();

  NamedPath what_;
  std::string target_;  ///< the file replaced at commit (symlinks resolved); empty for a stream
  std::string temp_;    ///< the temporary file; empty for a stream
  int fd_ = -1;
  int slot_ = -1;  ///< index in the table of temporaries removed on a fatal signal
  int err_ = 0;    ///< errno of the first failure
  std::string buffer_;
  std::uint64_t flushed_bytes_ = 0;  ///< bytes of whole records on disk
  std::uint64_t records_ = 0;
  std::vector<std::size_t> record_ends_;  ///< where each buffered record ends in buffer_
  bool committed_ = false;
};

/// Removes the temporary files of every open OutputFile. Async-signal-safe: for a handler
/// that ends the process at once (a second Ctrl-C).
void remove_output_temporaries() noexcept;

}  // namespace opencnc
