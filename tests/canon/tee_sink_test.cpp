// SPDX-License-Identifier: GPL-3.0-or-later
// TeeSink hands every canonical call to both of its sinks, in order.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <string>

#include "opencnc/canon/rs274_printer.hpp"
#include "opencnc/canon/tee_sink.hpp"

using namespace opencnc;
using namespace opencnc::canon;

namespace {

std::string printed(const std::function<void(Sink&)>& calls, bool through_tee) {
  std::FILE* a = std::tmpfile();
  std::FILE* b = std::tmpfile();
  {
    Rs274Printer left(a, a), right(b, b);
    if (through_tee) {
      TeeSink tee(left, right);
      calls(tee);
    } else {
      calls(left);
      calls(right);
    }
  }
  std::string out;
  for (std::FILE* f : {a, b}) {
    std::rewind(f);
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
    out += "--\n";
    std::fclose(f);
  }
  return out;
}

}  // namespace

TEST(TeeSink, BothSinksSeeWhatEachWouldSeeAlone) {
  auto calls = [](Sink& s) {
    BlockOrigin o;
    o.line = 3;
    s.begin_block(o);
    s.use_length_units(Units::Inch);
    Pose p;
    p[Axis::X] = 1.5;
    s.set_g5x_offset(2, p);
    s.straight_traverse(0, p);
    s.straight_feed(1, p);
    ArcFeed arc;
    arc.first_end = 2;
    s.arc_feed(2, arc);
    s.dwell(0.5);
    s.set_feed_rate(100);
    s.start_spindle_clockwise(0);
    s.set_spindle_speed(0, 1200);
    s.select_tool(3);
    s.change_tool(3);
    s.use_tool_length_offset(p);
    s.set_tool_table_entry(1, 3, p, 0.5, 0, 0, 0);
    s.comment("c");
    s.message("m");
    s.print("p");
    s.wait_for_input(1, true, 3, 2.0);
    s.set_aux_output_bit(4);
    s.mist_on();
    s.flood_off();
    s.program_stop();
    s.program_end();
  };
  const std::string direct = printed(calls, false);
  EXPECT_EQ(printed(calls, true), direct);
  EXPECT_NE(direct.find("SET_TOOL_TABLE_ENTRY"), std::string::npos);
}
