// SPDX-License-Identifier: GPL-3.0-or-later
// Setting one key of a TOML text to a new value, line by line: comments, blank lines, the order of
// keys and every other value stay as the user wrote them.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace opencnc::config {

/// `text` with the key `dotted_key` ("axis.x.max_velocity": the table `[axis.x]`, whose header
/// is compared in lower case, and the key `max_velocity` in it) set to `value_toml` (a TOML value
/// on one line: a number, a boolean, a string, an array). The key's line keeps its indentation
/// and trailing comment; a key the table lacks is added after the table's last key. Refused
/// (nullopt, `error` says why) when the table has no header line of its own (dotted or inline
/// tables), the key is written twice or its value spans lines (multi-line strings or arrays),
/// the value is not TOML, or the result does not read back as `text` with only that value
/// changed. Non-real-time; any thread.
std::optional<std::string> with_toml_value(std::string_view text, std::string_view dotted_key,
                                           std::string_view value_toml, std::string& error);

/// `text` without the key `dotted_key`'s line (as with_toml_value() finds it; the lines around it
/// stay). Refused (nullopt, `error` says why) as with_toml_value() refuses, and when the table has
/// no such key. Non-real-time; any thread.
std::optional<std::string> without_toml_key(std::string_view text, std::string_view dotted_key,
                                            std::string& error);

/// `text` with the key `key` of element `element` (0 first) of the array of tables `array_key`
/// (`[[edm.condition]]`: "edm.condition", compared in lower case) set to `value_toml`, as
/// with_toml_value() sets a key of a table: the line keeps its indentation and comment, a key the
/// element lacks is added after its last key. Refused (nullopt, `error` says why) as
/// with_toml_value() refuses, and when the elements are not each written under a `[[…]]` header
/// of their own (an inline array of tables). Non-real-time; any thread.
std::optional<std::string> with_toml_element_value(std::string_view text, std::string_view array_key,
                                                   int element, std::string_view key,
                                                   std::string_view value_toml, std::string& error);

/// `text` without the key `key` of element `element` of the array of tables `array_key` (as
/// with_toml_element_value() finds it). Non-real-time; any thread.
std::optional<std::string> without_toml_element_key(std::string_view text, std::string_view array_key,
                                                    int element, std::string_view key, std::string& error);

/// `text` with a copy of element `element` (0 first) of the array of tables `array_key`
/// ("edm.condition", lower case) appended after the array's last element: a blank line, the
/// comment line `comment` ("" for none), the element's header, and its keys in the order its lines
/// give them, each written afresh from its value (the source's comments are not copied), with
/// `key` set to `value_toml` (added when the element lacks it). The comments and lines that lead
/// into the next table stay after the copy. Refused (nullopt, `error` says why) when the elements
/// are not each written under a `[[…]]` header of their own, a copied value is an array, a table
/// or a date, `value_toml` is not one TOML value, or the result does not read back as `text` with
/// exactly that element appended. Non-real-time; any thread.
std::optional<std::string> with_toml_element_copy(std::string_view text, std::string_view array_key,
                                                  int element, std::string_view key, std::string_view value_toml,
                                                  std::string_view comment, std::string& error);

/// `text` without element `element` of the array of tables `array_key`: its header, its lines,
/// the comment lines right above its header (what it is) and the blank line before them; every
/// other line stays. Refused (nullopt, `error` says why) as with_toml_element_copy() refuses, and
/// when the result does not read back as `text` without exactly that element. Non-real-time; any
/// thread.
std::optional<std::string> without_toml_element(std::string_view text, std::string_view array_key, int element,
                                                std::string& error);

/// A number as TOML text that reads back as the same double (always a float: "80.0", "1e-05").
/// Any thread.
std::string toml_number(double v);

}  // namespace opencnc::config
