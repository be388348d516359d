// SPDX-License-Identifier: GPL-3.0-or-later
// The printer writes the exact text of LinuxCNC 2.9's `rs274 -g` for each canonical call.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "opencnc/canon/rs274_printer.hpp"

using namespace opencnc;
using namespace opencnc::canon;

namespace {

class Capture {
 public:
  Capture() : file_(std::tmpfile()) {}
  ~Capture() { std::fclose(file_); }
  std::FILE* file() { return file_; }
  std::string text() {
    std::fflush(file_);
    std::rewind(file_);
    std::string out;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, file_)) > 0) out.append(buf, n);
    return out;
  }

 private:
  std::FILE* file_;
};

BlockOrigin with_n(const char* digits) {
  BlockOrigin o;
  o.n_present = true;
  o.n_length = static_cast<std::uint8_t>(std::strlen(digits));
  std::memcpy(o.n_digits, digits, o.n_length);
  return o;
}

}  // namespace

TEST(Rs274Printer, NumbersLinesAndLabelsBlocks) {
  Capture cap;
  {
    Rs274Printer p(cap.file(), nullptr);
    p.use_length_units(Units::Mm);
    p.begin_block(with_n("0150"));
    p.program_end();
    p.begin_block(with_n("35286"));
    p.pallet_shuttle();
    p.begin_block(BlockOrigin{});
    p.on_reset();
  }
  EXPECT_EQ(cap.text(),
            "    1 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
            "    2 N0150  PROGRAM_END()\n"
            "    3 N35286 PALLET_SHUTTLE()\n"
            "    4 N..... ON_RESET()\n");
}

TEST(Rs274Printer, FormatsMotionCalls) {
  Capture cap;
  {
    Rs274Printer p(cap.file(), nullptr);
    Pose e;
    e[Axis::X] = 1;
    e[Axis::Y] = 2;
    e[Axis::Z] = -1;
    p.straight_feed(0, e);
    ArcFeed a;
    a.first_end = 3;
    a.second_end = 2;
    a.first_center = 2;
    a.second_center = 2;
    a.rotation = -1;
    a.axis_end = -1;
    p.arc_feed(1, a);
    p.rigid_tap(2, e, 1.0);
    p.set_g5x_offset(2, e);
    p.use_tool_length_offset(e);
  }
  EXPECT_EQ(cap.text(),
            "    1 N..... STRAIGHT_FEED(1.0000, 2.0000, -1.0000, 0.0000, 0.0000, 0.0000)\n"
            "    2 N..... ARC_FEED(3.0000, 2.0000, 2.0000, 2.0000, -1, -1.0000, 0.0000, 0.0000, 0.0000)\n"
            "    3 N..... RIGID_TAP(1.0000, 2.0000, -1.0000)\n"
            "    4 N..... SET_G5X_OFFSET(2, 1.0000, 2.0000, -1.0000, 0.0000, 0.0000, 0.0000)\n"
            "    5 N..... USE_TOOL_LENGTH_OFFSET(1.0000 2.0000 -1.0000, 0.0000 0.0000 0.0000, "
            "0.0000 0.0000 0.0000)\n");
}

TEST(Rs274Printer, FormatsModeAndIoCalls) {
  Capture cap;
  {
    Rs274Printer p(cap.file(), nullptr);
    p.set_motion_control_mode(MotionControl::Continuous, 0.1);
    p.set_motion_control_mode(MotionControl::ExactPath, 0);
    p.set_naivecam_tolerance(0.05);
    p.set_feed_mode(0, FeedMode::UnitsPerRevolution);
    p.set_feed_mode(0, FeedMode::InverseTime);
    p.start_speed_feed_synch(0, 0.5, false);
    p.set_spindle_mode(0, 2000);
    p.orient_spindle(0, 45, 1);
    p.wait_spindle_orient_complete(0, 2);
    p.set_aux_output_value(2, 6);
    p.message("hello world");
    p.select_plane(Plane::UV);
  }
  EXPECT_EQ(cap.text(),
            "    1 N..... SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.100000)\n"
            "    2 N..... SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)\n"
            "    3 N..... SET_NAIVECAM_TOLERANCE(0.0500)\n"
            "    4 N..... SET_FEED_MODE(0, 1)\n"
            "    5 N..... SET_FEED_MODE(0, 0)\n"
            "    6 N..... START_SPEED_FEED_SYNC(0.500000,0)\n"
            "    7 N..... SET_SPINDLE_MODE(0 2000.0000)\n"
            "    8 N..... ORIENT_SPINDLE(0, 45.0000, 1)\n"
            "    9 N..... SPINDLE.0.WAIT_ORIENT_COMPLETE(2.0000)\n"
            "   10 N..... SET_AUX_OUTPUT_VALUE(2,6.000000)\n"
            "   11 N..... MESSAGE(\"hello world\")\n"
            "   12 N..... SELECT_PLANE(CANON_PLANE_UNKNOWN)\n");
}

TEST(Rs274Printer, FormatsToolTableEntriesAsRs274) {
  Capture cap;
  {
    Rs274Printer p(cap.file(), nullptr);
    Pose offset;
    offset[Axis::X] = 0.25;
    offset[Axis::Z] = 1.5;
    p.set_tool_table_entry(2, 2, offset, 0.2, 10, 20, 3);   // the diameter is not printed
  }
  EXPECT_EQ(cap.text(),
            "    1 N..... SET_TOOL_TABLE_ENTRY(2, 2, 0.2500 0.0000 1.5000 0.0000 0.0000 0.0000 0.0000 0.0000 0.0000, "
            "10.0000, 20.0000, 3)\n");
}

TEST(Rs274Printer, PrintTextKeepsItsPlaceAndLongLabelsRunOn) {
  Capture cap;
  {
    Rs274Printer p(cap.file(), cap.file());   // one stream, as `opencnc canon` prints
    p.use_length_units(Units::Inch);
    p.print("hello");
    p.begin_block(with_n("123456789012"));
    p.straight_traverse(0, Pose{});
  }
  EXPECT_EQ(cap.text(),
            "    1 N..... USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
            "hello\n"
            "    2 N123456789012STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n");
}

TEST(Rs274Printer, SequenceNumbersWidenPastFiveDigits) {
  Capture cap;
  {
    Rs274Printer p(cap.file(), nullptr);
    for (int i = 0; i < 100000; ++i) p.flood_off();
  }
  const std::string text = cap.text();
  EXPECT_NE(text.find("\n99999 N..... FLOOD_OFF()\n100000 N..... FLOOD_OFF()\n"), std::string::npos);
}
