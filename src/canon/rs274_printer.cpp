// SPDX-License-Identifier: GPL-3.0-or-later
// rs274 -g text format: "%5d " sequence, N label from the block, then the call.
#include "opencnc/canon/rs274_printer.hpp"

#include <cstring>

#include "opencnc/core/number_format.hpp"

namespace opencnc::canon {

namespace {
constexpr std::size_t kFlushAt = 1 << 16;
}

Rs274Printer::Rs274Printer(std::FILE* out, std::FILE* print_stream) : out_(out), print_stream_(print_stream) {
  buf_.reserve(kFlushAt + 512);
}

Rs274Printer::~Rs274Printer() { flush(); }

void Rs274Printer::flush() {
  if (!buf_.empty() && out_ != nullptr) std::fwrite(buf_.data(), 1, buf_.size(), out_);
  buf_.clear();
  if (out_ != nullptr) std::fflush(out_);
}

namespace {
// Decimal digits of v (v >= 0) right-aligned ending at `end`; returns the first digit.
char* digits_before(char* end, unsigned long v) {
  do {
    *--end = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  return end;
}
}  // namespace

void Rs274Printer::prefix() {
  // "%5d " without printf: this runs once per printed line. The text ends mid-buffer so that
  // a fixed 24 bytes can be copied (a copy of variable length is a library call).
  char seq[48];
  char* const end = seq + 23;
  *end = ' ';
  const int n = sequence_++;
  char* first = digits_before(end, static_cast<unsigned long>(n < 0 ? -static_cast<long>(n) : n));
  if (n < 0) *--first = '-';
  while (end - first < 5) *--first = ' ';
  std::memcpy(buf_.room(24), first, 24);
  buf_.grow(static_cast<std::size_t>(end - first + 1));
  if (origin_.n_present) {
    // rs274 copies the N word's digits as written and pads them to six characters.
    buf_.push_back('N');
    buf_.append(origin_.n_digits, origin_.n_length);
    for (int m = origin_.n_length; m < 6; ++m) buf_.push_back(' ');
  } else {
    buf_.append("N..... ");
  }
}

void Rs274Printer::end_line() {
  buf_.push_back('\n');
  if (buf_.size() >= kFlushAt) {
    std::fwrite(buf_.data(), 1, buf_.size(), out_);
    buf_.clear();
  }
}

void Rs274Printer::num(double v, int decimals) {
  buf_.grow(format_fixed(buf_.room(kFixedBufferSize), v, decimals));   // in place: no copy
}

void Rs274Printer::integer(long v) {
  char tmp[24];
  char* end = tmp + sizeof tmp;
  char* first = digits_before(end, v < 0 ? 0ul - static_cast<unsigned long>(v) : static_cast<unsigned long>(v));
  if (v < 0) *--first = '-';
  buf_.append(first, static_cast<std::size_t>(end - first));
}

void Rs274Printer::simple(const char* call) {
  prefix();
  buf_.append(call);
  end_line();
}

void Rs274Printer::indexed(const char* open, int index) {
  prefix();
  buf_.append(open);
  integer(index);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::quoted(const char* open, std::string_view text) {
  prefix();
  buf_.append(open);
  buf_.append(text);
  buf_.append("\")");
  end_line();
}

void Rs274Printer::pose_call(const char* open, const Pose& p) {
  prefix();
  buf_.append(open);
  for (int i = 0; i < 6; ++i) {
    if (i > 0) buf_.append(", ");
    num(p[i]);
  }
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::use_length_units(Units u) {
  simple(u == Units::Inch ? "USE_LENGTH_UNITS(CANON_UNITS_INCHES)" : "USE_LENGTH_UNITS(CANON_UNITS_MM)");
}

void Rs274Printer::set_g5x_offset(int index, const Pose& offset) {
  prefix();
  buf_.append("SET_G5X_OFFSET(");
  integer(index);
  for (int i = 0; i < 6; ++i) {
    buf_.append(", ");
    num(offset[i]);
  }
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_g92_offset(const Pose& offset) { pose_call("SET_G92_OFFSET(", offset); }

void Rs274Printer::set_xy_rotation(double degrees) {
  prefix();
  buf_.append("SET_XY_ROTATION(");
  num(degrees);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::select_plane(Plane p) {
  const char* name = "UNKNOWN";
  switch (p) {
    case Plane::XY: name = "XY"; break;
    case Plane::YZ: name = "YZ"; break;
    case Plane::XZ: name = "XZ"; break;
    default: break;
  }
  prefix();
  buf_.append("SELECT_PLANE(CANON_PLANE_");
  buf_.append(name);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_feed_reference(FeedReference r) {
  simple(r == FeedReference::Workpiece ? "SET_FEED_REFERENCE(CANON_WORKPIECE)" : "SET_FEED_REFERENCE(CANON_XYZ)");
}

void Rs274Printer::arc_feed(SegmentId, const ArcFeed& arc) {
  prefix();
  buf_.append("ARC_FEED(");
  num(arc.first_end);
  buf_.append(", ");
  num(arc.second_end);
  buf_.append(", ");
  num(arc.first_center);
  buf_.append(", ");
  num(arc.second_center);
  buf_.append(", ");
  integer(arc.rotation);
  buf_.append(", ");
  num(arc.axis_end);
  for (int i = 3; i < 6; ++i) {
    buf_.append(", ");
    num(arc.end[i]);
  }
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::rigid_tap(SegmentId, const Pose& end, double /*scale*/) {
  prefix();
  buf_.append("RIGID_TAP(");
  num(end[0]);
  buf_.append(", ");
  num(end[1]);
  buf_.append(", ");
  num(end[2]);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::nurbs_feed(SegmentId, int /*order*/, std::span<const NurbsPoint> points) {
  // rs274 prints the number of control points, not the order.
  prefix();
  buf_.append("NURBS_FEED(");
  integer(static_cast<int>(points.size()));
  buf_.append(", ...)");
  end_line();
}

void Rs274Printer::dwell(double seconds) {
  prefix();
  buf_.append("DWELL(");
  num(seconds);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_feed_rate(double rate) {
  prefix();
  buf_.append("SET_FEED_RATE(");
  num(rate);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_feed_mode(int spindle, FeedMode mode) {
  // LinuxCNC's canon knows two modes: 0 = per minute (G93 and G94 alike), 1 = per revolution.
  prefix();
  buf_.append("SET_FEED_MODE(");
  integer(spindle);
  buf_.append(", ");
  integer(mode == FeedMode::UnitsPerRevolution ? 1 : 0);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_motion_control_mode(MotionControl mode, double tolerance) {
  switch (mode) {
    case MotionControl::ExactStop: simple("SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)"); return;
    case MotionControl::ExactPath: simple("SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)"); return;
    case MotionControl::Continuous: break;
  }
  prefix();
  buf_.append("SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, ");
  num(tolerance, 6);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_naivecam_tolerance(double tolerance) {
  prefix();
  buf_.append("SET_NAIVECAM_TOLERANCE(");
  num(tolerance);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::start_speed_feed_synch(int /*spindle*/, double feed_per_rev, bool velocity_mode) {
  prefix();
  buf_.append("START_SPEED_FEED_SYNC(");
  num(feed_per_rev, 6);
  buf_.push_back(',');
  integer(velocity_mode ? 1 : 0);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_spindle_speed(int spindle, double rpm) {
  prefix();
  buf_.append("SET_SPINDLE_SPEED(");
  integer(spindle);
  buf_.append(", ");
  num(rpm);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_spindle_mode(int spindle, double css_max) {
  prefix();
  buf_.append("SET_SPINDLE_MODE(");
  integer(spindle);
  buf_.push_back(' ');
  num(css_max);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::orient_spindle(int spindle, double degrees, int direction) {
  prefix();
  buf_.append("ORIENT_SPINDLE(");
  integer(spindle);
  buf_.append(", ");
  num(degrees);
  buf_.append(", ");
  integer(direction);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::wait_spindle_orient_complete(int spindle, double timeout_s) {
  prefix();
  buf_.append("SPINDLE.");
  integer(spindle);
  buf_.append(".WAIT_ORIENT_COMPLETE(");
  num(timeout_s);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::use_tool_length_offset(const Pose& offset) {
  prefix();
  buf_.append("USE_TOOL_LENGTH_OFFSET(");
  for (int i = 0; i < 9; ++i) {
    if (i > 0) buf_.append(i % 3 == 0 ? ", " : " ");
    num(offset[i]);
  }
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_motion_output_value(int index, double value) {
  prefix();
  buf_.append("SET_MOTION_OUTPUT_VALUE(");
  integer(index);
  buf_.push_back(',');
  num(value, 6);
  buf_.push_back(')');
  end_line();
}

// Not a call of LinuxCNC's canon (it has no coupling): printed in its style, law, table, pitch, rate.
void Rs274Printer::set_axis_coupling(const AxisCoupling& c) {
  prefix();
  buf_.append("SET_AXIS_COUPLING(");
  integer(c.law);
  buf_.push_back(',');
  integer(c.table);
  buf_.push_back(',');
  num(c.pitch, 6);
  buf_.push_back(',');
  num(c.rate, 6);
  buf_.push_back(')');
  end_line();
}

// Not a call of LinuxCNC's canon either: the code and its words, in its style.
void Rs274Printer::process_code(const ProcessCode& c) {
  prefix();
  buf_.append("PROCESS_CODE(");
  integer(c.code);
  buf_.push_back(',');
  num(c.p, 6);
  buf_.push_back(',');
  num(c.q, 6);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::set_aux_output_value(int index, double value) {
  prefix();
  buf_.append("SET_AUX_OUTPUT_VALUE(");
  integer(index);
  buf_.push_back(',');
  num(value, 6);
  buf_.push_back(')');
  end_line();
}

void Rs274Printer::print(std::string_view text) {
  // rs274 prints (PRINT,...) text as a plain line, outside the numbered stream.
  if (print_stream_ == nullptr) return;
  if (print_stream_ == out_) {
    buf_.append(text);
    end_line();
    return;
  }
  flush();
  std::fwrite(text.data(), 1, text.size(), print_stream_);
  std::fputc('\n', print_stream_);
}

void Rs274Printer::set_tool_table_entry(int index, int tool, const Pose& offset, double /*diameter*/,
                                        double front_angle, double back_angle, int orientation) {
  // rs274 leaves the diameter out of this line.
  prefix();
  buf_.append("SET_TOOL_TABLE_ENTRY(");
  integer(index);
  buf_.append(", ");
  integer(tool);
  buf_.append(", ");
  for (int i = 0; i < 9; ++i) {
    if (i > 0) buf_.push_back(' ');
    num(offset[i]);
  }
  buf_.append(", ");
  num(front_angle);
  buf_.append(", ");
  num(back_angle);
  buf_.append(", ");
  integer(orientation);
  buf_.push_back(')');
  end_line();
}

}  // namespace opencnc::canon
