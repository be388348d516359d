// SPDX-License-Identifier: GPL-3.0-or-later
// Command lines for opencnc and rs274, built from a row of cases.tsv.
#include "runner.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <stdexcept>

#include <fmt/format.h>

namespace opencnc::conformance {

namespace {

std::vector<std::string> split(std::string_view s, char sep) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= s.size()) {
    const std::size_t end = s.find(sep, start);
    const auto part = s.substr(start, end == std::string_view::npos ? s.npos : end - start);
    if (!part.empty()) parts.emplace_back(part);
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return parts;
}

std::filesystem::path env_or(const char* name, const std::filesystem::path& fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? std::filesystem::path(v) : fallback;
}

}  // namespace

std::filesystem::path Roots::set_root(const std::string& set) const {
  if (set == "own") return conf / "programs";
  if (set == "ncfiles") return ncfiles;
  if (set == "corpus") return corpus;
  throw std::runtime_error("unknown case set '" + set + "'");
}

std::filesystem::path Roots::resolve(const std::string& token_path) const {
  if (token_path == "-" || token_path.empty()) return {};
  const auto slash = token_path.find('/');
  const std::string root = token_path.substr(0, slash);
  const std::string rest = slash == std::string::npos ? std::string{} : token_path.substr(slash + 1);
  if (root == "@conf") return conf / rest;
  if (root == "@corpus") return corpus / rest;
  if (root == "@ncfiles") return ncfiles / rest;
  throw std::runtime_error("path without a root token in cases.tsv: " + token_path);
}

std::vector<std::filesystem::path> search_path(const Case& c, const Roots& roots,
                                               const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> dirs;
  if (c.subpath == "-") return dirs;
  for (const auto& dir : split(c.subpath, ':')) {
    dirs.push_back(dir[0] == '@' ? roots.resolve(dir) : (folder / dir).lexically_normal());
  }
  return dirs;
}

Roots roots_from_environment(const std::filesystem::path& source_dir, const std::filesystem::path& shared_dir) {
  Roots r;
  r.conf = source_dir / "tests" / "conformance";
  r.ncfiles = env_or("OPENCNC_NCFILES", "/usr/share/linuxcnc/ncfiles");
  r.corpus = env_or("OPENCNC_CORPUS", shared_dir / "gcode-corpus");
  return r;
}

Invocation opencnc_invocation(const Case& c, const Roots& roots, const std::filesystem::path& binary,
                              std::string_view subcommand) {
  const auto program = roots.program(c);
  Invocation inv{{binary.string(), std::string(subcommand), program.filename().string()}, program.parent_path(), {}};
  if (c.dialect != "linuxcnc") inv.argv.insert(inv.argv.end(), {"--dialect", c.dialect});
  if (const auto table = roots.resolve(c.tool_table); !table.empty()) {
    inv.argv.insert(inv.argv.end(), {"--tool-table", table.string()});
  }
  inv.argv.insert(inv.argv.end(), {"--subroutine-path", inv.cwd.string()});
  for (const auto& dir : search_path(c, roots, inv.cwd)) {
    inv.argv.insert(inv.argv.end(), {"--subroutine-path", dir.string()});
  }
  if (c.args != "-") {
    for (const auto& a : split(c.args, ' ')) inv.argv.push_back(a);
  }
  return inv;
}

namespace {
// Own Fanuc-dialect programs are represented by their hand-written LinuxCNC twin.
bool uses_twin(const Case& c) { return c.set == "own" && c.dialect != "linuxcnc"; }
}  // namespace

bool rs274_can_run(const Case& c) { return c.golden != "-"; }

Invocation rs274_invocation(const Case& c, const Roots& roots, const std::filesystem::path& rs274,
                            const std::filesystem::path& scratch) {
  auto program = roots.program(c);
  std::string subpath = c.subpath;
  if (uses_twin(c)) {
    program = roots.conf / "twins" / std::filesystem::path(c.program).replace_extension(".ngc");
    subpath = "-";
  }
  Invocation inv{{rs274.string()}, program.parent_path(), {"HOME=" + scratch.string()}};
  if (const auto table = roots.resolve(c.tool_table); !table.empty()) {
    inv.argv.insert(inv.argv.end(), {"-t", table.string()});
  }
  if (subpath != "-") {
    const auto ini = scratch / fmt::format("subpath-{:016x}.ini", std::hash<std::string>{}(subpath));
    std::string joined;
    for (const auto& dir : split(subpath, ':')) {
      joined += (joined.empty() ? "" : ":") + (dir[0] == '@' ? roots.resolve(dir).string() : dir);
    }
    std::ofstream(ini) << "[RS274NGC]\nSUBROUTINE_PATH = " << joined << "\n";
    inv.argv.insert(inv.argv.end(), {"-i", ini.string()});
  }
  inv.argv.insert(inv.argv.end(), {"-g", program.filename().string()});
  return inv;
}

std::vector<std::string> rs274_error_lines(const std::string& err, const Roots& roots) {
  std::error_code ec;
  const std::pair<std::string, const char*> replacements[] = {
      {std::filesystem::canonical(roots.conf / "programs", ec).string(), "@programs"},
      {std::filesystem::canonical(roots.ncfiles, ec).string(), "@ncfiles"}};
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < err.size()) {
    const std::size_t eol = std::min(err.find('\n', start), err.size());
    std::string line = err.substr(start, eol - start);
    start = eol + 1;
    if (line == "executing") continue;
    for (const auto& [path, token] : replacements) {
      for (std::size_t at = 0; !path.empty() && (at = line.find(path, at)) != std::string::npos;) {
        line.replace(at, path.size(), token);
      }
    }
    lines.push_back(line);
  }
  return lines;
}

}  // namespace opencnc::conformance
