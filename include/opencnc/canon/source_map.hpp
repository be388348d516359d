// SPDX-License-Identifier: GPL-3.0-or-later
// Files and interned call stacks that canonical calls and segments refer to.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace opencnc::canon {

/// A place in the source: file index, 1-based line and column.
struct SourceRef {
  std::uint32_t file = 0;
  std::uint32_t line = 0;
  std::uint32_t col = 0;
};

/// The files of a run and the call stacks met while running it. A call stack is interned as
/// a chain of contexts: context 0 is the main program; every other context names its parent,
/// the call site (file, line) and the file of the called body. Loops that call the same
/// subprogram from the same place reuse one context, so a million segments need only a few.
/// Non-real-time; owned by the interpreter and shared with the canonical program.
class SourceMap {
 public:
  struct Context {
    std::uint32_t parent = 0;
    SourceRef call_site;        ///< where the call was made (in the parent's file)
    std::uint32_t body_file = 0;
    std::string name;           ///< subprogram name as written (`o<name>`, `O1000`, ...)
  };

  SourceMap();

  /// Registers a file path (once) and returns its index.
  std::uint32_t add_file(std::string_view path);
  const std::string& file(std::uint32_t index) const { return files_.at(index); }
  std::size_t file_count() const noexcept { return files_.size(); }

  /// Interns the context "called `name` at `call_site` from `parent`, body in `body_file`".
  std::uint32_t context(std::uint32_t parent, SourceRef call_site, std::uint32_t body_file,
                        std::string_view name);
  const Context& context_info(std::uint32_t id) const { return contexts_.at(id); }
  std::size_t context_count() const noexcept { return contexts_.size(); }

  /// The call stack of `context`, outermost first (empty for the main program).
  std::vector<std::uint32_t> stack(std::uint32_t context) const;
  /// "main.ngc:12 > sub.ngc:4" style description of a block position.
  std::string describe(std::uint32_t context, std::uint32_t file, std::uint32_t line) const;

 private:
  struct Key {
    std::uint32_t parent, file, line, col, body;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const noexcept;
  };
  std::vector<std::string> files_;
  std::unordered_map<std::string, std::uint32_t> file_index_;
  std::vector<Context> contexts_;
  std::unordered_map<Key, std::uint32_t, KeyHash> context_index_;
};

}  // namespace opencnc::canon
