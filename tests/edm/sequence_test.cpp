// SPDX-License-Identifier: GPL-3.0-or-later
// The condition sequence from the technology table: the roughing by the electrode's area, the
// steps down by Ra to the finish, the walls back from the undersize, and each refusal in words.
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/edm/sequence.hpp"

namespace opencnc::edm {
namespace {

const machine::EdmConfig& table() {
  static const config::ProfileLoad p = config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml");
  return p.profile->edm.config;
}

Sequence planned(double area, double ra, double undersize, const machine::EdmConfig& edm = table()) {
  auto r = plan_sequence(edm, {area, ra, undersize});
  if (const auto* why = std::get_if<std::string>(&r)) ADD_FAILURE() << *why;
  return std::holds_alternative<Sequence>(r) ? std::get<Sequence>(r) : Sequence{};
}

std::string refusal(double area, double ra, double undersize, const machine::EdmConfig& edm = table()) {
  auto r = plan_sequence(edm, {area, ra, undersize});
  return std::holds_alternative<std::string>(r) ? std::get<std::string>(r) : std::string("(planned)");
}

TEST(EdmSequence, VdiAndRaConvertAsTheStandardSays) {
  EXPECT_NEAR(vdi_to_ra_um(18), 0.794, 0.001);
  EXPECT_NEAR(vdi_to_ra_um(30), 3.16, 0.01);
  EXPECT_EQ(ra_to_vdi(0.8), 18);
  EXPECT_EQ(ra_to_vdi(3.2), 30);
  EXPECT_NEAR(std::get<double>(parse_finish("VDI18")), 0.794, 0.001);
  EXPECT_EQ(std::get<double>(parse_finish("Ra0.8")), 0.8);
  EXPECT_EQ(std::get<double>(parse_finish("1.6")), 1.6);
  EXPECT_NE(std::get<std::string>(parse_finish("fine")).find("is not a finish"), std::string::npos);
  EXPECT_NE(std::get<std::string>(parse_finish("VDI60")).find("from 0 to 45"), std::string::npos);
  EXPECT_NE(std::get<std::string>(parse_finish("-1")).find("above 0"), std::string::npos);
}

// The 20 mm² blade takes 12 A at 0.6 A/mm²: E1 roughs, E2 halves its Ra, E3 finishes to Ra 0.8.
// The walls back from 0.08 mm: E3 at 0.08 (orbit 0.068), E2 8 µm short (5 × Ra 1.6: orbit 0.047),
// E1 16 µm short of that (no orbit: its wall is its side gap, 0.040 ≤ 0.056).
TEST(EdmSequence, TheRoughingByAreaThenStepsDownByRaWithTheOrbitFromTheUndersize) {
  const Sequence s = planned(20, 0.8, 0.08);
  ASSERT_EQ(s.steps.size(), 3u);
  EXPECT_EQ(s.steps[0].condition, 1);
  EXPECT_EQ(s.steps[1].condition, 2);
  EXPECT_EQ(s.steps[2].condition, 3);
  EXPECT_EQ(s.steps[0].orbit_mm, 0);
  EXPECT_NEAR(s.steps[0].wall_mm, 0.040, 1e-12);
  EXPECT_NEAR(s.steps[0].allowance_mm, 0.024, 1e-12);
  EXPECT_NEAR(s.steps[1].orbit_mm, 0.047, 1e-12);
  EXPECT_NEAR(s.steps[1].wall_mm, 0.072, 1e-12);
  EXPECT_NEAR(s.steps[1].allowance_mm, 0.008, 1e-12);
  EXPECT_NEAR(s.steps[2].orbit_mm, 0.068, 1e-12);
  EXPECT_NEAR(s.steps[2].wall_mm, 0.08, 1e-12);
  EXPECT_EQ(s.steps[2].allowance_mm, 0);
  // Each step removes what the one before left: its wall at least the previous Rz beyond it.
  for (std::size_t k = 1; k < s.steps.size(); ++k)
    EXPECT_GE(s.steps[k].wall_mm - s.steps[k - 1].wall_mm, kRzPerRa * s.steps[k - 1].ra_um * 1e-3 - 1e-12);
  // A coarser finish stops at E2 (the orbit then the whole undersize less E2's side gap).
  const Sequence coarse = planned(20, 1.6, 0.06);
  ASSERT_EQ(coarse.steps.size(), 2u);
  EXPECT_EQ(coarse.steps[1].condition, 2);
  EXPECT_NEAR(coarse.steps[1].orbit_mm, 0.035, 1e-12);
  // A small electrode takes less current: 15 mm² at 0.6 A/mm² is 9 A, so E2 roughs.
  const Sequence small = planned(15, 0.8, 0.08);
  ASSERT_EQ(small.steps.size(), 2u);
  EXPECT_EQ(small.steps[0].condition, 2);
  EXPECT_EQ(small.steps[1].condition, 3);
}

TEST(EdmSequence, ATableWithAStepBetweenIsSteppedThroughAndOneTooFarApartIsBridged) {
  machine::EdmConfig edm = table();
  // A fourth condition, Ra 1.2 µm: from E2's 1.6 the finest within half is E3's 0.8, so 1.2 is
  // skipped; with E3 at 0.5 (below half of 1.6) the step goes to the next finer one, 1.2.
  machine::EdmCondition four = *edm.find(2);
  four.number = 4;
  four.ra_um = 1.2;
  four.side_gap_mm = 0.018;
  four.removal_mm3_min = 2;
  edm.conditions[static_cast<std::size_t>(edm.condition_count++)] = four;
  EXPECT_EQ(planned(20, 0.8, 0.08, edm).steps.size(), 3u);
  const_cast<machine::EdmCondition*>(edm.find(3))->ra_um = 0.5;
  const Sequence s = planned(20, 0.5, 0.08, edm);
  ASSERT_EQ(s.steps.size(), 4u);
  EXPECT_EQ(s.steps[2].condition, 4);
  EXPECT_EQ(s.steps[3].condition, 3);
}

TEST(EdmSequence, WhatCannotBePlannedIsSaidInWords) {
  EXPECT_NE(refusal(2, 0.8, 0.08).find("takes at most 1.2 A"), std::string::npos) << refusal(2, 0.8, 0.08);
  EXPECT_NE(refusal(20, 0.3, 0.08)
                .find("no condition this electrode takes finishes to Ra 0.3 µm (VDI 10): the "
                      "finest, E3, leaves Ra 0.8 µm"),
            std::string::npos)
      << refusal(20, 0.3, 0.08);
  EXPECT_NE(
      refusal(20, 0.8, 0.1).find("E3's orbit reaches at most 0.0800 mm: an undersize of at most 0.0920 mm"),
      std::string::npos)
      << refusal(20, 0.8, 0.1);
  EXPECT_NE(refusal(20, 0.8, 0.05)
                .find("the undersize 0.0500 mm is too small for this sequence: E1's side gap "
                      "(0.0400 mm) and the 0.0240 mm the later steps remove need at least "
                      "0.0640 mm"),
            std::string::npos)
      << refusal(20, 0.8, 0.05);
  EXPECT_NE(refusal(20, 0.8, 0.01).find("below E3's side gap"), std::string::npos);
  EXPECT_NE(refusal(0, 0.8, 0.08).find("frontal area must be above 0"), std::string::npos);
  machine::EdmConfig edm = table();
  edm.current_density_max_a_mm2 = 0;
  EXPECT_NE(refusal(20, 0.8, 0.08, edm).find("no [edm] current_density_max_a_mm2"), std::string::npos);
  for (int i = 0; i < edm.condition_count; ++i) edm.conditions[static_cast<std::size_t>(i)].ra_um = 0;
  EXPECT_NE(refusal(20, 0.8, 0.08, edm).find("no technology table"), std::string::npos);
}

TEST(EdmSequence, TheProgramSelectsEachStepWithItsOrbitAndFeedsToItsDepth) {
  const Sequence s = planned(20, 0.8, 0.08);
  const std::string text = sequence_program(s, table(), 'Z', -20, 0.1, 1);
  EXPECT_NE(text.find("G0 Z-19.9500\nM180 P1\nG1 Z-20.0760 F60\nM180 P2 Q0.0470\nG1 Z-20.0920 F"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("M180 P3 Q0.0680\nG1 Z-20.1000 F"), std::string::npos) << text;
  EXPECT_NE(text.find("M181\nG0 Z-15.0000\nM2\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace opencnc::edm
