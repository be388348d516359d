// SPDX-License-Identifier: GPL-3.0-or-later
// File table and interned call stacks.
#include "opencnc/canon/source_map.hpp"

#include <algorithm>
#include <fmt/format.h>

namespace opencnc::canon {

std::size_t SourceMap::KeyHash::operator()(const Key& k) const noexcept {
  std::size_t h = k.parent;
  for (std::uint32_t v : {k.file, k.line, k.col, k.body}) h = h * 1000003u ^ v;
  return h;
}

SourceMap::SourceMap() { contexts_.push_back(Context{}); }

std::uint32_t SourceMap::add_file(std::string_view path) {
  std::string key(path);
  auto it = file_index_.find(key);
  if (it != file_index_.end()) return it->second;
  auto index = static_cast<std::uint32_t>(files_.size());
  files_.push_back(key);
  file_index_.emplace(std::move(key), index);
  return index;
}

std::uint32_t SourceMap::context(std::uint32_t parent, SourceRef call_site, std::uint32_t body_file,
                                 std::string_view name) {
  Key key{parent, call_site.file, call_site.line, call_site.col, body_file};
  auto it = context_index_.find(key);
  if (it != context_index_.end()) return it->second;
  auto id = static_cast<std::uint32_t>(contexts_.size());
  contexts_.push_back(Context{parent, call_site, body_file, std::string(name)});
  context_index_.emplace(key, id);
  return id;
}

std::vector<std::uint32_t> SourceMap::stack(std::uint32_t context) const {
  std::vector<std::uint32_t> out;
  while (context != 0) {
    out.push_back(context);
    context = contexts_.at(context).parent;
  }
  std::reverse(out.begin(), out.end());
  return out;
}

std::string SourceMap::describe(std::uint32_t context, std::uint32_t file, std::uint32_t line) const {
  std::string out;
  for (std::uint32_t c : stack(context)) {
    const Context& info = contexts_.at(c);
    out += fmt::format("{}:{} ({}) > ", files_.at(info.call_site.file), info.call_site.line, info.name);
  }
  out += fmt::format("{}:{}", file < files_.size() ? files_[file] : std::string("?"), line);
  return out;
}

}  // namespace opencnc::canon
