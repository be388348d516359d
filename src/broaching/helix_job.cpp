// SPDX-License-Identifier: GPL-3.0-or-later
// The broaching job generator: strokes, infeeds and the coupling codes of a helical groove.
#include "opencnc/broaching/helix_job.hpp"

#include <fmt/format.h>

#include <cmath>

namespace opencnc::cam {

namespace {

/// Depths closer than this to the total are the total (an infeed that divides the depth exactly
/// must not leave a stroke of rounding).
constexpr double kDepthEpsilon = 1e-9;

const char* type_name(HelixType t) {
  switch (t) {
    case HelixType::Constant:
      return "constant pitch";
    case HelixType::Variable:
      return "variable pitch";
    case HelixType::Table:
      return "pitch table";
    case HelixType::Cam:
      return "cam";
  }
  return "";
}

std::string coupling_code(const HelixJob& j) {
  switch (j.type) {
    case HelixType::Constant:
      return fmt::format("M171 P{:.4f}", j.pitch_mm);
    case HelixType::Variable: {
      const double rate = (j.pitch_end_mm - j.pitch_mm) / (j.z_end - j.z_start);
      return fmt::format("M172 P{:.4f} Q{:.8f}", j.pitch_mm, rate);
    }
    case HelixType::Table:
      return fmt::format("M173 P{}", j.table);
    case HelixType::Cam:
      return fmt::format("M174 P{}", j.table);
  }
  return {};
}

/// The depth of stroke `k` (0-based): infeed by infeed to the full depth, then spring passes.
double stroke_depth(const HelixJob& j, int k) {
  return std::min(j.depth_mm, j.infeed_mm * (k + 1));
}

}  // namespace

int strokes_per_groove(const HelixJob& j) {
  return static_cast<int>(std::ceil(j.depth_mm / j.infeed_mm - kDepthEpsilon)) + j.spring_passes;
}

std::optional<std::string> validate(const HelixJob& j) {
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!finite(j.z_start) || !finite(j.z_end) || j.z_start == j.z_end)
    return "--z-start and --z-end must be different finite positions";
  // The job writes pitches with 4 decimals (M171 P, as the interpreter reads them): a smaller one
  // would be written as 0, which the interpreter refuses.
  constexpr double kLeastPitchMm = 1e-4;
  if ((j.type == HelixType::Constant || j.type == HelixType::Variable) &&
      (!finite(j.pitch_mm) || std::fabs(j.pitch_mm) < kLeastPitchMm))
    return "--pitch must be a pitch per revolution of at least 0.0001 mm (negative: a left-hand helix)";
  if (j.type == HelixType::Variable) {
    if (!finite(j.pitch_end_mm) || std::fabs(j.pitch_end_mm) < kLeastPitchMm ||
        (j.pitch_end_mm > 0) != (j.pitch_mm > 0))
      return "--pitch-end must be a pitch of at least 0.0001 mm, of the same sign as --pitch";
  }
  if ((j.type == HelixType::Table || j.type == HelixType::Cam) && (j.table < 1 || j.table > 8))
    return "--table must be the number of one of the machine's coupling tables, 1 to 8";
  if (!(j.depth_mm > 0) || !(j.infeed_mm > 0) || !finite(j.depth_mm) || !finite(j.infeed_mm))
    return "--depth and --infeed must be positive";
  if (j.depth_mm / j.infeed_mm > 10000) return "--depth / --infeed would take more than 10000 strokes";
  if (j.spring_passes < 0 || j.spring_passes > 100) return "--spring-passes must be 0 to 100";
  if (j.grooves < 1 || j.grooves > 360) return "--grooves must be 1 to 360";
  if (!(j.feed > 0) || !(j.infeed_feed > 0) || !finite(j.feed) || !finite(j.infeed_feed))
    return "--feed and --infeed-feed must be positive";
  if (!(j.lift_mm > 0) || !finite(j.lift_mm)) return "--lift must be positive";
  if (!finite(j.c_start)) return "--c-start must be a finite angle";
  return std::nullopt;
}

std::string helix_program(const HelixJob& j, const std::string& command_line) {
  std::string p;
  const auto line = [&](const std::string& s) { p += s + "\n"; };
  line(fmt::format("(broaching job written by: {})", command_line));
  line(fmt::format(
      "(helix: {}, Z {:.3f} to {:.3f}, depth {:.4f} mm in strokes of {:.4f} + {} spring, {} groove{})",
      type_name(j.type), j.z_start, j.z_end, j.depth_mm, j.infeed_mm, j.spring_passes, j.grooves,
      j.grooves == 1 ? "" : "s"));
  line("G21 G90 G94 G17 G40 G49");
  line("G64 P0.005");
  line(fmt::format("G0 X{:.4f}", -j.lift_mm));
  line(fmt::format("G0 Z{:.4f} C{:.4f}", j.z_start, j.c_start));
  const int strokes = strokes_per_groove(j);
  for (int g = 0; g < j.grooves; ++g) {
    const double c = j.c_start + 360.0 * g / j.grooves;
    line(fmt::format("(groove {} of {} at C{:.4f})", g + 1, j.grooves, c));
    if (g > 0) line(fmt::format("G0 C{:.4f}", c));
    line(coupling_code(j) + " (C follows Z)");
    for (int k = 0; k < strokes; ++k) {
      const double depth = stroke_depth(j, k);
      line(fmt::format("(stroke {} of {}: depth {:.4f})", k + 1, strokes, depth));
      line(fmt::format("G1 X{:.4f} F{:.1f}", depth, j.infeed_feed));
      line(fmt::format("G1 Z{:.4f} F{:.1f}", j.z_end, j.feed));
      line(fmt::format("G1 X{:.4f} F{:.1f}", depth - j.lift_mm, j.infeed_feed));
      line(j.rapid_return ? fmt::format("G0 Z{:.4f}", j.z_start)
                          : fmt::format("G1 Z{:.4f} F{:.1f}", j.z_start, j.feed));
    }
    line("M175");
  }
  line(fmt::format("G0 X{:.4f}", -j.lift_mm));
  line("M2");
  return p;
}

}  // namespace opencnc::cam
