// SPDX-License-Identifier: GPL-3.0-or-later
// A sinker EDM's roughing-to-finishing condition sequence, chosen from the electrode's frontal
// area, the finish asked for and the electrode's undersize by the profile's technology table
// (each condition's Ra, side gap, removal rate and wear), as the makers' tables do (docs/edm.md).
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "opencnc/machine/edm.hpp"

namespace opencnc::edm {

/// What the operator asks for.
struct SequenceRequest {
  double area_mm2 = 0;      ///< the electrode's frontal area
  double finish_ra_um = 0;  ///< the surface roughness Ra the cavity must have at most
  double undersize_mm = 0;  ///< the electrode's undersize per side: final orbit + final side gap
};

/// One step of the sequence: a condition, the orbit it burns with and where its wall ends.
struct SequenceStep {
  int condition = 0;
  double peak_current_a = 0;
  double ra_um = 0;
  double side_gap_mm = 0;
  double orbit_mm = 0;      ///< the orbit's radius (M180's Q; 0: the condition has no orbit)
  double wall_mm = 0;       ///< the side wall's distance beyond the electrode after this step
  double allowance_mm = 0;  ///< what the later steps remove, on the sides and on the front
  double removal_mm3_min = 0;
  double wear_ratio = 0;
  bool orbit_limited = false;  ///< the planned orbit was beyond the condition's radius: its radius
};

struct Sequence {
  SequenceRequest request;
  std::vector<SequenceStep> steps;
};

/// Rz, the roughness' depth, per µm of Ra: the layer a step leaves for the next to remove
/// (the makers' rule of thumb Rz ≈ 4 … 7 Ra).
inline constexpr double kRzPerRa = 5.0;

/// Ra (µm) of a VDI 3400 class: Ra = 10^(VDI/20) / 10. Any thread.
double vdi_to_ra_um(double vdi) noexcept;
/// The VDI 3400 class of an Ra (µm), rounded to a whole class. Any thread.
int ra_to_vdi(double ra_um) noexcept;

/// "0.8" (Ra in µm), "Ra0.8" or "VDI18": the Ra asked for; an error in words otherwise.
std::variant<double, std::string> parse_finish(const std::string& text);

/// The sequence for `r` from `edm`'s conditions that give an Ra (the technology table); an error
/// in words when the table, the area, the finish or the undersize do not allow one. Rules:
/// the roughing is the condition of the highest removal rate whose peak current the area takes
/// (edm.current_density_max_a_mm2); each next step is the finest condition no finer than half the
/// previous one's Ra (else the next finer one), down to the coarsest that meets the finish; the
/// final wall is the undersize, each earlier one short of the next by its own Rz (kRzPerRa × Ra),
/// so that every step removes the roughness the one before it left; a step's orbit is its wall
/// less its side gap. Any thread (allocates).
std::variant<Sequence, std::string> plan_sequence(const machine::EdmConfig& edm, const SequenceRequest& r);

/// The sequence in lines of text (one per step), for the terminal. Any thread.
std::string sequence_text(const Sequence& s);

/// A program that burns the sequence along the tool axis `axis_letter` from `surface` (the
/// work's surface, where the electrode's tip touches it) to `depth_mm` below it: per step
/// `M180 P<n> [Q<orbit>]` and a feed to the depth less the step's allowance; then M181 and a lift.
/// `lift` is +1 when away from the work is +. Any thread.
std::string sequence_program(const Sequence& s, const machine::EdmConfig& edm, char axis_letter,
                             double surface, double depth_mm, double lift);

}  // namespace opencnc::edm
