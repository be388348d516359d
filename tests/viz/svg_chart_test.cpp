// SPDX-License-Identifier: GPL-3.0-or-later
// SVG charts: nice ticks, well-formed output, equal scales for toolpaths.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "opencnc/viz/svg_chart.hpp"

using namespace opencnc::viz;

TEST(NiceTicks, UsesOneTwoFiveSteps) {
  EXPECT_EQ(nice_ticks(0, 10, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  auto small = nice_ticks(-0.3, 0.3, 6);
  ASSERT_EQ(small.size(), 7u);
  EXPECT_NEAR(small.front(), -0.3, 1e-12);
  EXPECT_NEAR(small[1] - small[0], 0.1, 1e-12);
  auto t = nice_ticks(0, 7300, 6);
  ASSERT_GE(t.size(), 2u);
  EXPECT_DOUBLE_EQ(t[1] - t[0], 2000.0);  // 7300/6 = 1217 rounds up to the next 1-2-5 step
  EXPECT_TRUE(nice_ticks(1, 1).empty());
}

TEST(SvgChart, RendersPanelsSeriesAndEscapesText) {
  SvgChart chart("Toolpath <test>", 2);
  Panel p;
  p.title = "XY";
  p.x_label = "X (mm)";
  p.y_label = "Y (mm)";
  p.equal_scale = true;
  p.series.push_back(Series{"feed", "#d62728", {0, 10, 10, 0, 0}, {0, 0, 5, 5, 0}, false, 1.2});
  chart.add_panel(p);
  Panel h;
  h.title = "latency";
  h.log_y = true;
  h.series.push_back(Series{"", "#333", {0, 1, 2}, {100, 0, 3}, true, 1.0});
  chart.add_panel(h);
  const std::string svg = chart.render();
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("Toolpath &lt;test&gt;"), std::string::npos);
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  // Two bars drawn: the zero count is skipped on a log axis.
  std::size_t bars = 0;
  for (std::size_t pos = 0; (pos = svg.find("fill=\"#333\"", pos)) != std::string::npos; ++pos) ++bars;
  EXPECT_EQ(bars, 2u);
}
