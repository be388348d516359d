// SPDX-License-Identifier: GPL-3.0-or-later
// Diagnostics print as file:line:col: severity: message, leaving out unknown parts.
#include <gtest/gtest.h>

#include "opencnc/core/diagnostic.hpp"

using opencnc::Diagnostic;
using opencnc::Diagnostics;
using opencnc::Severity;

TEST(Diagnostic, FormatsFullPosition) {
  Diagnostic d{Severity::Error, "part.ngc", 12, 5, "bad character 'q'", "gcode.bad-character"};
  EXPECT_EQ(d.format(), "part.ngc:12:5: error: bad character 'q'");
}

TEST(Diagnostic, LeavesOutUnknownParts) {
  EXPECT_EQ((Diagnostic{Severity::Warning, "a.ngc", 3, 0, "m", ""}).format(), "a.ngc:3: warning: m");
  EXPECT_EQ((Diagnostic{Severity::Error, "", 0, 0, "m", ""}).format(), "error: m");
}

TEST(Diagnostics, CountsBySeverity) {
  Diagnostics ds;
  EXPECT_FALSE(ds.has_errors());
  ds.warning("f", 1, 1, "w");
  EXPECT_FALSE(ds.has_errors());
  ds.error("f", 2, 1, "e");
  EXPECT_TRUE(ds.has_errors());
  EXPECT_EQ(ds.error_count(), 1u);
  EXPECT_EQ(ds.warning_count(), 1u);
}
