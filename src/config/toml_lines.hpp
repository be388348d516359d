// SPDX-License-Identifier: GPL-3.0-or-later
// A TOML text as lines: table headers, comments and table extents, for edits that keep the rest.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::config::detail {

struct TomlLine {
  std::string_view text;           ///< without its line ending
  std::size_t begin = 0, end = 0;  ///< byte range in the whole text, line ending included
};

/// The lines of `text` (views into it). Any thread.
std::vector<TomlLine> split_lines(std::string_view text);

/// `s` without leading and trailing blanks and tabs. Any thread.
std::string_view trim(std::string_view s);

/// The key of a table header line (`[axis.X.compensation]  # …` → "axis.x.compensation", lower
/// case, blanks and quotes dropped), or "" for any other line. Array-of-tables headers and array
/// values (`[1.0, 2.0]`) are not table headers. Any thread.
std::string header_key(std::string_view line);

/// True for a line that starts an array of tables (`[[edm.condition]]`). Any thread.
bool is_array_header(std::string_view line);

/// The key of an array-of-tables header line (`[[edm.condition]]  # …` → "edm.condition", as
/// header_key() writes it), or "" for any other line. Any thread.
std::string array_header_key(std::string_view line);

/// True for a blank line or a comment. Any thread.
bool is_blank_or_comment(std::string_view line);

/// End (exclusive line index) of the table that starts at line `header`: the next header, less
/// the comments and blank lines that lead into it. Any thread.
std::size_t table_end(const std::vector<TomlLine>& lines, std::size_t header);

}  // namespace opencnc::config::detail
