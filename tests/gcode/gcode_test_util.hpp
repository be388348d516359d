// SPDX-License-Identifier: GPL-3.0-or-later
// Test helpers: run a program text through the interpreter and read back rs274-format text.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/canon/rs274_printer.hpp"
#include "opencnc/gcode/interpreter.hpp"

namespace opencnc::gcode::test {

/// Canonical output (rs274 text) of a run, with the call texts split out.
struct Result {
  RunStatus status = RunStatus::Ok;
  std::string text;                 ///< every printed line
  std::vector<std::string> calls;   ///< the calls after the start-up lines, without "  12 N..... "
  std::vector<std::string> labels;  ///< the N label column of those calls
  Diagnostics diagnostics;
  InterpState state;
  /// Code of the first error ("" if none).
  std::string code() const {
    for (const auto& d : diagnostics.items()) {
      if (d.severity == Severity::Error) return d.code;
    }
    return "";
  }
};

inline Result collect(Interpreter& interp, RunStatus status, const std::string& text) {
  Result r;
  r.status = status;
  r.text = text;
  std::size_t line_no = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    const std::string line = text.substr(pos, nl - pos);
    pos = nl + 1;
    if (++line_no <= 5 || line.size() < 13) continue;  // start-up calls (units, offsets, ...)
    r.labels.push_back(line.substr(6, 6));
    r.calls.push_back(line.substr(13));
  }
  r.diagnostics = interp.diagnostics();
  r.state = interp.state();
  return r;
}

/// Reads everything written to a memory stream.
class MemoryStream {
 public:
  MemoryStream() : file_(open_memstream(&data_, &size_)) {}
  ~MemoryStream() {
    if (file_ != nullptr) std::fclose(file_);
    std::free(data_);
  }
  std::FILE* file() { return file_; }
  std::string text() {
    std::fflush(file_);
    return std::string(data_, size_);
  }

 private:
  char* data_ = nullptr;
  std::size_t size_ = 0;
  std::FILE* file_;
};

/// Runs `program` to its end and returns its canonical text.
inline Result run(std::string_view program, Options options = {}) {
  Interpreter interp(options);
  interp.open_text("test.ngc", std::string(program));
  MemoryStream out;
  RunStatus status;
  {
    canon::Rs274Printer printer(out.file(), out.file());
    status = interp.run(printer);
  }
  return collect(interp, status, out.text());
}

/// The first `n` calls (or all).
inline std::vector<std::string> head(const Result& r, std::size_t n) {
  return {r.calls.begin(), r.calls.begin() + static_cast<std::ptrdiff_t>(std::min(n, r.calls.size()))};
}

/// A scratch directory for subprogram files under /tmp, removed with the object.
class TempDir {
 public:
  TempDir() {
    char name[] = "/tmp/opencnc_gcode_test_XXXXXX";
    path_ = ::mkdtemp(name);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// Writes `text` to `file` in the directory.
  void write(const std::string& file, const std::string& text) const { std::ofstream(path_ / file) << text; }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace opencnc::gcode::test
