// SPDX-License-Identifier: GPL-3.0-or-later
// Line normalisation: LinuxCNC reads a block after removing blanks and lowering case
// everywhere outside comments; comments are checked for nesting and closure.
#pragma once

#include <cstdint>
#include <string_view>

namespace opencnc::gcode {

/// LinuxCNC rejects lines of 255 characters or more ("command too long").
inline constexpr std::size_t kMaxLineLength = 254;

/// Raw line without its line ending and trailing white space.
std::string_view trim_raw_line(std::string_view raw) noexcept;

/// Writes the normalised form of `raw` into `out` (at least raw.size() bytes) and returns its
/// length. Outside comments: spaces, tabs and CRs are dropped, A-Z lowered; after ';' the rest
/// is copied as is. Throws GcodeError (unclosed comment; a nested one unless
/// `nested_comments`, as the Fanuc dialect allows; a NUL byte anywhere, which LinuxCNC's
/// C-string reading would take as the end of the line).
std::size_t normalize_line(std::string_view raw, char* out, bool nested_comments = false);

/// Column (1-based) in `raw` of the normalised character at `index`, for error messages.
std::uint32_t raw_column(std::string_view raw, int index, bool nested_comments = false) noexcept;

/// The digits of a leading N word as the stand-alone rs274 shows them: after leading blanks
/// and '/', an 'N' and the digits that follow it directly. Returns false if no N.
bool leading_n_digits(std::string_view raw, std::string_view& digits) noexcept;

}  // namespace opencnc::gcode
