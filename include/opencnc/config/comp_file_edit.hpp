// SPDX-License-Identifier: GPL-3.0-or-later
// Writing an axis' pitch-error table back into its LinuxCNC comp file: the new text with the
// file's comment lines kept, for the profile loader to check before anything is written.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {

/// `old_text` (a comp file: lines of "nominal forward reverse") with its points replaced by the
/// table's: the k-th line of numbers becomes the k-th point, number lines beyond the new count
/// are removed, and further points follow the last one. Lines that are blank or start with '#'
/// stay where they are (the format has no other place for a comment). `type` is comp_file_type:
/// 0 writes the positions reached (nominal + error), 1 the trims (−error). The three spans have
/// the same length. Any thread.
std::string comp_file_with_table(std::string_view old_text, int type, std::span<const double> positions,
                                 std::span<const double> forward, std::span<const double> reverse);

/// The new text of the comp file of axis `a` (`a.compensation.comp_file` not empty) with the
/// forward and reverse errors and the points' positions given as one-line TOML arrays; each is
/// optional and keeps its present value when absent. Refused with `error` (nothing else read or
/// written): the file changed on disk since it was loaded (its digest), a value that is not an
/// array of finite numbers, lengths that differ. Whether the table is usable (positions
/// increasing, slopes, at most 256 points) is the profile loader's to say, on this text.
/// Non-real-time (reads the file).
std::optional<FileText> edit_comp_file(const AxisProfile& a, const std::optional<std::string>& forward,
                                       const std::optional<std::string>& reverse,
                                       const std::optional<std::string>& positions, std::string& error);

/// edit_profile()'s pitch-table keys of axes whose table is in a comp file, gathered per axis and
/// then turned into each file's new text. Non-real-time.
class CompFileEdits {
 public:
  /// Takes `name` ("forward", "reverse" or "positions") of axis `a` with its TOML `value`; false
  /// with `error` for "start" or "interval" (a comp file lists each point's position).
  bool add(const AxisProfile& a, std::string_view name, const std::string& value, std::string& error);
  /// Appends each axis' comp file with its new text (edit_comp_file); false with `error`.
  bool texts(std::vector<FileText>& out, std::string& error) const;

 private:
  struct Axis {
    const AxisProfile* axis = nullptr;
    std::optional<std::string> forward, reverse, positions;
  };
  std::vector<Axis> axes_;
};

}  // namespace opencnc::config
