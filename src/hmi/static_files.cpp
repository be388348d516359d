// SPDX-License-Identifier: GPL-3.0-or-later
#include "opencnc/hmi/static_files.hpp"

#include <fstream>
#include <sstream>

namespace opencnc::hmi {

std::string_view mime_type(const std::filesystem::path& p) {
  const std::string e = p.extension().string();
  if (e == ".html") return "text/html; charset=utf-8";
  if (e == ".js") return "text/javascript";
  if (e == ".css") return "text/css";
  if (e == ".svg") return "image/svg+xml";
  if (e == ".png") return "image/png";
  if (e == ".json" || e == ".map") return "application/json";
  if (e == ".ico") return "image/x-icon";
  return "application/octet-stream";
}

std::optional<StaticFile> read_static_file(const std::filesystem::path& dir, std::string_view path,
                                           std::string_view index) {
  if (dir.empty() || !path.starts_with('/')) return std::nullopt;
  const std::filesystem::path rel(path == "/" ? std::string(index) : std::string(path.substr(1)));
  for (const auto& part : rel) {
    if (part == ".." || part.string().starts_with(".")) return std::nullopt;
  }
  std::ifstream in(dir / rel, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream body;
  body << in.rdbuf();
  return StaticFile{body.str(), mime_type(rel), path.starts_with("/assets/")};
}

}  // namespace opencnc::hmi
