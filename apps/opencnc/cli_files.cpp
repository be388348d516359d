// SPDX-License-Identifier: GPL-3.0-or-later
// Checking a subcommand's inputs and opening its outputs before it runs.
#include "cli_files.hpp"

#include <fmt/format.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "run_session.hpp"

namespace opencnc::cli {

std::optional<config::MachineProfile> quiet_profile(const SessionOptions& o) {
  if (o.machine.empty()) return std::nullopt;
  return config::load_profile(o.machine, o.sets).profile;
}

std::vector<NamedPath> session_inputs(const SessionOptions& o, const config::MachineProfile* profile) {
  std::vector<NamedPath> in = {{"the program", o.file}, {"the profile", o.machine}};
  if (profile != nullptr && !profile->interpreter.tool_table.empty())
    in.push_back({"the tool table", profile->interpreter.tool_table});
  if (profile != nullptr && profile->tool_guard.present)
    in.push_back({"the tool store", profile->tool_guard.store});
  return in;
}

bool check_inputs(std::span<const NamedPath> inputs) {
  for (const NamedPath& in : inputs) {
    if (in.path.empty()) continue;
    // O_NONBLOCK: a FIFO given as a profile must not hang the check until a writer comes.
    const int fd = ::open(in.path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    struct stat st {};
    const bool opened = fd >= 0 && ::fstat(fd, &st) == 0;
    const int err = errno;
    if (fd >= 0) ::close(fd);
    if (!opened) {
      fmt::print(stderr, "error: {} {}: {}\n", in.role, in.path, std::strerror(err));
      return false;
    }
    if (S_ISDIR(st.st_mode)) {
      fmt::print(stderr, "error: {} {}: it is a folder, not a file\n", in.role, in.path);
      return false;
    }
  }
  return true;
}

std::vector<std::unique_ptr<OutputFile>> open_outputs(std::span<const NamedPath> inputs,
                                                      std::span<const NamedPath> outputs) {
  if (const std::string conflict = output_conflict(inputs, outputs); !conflict.empty()) {
    fmt::print(stderr, "error: {}\n", conflict);
    return {};
  }
  std::vector<std::unique_ptr<OutputFile>> opened;
  for (const NamedPath& out : outputs) {
    if (out.path.empty()) {
      opened.emplace_back();
      continue;
    }
    std::string error;
    opened.push_back(OutputFile::open(out, &error));
    if (!opened.back()) {
      fmt::print(stderr, "error: {}\n", error);
      return {};  // (the ones opened so far remove their temporary files)
    }
  }
  return opened;
}

bool write_and_commit(OutputFile& out, std::string_view content) {
  out.write(content);
  return commit(out);
}

bool commit(OutputFile& out) {
  std::string error;
  if (out.commit(&error)) return true;
  fmt::print(stderr, "error: {}\n", error);
  return false;
}

bool replace_profile_text(const std::string& path, const std::string& original, const std::string& text,
                          std::string& why) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || ::access(path.c_str(), W_OK) != 0) {
    why = fmt::format("{} is not a regular file we may write", path);
    return false;
  }
  std::string now;
  if (!read_file(path, now, &why)) return false;
  if (now != original) {
    why = fmt::format("{} changed while the machine was measured (nothing written)", path);
    return false;
  }
  if (!write_file_atomically(path, text, &why)) return false;
  ::chmod(path.c_str(), st.st_mode & 07777);  // keep its permissions
  return true;
}

}  // namespace opencnc::cli
