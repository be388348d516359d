// SPDX-License-Identifier: GPL-3.0-or-later
// hmi: the built front end's files, as the HMI server and the fleet server serve them.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace opencnc::hmi {

/// The Content-Type of a front-end file, by its extension.
std::string_view mime_type(const std::filesystem::path& p);

struct StaticFile {
  std::string body;
  std::string_view type;
  bool immutable = false;  ///< below /assets/: named by its content's hash, cached for good
};

/// The file that the request path `path` ("/", "/assets/index-1a2b.js") names in `dir`: `index`
/// for "/"; nullopt when there is none, or when the path climbs out of `dir` or names a hidden
/// file.
std::optional<StaticFile> read_static_file(const std::filesystem::path& dir, std::string_view path,
                                           std::string_view index = "index.html");

}  // namespace opencnc::hmi
