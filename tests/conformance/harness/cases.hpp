// SPDX-License-Identifier: GPL-3.0-or-later
// The data files of the conformance suite: cases.tsv, error-codes.tsv, items.tsv.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::conformance {

/// What a case expects of the implementation.
enum class Expect { Accept, Reject, Run, Unsupported, Excluded };

/// One row of cases.tsv (written by regen-golden.sh). Paths are as written there: `program` is
/// relative to the set's root, `tool_table` starts with a root token (@conf, @corpus) or is "-".
struct Case {
  std::string name;        ///< unique, [A-Za-z0-9_]; the test name
  std::string set;         ///< own | ncfiles | corpus
  std::string program;
  std::string dialect;     ///< linuxcnc | fanuc
  std::string tool_table;
  std::string subpath;     ///< SUBROUTINE_PATH relative to the program folder, ':'-separated, or "-"
  std::string args;        ///< extra opencnc arguments, blank-separated, or "-"
  Expect expect = Expect::Accept;
  std::string code;        ///< expected problem code when given explicitly, else "-"
  std::string construct;   ///< for Unsupported: text the error message must contain
  std::string golden;      ///< relative to golden/, or "-"
  std::string note;
};

/// Reads cases.tsv. Throws std::runtime_error naming the line on a malformed row.
std::vector<Case> load_cases(const std::filesystem::path& path);

/// Splits a tab-separated line into fields.
std::vector<std::string> split_tabs(std::string_view line);

/// error-codes.tsv: rs274 message patterns (POSIX extended regular expressions) to problem codes.
class ErrorCodeTable {
 public:
  struct Row {
    std::string pattern;
    std::string code;
    std::string description;
  };

  /// Reads the table; throws std::runtime_error on a bad row or pattern.
  static ErrorCodeTable load(const std::filesystem::path& path);
  ~ErrorCodeTable();
  ErrorCodeTable(ErrorCodeTable&&) noexcept;
  ErrorCodeTable& operator=(ErrorCodeTable&&) noexcept;

  /// The code of the first row whose pattern matches the whole `message`, or "" if none does.
  std::string code_for(std::string_view message) const;
  const std::vector<Row>& rows() const noexcept { return rows_; }

 private:
  ErrorCodeTable();
  struct Compiled;
  std::vector<Row> rows_;
  std::unique_ptr<Compiled> compiled_;
};

/// Whether `code` has the form of a problem code: lower case, dotted, e.g. "gcode.feed-zero".
bool is_problem_code(std::string_view code);

/// Whether `code` occurs in `line` as a whole token, not as part of a longer code
/// ("[gcode.feed-zero]" mentions gcode.feed-zero; "gcode.feed-zero-x" does not).
bool mentions_code(std::string_view line, std::string_view code);

/// One row of items.tsv.
struct Item {
  std::string id;
  bool needs_error_case = false;
  std::string description;
};

/// Reads items.tsv.
std::vector<Item> load_items(const std::filesystem::path& path);

/// The items a program names on its `items:` line (within its first lines), in order.
std::vector<std::string> program_items(const std::filesystem::path& program);

}  // namespace opencnc::conformance
