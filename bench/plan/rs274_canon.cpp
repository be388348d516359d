// SPDX-License-Identifier: GPL-3.0-or-later
// `rs274 -g` listing → canonical calls (measurement tool; 4-decimal numbers as rs274 prints them).
#include "rs274_canon.hpp"

#include <cstdlib>
#include <string_view>
#include <vector>

#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::bench {

namespace {

/// The call name and its arguments, split on top-level commas (quoted text kept whole).
bool split_call(std::string_view line, std::string_view& name, std::vector<std::string_view>& args) {
  // "   12 N0040  STRAIGHT_FEED(1.0000, ...)": skip the counter and the N field.
  std::size_t p = line.find_first_not_of(' ');
  if (p == std::string_view::npos) return false;
  p = line.find(' ', p);  // after the counter
  if (p == std::string_view::npos) return false;
  p = line.find_first_not_of(' ', p);
  if (p == std::string_view::npos || line[p] != 'N') return false;
  p = line.find(' ', p);  // after the N field
  p = line.find_first_not_of(' ', p);
  const std::size_t open = line.find('(', p);
  if (p == std::string_view::npos || open == std::string_view::npos) return false;
  name = line.substr(p, open - p);
  args.clear();
  bool quoted = false;
  std::size_t start = open + 1;
  for (std::size_t i = open + 1; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    if (c == ',' || c == ')') {
      std::string_view a = line.substr(start, i - start);
      while (!a.empty() && a.front() == ' ') a.remove_prefix(1);
      if (!a.empty() || c == ',') args.push_back(a);
      start = i + 1;
      if (c == ')') break;
    }
  }
  return true;
}

double num(std::string_view s) {
  return std::strtod(std::string(s).c_str(), nullptr);
}

Pose pose6(const std::vector<std::string_view>& a, std::size_t first) {
  Pose p;
  for (int i = 0; i < 6 && first + static_cast<std::size_t>(i) < a.size(); ++i)
    p[i] = num(a[first + static_cast<std::size_t>(i)]);
  return p;
}

canon::Plane plane_of(std::string_view s) {
  if (s.find("YZ") != std::string_view::npos) return canon::Plane::YZ;
  if (s.find("XZ") != std::string_view::npos) return canon::Plane::XZ;
  return canon::Plane::XY;
}

}  // namespace

std::size_t read_rs274_listing(std::istream& in, canon::Sink& sink) {
  std::string line;
  std::vector<std::string_view> a;
  std::string_view name;
  canon::SegmentId id = 0;
  canon::Plane plane = canon::Plane::XY;
  std::uint32_t number = 0;
  while (std::getline(in, line)) {
    if (!split_call(line, name, a)) continue;
    canon::BlockOrigin origin;
    origin.line = ++number;  // listing line: rs274 prints N numbers only when the program has them
    sink.begin_block(origin);
    if (name == "STRAIGHT_FEED") {
      sink.straight_feed(id++, pose6(a, 0));
    } else if (name == "STRAIGHT_TRAVERSE") {
      sink.straight_traverse(id++, pose6(a, 0));
    } else if (name == "STRAIGHT_PROBE") {
      sink.straight_probe(id++, pose6(a, 0));
    } else if (name == "ARC_FEED" && a.size() >= 9) {
      canon::ArcFeed arc;
      arc.plane = plane;
      arc.first_end = num(a[0]);
      arc.second_end = num(a[1]);
      arc.first_center = num(a[2]);
      arc.second_center = num(a[3]);
      arc.rotation = static_cast<int>(num(a[4]));
      arc.axis_end = num(a[5]);
      const canon::PlaneAxes axes = canon::plane_axes(plane);  // rs274 prints the XYZ planes only
      arc.end[axes.first] = arc.first_end;
      arc.end[axes.second] = arc.second_end;
      arc.end[axes.normal] = arc.axis_end;
      for (int i = 0; i < 3; ++i) arc.end[3 + i] = num(a[6 + static_cast<std::size_t>(i)]);
      sink.arc_feed(id++, arc);
    } else if (name == "SELECT_PLANE" && !a.empty()) {
      plane = plane_of(a[0]);
      sink.select_plane(plane);
    } else if (name == "USE_LENGTH_UNITS" && !a.empty()) {
      sink.use_length_units(a[0].find("INCH") != std::string_view::npos ? canon::Units::Inch
                                                                        : canon::Units::Mm);
    } else if (name == "SET_G5X_OFFSET" && a.size() >= 7) {
      sink.set_g5x_offset(static_cast<int>(num(a[0])), pose6(a, 1));
    } else if (name == "SET_G92_OFFSET" && a.size() >= 6) {
      sink.set_g92_offset(pose6(a, 0));
    } else if (name == "SET_XY_ROTATION" && !a.empty()) {
      sink.set_xy_rotation(num(a[0]));
    } else if (name == "SET_FEED_RATE" && !a.empty()) {
      sink.set_feed_rate(num(a[0]));
    } else if (name == "SET_FEED_MODE" && a.size() >= 2) {
      sink.set_feed_mode(
          0, num(a[1]) != 0 ? canon::FeedMode::UnitsPerRevolution : canon::FeedMode::UnitsPerMinute);
    } else if (name == "SET_MOTION_CONTROL_MODE" && !a.empty()) {  // the tolerance only with G64
      const canon::MotionControl m =
          a[0].find("EXACT_STOP") != std::string_view::npos   ? canon::MotionControl::ExactStop
          : a[0].find("EXACT_PATH") != std::string_view::npos ? canon::MotionControl::ExactPath
                                                              : canon::MotionControl::Continuous;
      sink.set_motion_control_mode(m, a.size() > 1 ? num(a[1]) : 0.0);
    } else if (name == "SET_NAIVECAM_TOLERANCE" && !a.empty()) {
      sink.set_naivecam_tolerance(num(a[0]));
    } else if (name == "START_SPEED_FEED_SYNC" && a.size() >= 2) {
      sink.start_speed_feed_synch(0, num(a[0]), num(a[1]) != 0);
    } else if (name == "STOP_SPEED_FEED_SYNCH") {
      sink.stop_speed_feed_synch();
    } else if (name == "DWELL" && !a.empty()) {
      sink.dwell(num(a[0]));
    } else if (name == "SET_SPINDLE_SPEED" && a.size() >= 2) {
      sink.set_spindle_speed(0, num(a[1]));
    } else if (name == "START_SPINDLE_CLOCKWISE") {
      sink.start_spindle_clockwise(0);
    } else if (name == "START_SPINDLE_COUNTERCLOCKWISE") {
      sink.start_spindle_counterclockwise(0);
    } else if (name == "STOP_SPINDLE_TURNING") {
      sink.stop_spindle_turning(0);
    } else if (name == "CHANGE_TOOL" && !a.empty()) {
      sink.change_tool(static_cast<int>(num(a[0])));
    } else if (name == "SELECT_TOOL" && !a.empty()) {
      sink.select_tool(static_cast<int>(num(a[0])));
    } else if (name == "ENABLE_FEED_OVERRIDE") {
      sink.enable_feed_override();
    } else if (name == "DISABLE_FEED_OVERRIDE") {
      sink.disable_feed_override();
    } else if (name == "FLOOD_ON") {
      sink.flood_on();
    } else if (name == "FLOOD_OFF") {
      sink.flood_off();
    } else if (name == "MIST_ON") {
      sink.mist_on();
    } else if (name == "MIST_OFF") {
      sink.mist_off();
    } else if (name == "PROGRAM_STOP") {
      sink.program_stop();
    } else if (name == "OPTIONAL_PROGRAM_STOP") {
      sink.optional_program_stop();
    } else if (name == "PALLET_SHUTTLE") {
      sink.pallet_shuttle();
    } else if (name == "PROGRAM_END") {
      sink.program_end();
    }
  }
  return id;
}

}  // namespace opencnc::bench
