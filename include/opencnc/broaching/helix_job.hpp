// SPDX-License-Identifier: GPL-3.0-or-later
// The broaching job generator: a helical groove (constant or variable pitch, a profile's pitch
// table or cam) cut in strokes with a radial infeed each, written as G-code with the coupling
// codes M171-M175 (the automatic programming of `opencnc helix`).
#pragma once

#include <optional>
#include <string>

namespace opencnc::cam {

enum class HelixType { Constant, Variable, Table, Cam };

/// What the operator asks for. Lengths mm, feeds mm/min, pitches mm per revolution of C.
struct HelixJob {
  HelixType type = HelixType::Constant;
  double pitch_mm = 0;       ///< constant pitch, or the pitch at z_start (variable)
  double pitch_end_mm = 0;   ///< variable: the pitch at z_end (linear in between)
  int table = 0;             ///< table / cam: the profile's table number (1-based)
  double z_start = -10;      ///< where each cutting stroke starts (before the bore)
  double z_end = 100;        ///< where it ends (past the bore); either direction
  double c_start = 0;        ///< C of the first groove at z_start, degrees
  double depth_mm = 0.5;     ///< radial depth of the groove (X, from 0 at the bore wall)
  double infeed_mm = 0.1;    ///< radial infeed per stroke (the last one takes the rest)
  int spring_passes = 0;     ///< strokes repeated at full depth
  int grooves = 1;           ///< grooves around the bore, C indexed by 360/grooves between them
  double feed = 3000;        ///< cutting feed
  double infeed_feed = 60;   ///< feed of the radial infeed
  double lift_mm = 0.5;      ///< radial lift for the return stroke (X below the stroke's depth)
  bool rapid_return = true;  ///< the return stroke at rapid (G0), else at `feed`
};

/// What is wrong with `job` in words (for the command line), or nullopt. Any thread.
std::optional<std::string> validate(const HelixJob& job);

/// The job as a program (LinuxCNC dialect, mm, absolute): a header comment with the parameters,
/// per groove the coupling code, per stroke infeed → cutting stroke → lift → return, the
/// coupling released and C indexed to the next groove, M2. `command_line` goes into the header.
/// Any thread; non-real-time. Call validate() first.
std::string helix_program(const HelixJob& job, const std::string& command_line);

/// The number of cutting strokes per groove (infeeds to the depth plus spring passes).
int strokes_per_groove(const HelixJob& job);

}  // namespace opencnc::cam
