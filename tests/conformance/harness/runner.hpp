// SPDX-License-Identifier: GPL-3.0-or-later
// How the harness runs a conformance case through opencnc and through rs274.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "cases.hpp"

namespace opencnc::conformance {

/// Where the suite's files are. Defaults come from the build; OPENCNC_NCFILES and OPENCNC_CORPUS
/// override the two external folders.
struct Roots {
  std::filesystem::path conf;     ///< tests/conformance
  std::filesystem::path ncfiles;  ///< LinuxCNC's sample programs
  std::filesystem::path corpus;   ///< the real-world corpus

  /// The folder a case's `program` is relative to.
  std::filesystem::path set_root(const std::string& set) const;
  /// A path of cases.tsv: "@conf/..." or "@corpus/..." made absolute; "-" stays empty.
  std::filesystem::path resolve(const std::string& token_path) const;
  /// The program of `c`, absolute.
  std::filesystem::path program(const Case& c) const { return set_root(c.set) / c.program; }
};

/// Roots for the compiled-in source folder `source_dir` and shared folder `shared_dir`,
/// with the environment overrides applied.
Roots roots_from_environment(const std::filesystem::path& source_dir, const std::filesystem::path& shared_dir);

/// The case's SUBROUTINE_PATH entries as absolute folders (relative ones are relative to
/// `folder`, the program's folder; "@ncfiles/..." ones to the roots).
std::vector<std::filesystem::path> search_path(const Case& c, const Roots& roots, const std::filesystem::path& folder);

/// A command line, the folder it runs in and changes to its environment ("KEY=VALUE").
struct Invocation {
  std::vector<std::string> argv;
  std::filesystem::path cwd;
  std::vector<std::string> env;
};

/// `opencnc <subcommand> FILE [--dialect fanuc] [--tool-table T] [--subroutine-path DIR]... [args]`,
/// run in the program's folder. The program's folder is the first search-path entry (rs274 finds
/// subprogram files in its working folder), then the case's SUBROUTINE_PATH entries.
Invocation opencnc_invocation(const Case& c, const Roots& roots, const std::filesystem::path& binary,
                              std::string_view subcommand);

/// rs274 as regen-golden.sh runs it (for own Fanuc-dialect cases: on the twin). When the case has a
/// SUBROUTINE_PATH, an INI file for it is written into `scratch`. HOME is set to `scratch`: rs274
/// keeps the tool table in $HOME/.tool.mmap, so two rs274 runs with one HOME corrupt each other's.
Invocation rs274_invocation(const Case& c, const Roots& roots, const std::filesystem::path& rs274,
                            const std::filesystem::path& scratch);

/// Whether rs274 has a golden output for the case to be checked against (every case but the
/// Fanuc-dialect error programs; own Fanuc-dialect programs run as their twins, Fanuc-style corpus
/// files as LinuxCNC programs, which rs274 rejects).
bool rs274_can_run(const Case& c);

/// rs274's standard error as the golden files keep it: without "executing", with the absolute
/// programs and ncfiles folders written as @programs and @ncfiles.
std::vector<std::string> rs274_error_lines(const std::string& err, const Roots& roots);

}  // namespace opencnc::conformance
