// SPDX-License-Identifier: GPL-3.0-or-later
// TeeSink — forwards every canonical call to two sinks (e.g. a program builder and a printer).
#pragma once

#include "opencnc/canon/sink.hpp"

namespace opencnc::canon {

/// Forwards each call to `a` then `b`. Same thread and real-time rules as the sinks it wraps.
class TeeSink final : public Sink {
 public:
  TeeSink(Sink& a, Sink& b) : a_(a), b_(b) {}

  void begin_block(const BlockOrigin& origin) override {
    a_.begin_block(origin);
    b_.begin_block(origin);
  }
  void use_length_units(Units units) override {
    a_.use_length_units(units);
    b_.use_length_units(units);
  }
  void set_g5x_offset(int index, const Pose& offset) override {
    a_.set_g5x_offset(index, offset);
    b_.set_g5x_offset(index, offset);
  }
  void set_g92_offset(const Pose& offset) override {
    a_.set_g92_offset(offset);
    b_.set_g92_offset(offset);
  }
  void set_xy_rotation(double degrees) override {
    a_.set_xy_rotation(degrees);
    b_.set_xy_rotation(degrees);
  }
  void select_plane(Plane plane) override {
    a_.select_plane(plane);
    b_.select_plane(plane);
  }
  void set_feed_reference(FeedReference reference) override {
    a_.set_feed_reference(reference);
    b_.set_feed_reference(reference);
  }
  void straight_traverse(SegmentId id, const Pose& end) override {
    a_.straight_traverse(id, end);
    b_.straight_traverse(id, end);
  }
  void straight_feed(SegmentId id, const Pose& end) override {
    a_.straight_feed(id, end);
    b_.straight_feed(id, end);
  }
  void arc_feed(SegmentId id, const ArcFeed& arc) override {
    a_.arc_feed(id, arc);
    b_.arc_feed(id, arc);
  }
  void straight_probe(SegmentId id, const Pose& end) override {
    a_.straight_probe(id, end);
    b_.straight_probe(id, end);
  }
  void rigid_tap(SegmentId id, const Pose& end, double scale) override {
    a_.rigid_tap(id, end, scale);
    b_.rigid_tap(id, end, scale);
  }
  void nurbs_feed(SegmentId id, int order, std::span<const NurbsPoint> control_points) override {
    a_.nurbs_feed(id, order, control_points);
    b_.nurbs_feed(id, order, control_points);
  }
  void dwell(double seconds) override {
    a_.dwell(seconds);
    b_.dwell(seconds);
  }
  void set_feed_rate(double units_per_min_or_rev_or_inverse_time) override {
    a_.set_feed_rate(units_per_min_or_rev_or_inverse_time);
    b_.set_feed_rate(units_per_min_or_rev_or_inverse_time);
  }
  void set_feed_mode(int spindle, FeedMode mode) override {
    a_.set_feed_mode(spindle, mode);
    b_.set_feed_mode(spindle, mode);
  }
  void set_motion_control_mode(MotionControl mode, double tolerance) override {
    a_.set_motion_control_mode(mode, tolerance);
    b_.set_motion_control_mode(mode, tolerance);
  }
  void set_naivecam_tolerance(double tolerance) override {
    a_.set_naivecam_tolerance(tolerance);
    b_.set_naivecam_tolerance(tolerance);
  }
  void start_speed_feed_synch(int spindle, double feed_per_rev, bool velocity_mode) override {
    a_.start_speed_feed_synch(spindle, feed_per_rev, velocity_mode);
    b_.start_speed_feed_synch(spindle, feed_per_rev, velocity_mode);
  }
  void stop_speed_feed_synch() override {
    a_.stop_speed_feed_synch();
    b_.stop_speed_feed_synch();
  }
  void set_spindle_speed(int spindle, double rpm_or_surface_speed) override {
    a_.set_spindle_speed(spindle, rpm_or_surface_speed);
    b_.set_spindle_speed(spindle, rpm_or_surface_speed);
  }
  void start_spindle_clockwise(int spindle) override {
    a_.start_spindle_clockwise(spindle);
    b_.start_spindle_clockwise(spindle);
  }
  void start_spindle_counterclockwise(int spindle) override {
    a_.start_spindle_counterclockwise(spindle);
    b_.start_spindle_counterclockwise(spindle);
  }
  void stop_spindle_turning(int spindle) override {
    a_.stop_spindle_turning(spindle);
    b_.stop_spindle_turning(spindle);
  }
  void set_spindle_mode(int spindle, double css_max) override {
    a_.set_spindle_mode(spindle, css_max);
    b_.set_spindle_mode(spindle, css_max);
  }
  void orient_spindle(int spindle, double degrees, int direction) override {
    a_.orient_spindle(spindle, degrees, direction);
    b_.orient_spindle(spindle, degrees, direction);
  }
  void wait_spindle_orient_complete(int spindle, double timeout_s) override {
    a_.wait_spindle_orient_complete(spindle, timeout_s);
    b_.wait_spindle_orient_complete(spindle, timeout_s);
  }
  void select_tool(int tool) override {
    a_.select_tool(tool);
    b_.select_tool(tool);
  }
  void start_change() override {
    a_.start_change();
    b_.start_change();
  }
  void change_tool(int tool) override {
    a_.change_tool(tool);
    b_.change_tool(tool);
  }
  void change_tool_number(int tool) override {
    a_.change_tool_number(tool);
    b_.change_tool_number(tool);
  }
  void use_tool_length_offset(const Pose& offset) override {
    a_.use_tool_length_offset(offset);
    b_.use_tool_length_offset(offset);
  }
  void set_tool_table_entry(int index, int tool, const Pose& offset, double diameter, double front_angle, double back_angle, int orientation) override {
    a_.set_tool_table_entry(index, tool, offset, diameter, front_angle, back_angle, orientation);
    b_.set_tool_table_entry(index, tool, offset, diameter, front_angle, back_angle, orientation);
  }
  void mist_on() override {
    a_.mist_on();
    b_.mist_on();
  }
  void mist_off() override {
    a_.mist_off();
    b_.mist_off();
  }
  void flood_on() override {
    a_.flood_on();
    b_.flood_on();
  }
  void flood_off() override {
    a_.flood_off();
    b_.flood_off();
  }
  void enable_feed_override() override {
    a_.enable_feed_override();
    b_.enable_feed_override();
  }
  void disable_feed_override() override {
    a_.disable_feed_override();
    b_.disable_feed_override();
  }
  void enable_speed_override(int spindle) override {
    a_.enable_speed_override(spindle);
    b_.enable_speed_override(spindle);
  }
  void disable_speed_override(int spindle) override {
    a_.disable_speed_override(spindle);
    b_.disable_speed_override(spindle);
  }
  void enable_adaptive_feed() override {
    a_.enable_adaptive_feed();
    b_.enable_adaptive_feed();
  }
  void disable_adaptive_feed() override {
    a_.disable_adaptive_feed();
    b_.disable_adaptive_feed();
  }
  void enable_feed_hold() override {
    a_.enable_feed_hold();
    b_.enable_feed_hold();
  }
  void disable_feed_hold() override {
    a_.disable_feed_hold();
    b_.disable_feed_hold();
  }
  void set_motion_output_bit(int index) override {
    a_.set_motion_output_bit(index);
    b_.set_motion_output_bit(index);
  }
  void clear_motion_output_bit(int index) override {
    a_.clear_motion_output_bit(index);
    b_.clear_motion_output_bit(index);
  }
  void set_aux_output_bit(int index) override {
    a_.set_aux_output_bit(index);
    b_.set_aux_output_bit(index);
  }
  void clear_aux_output_bit(int index) override {
    a_.clear_aux_output_bit(index);
    b_.clear_aux_output_bit(index);
  }
  void set_motion_output_value(int index, double value) override {
    a_.set_motion_output_value(index, value);
    b_.set_motion_output_value(index, value);
  }
  void set_axis_coupling(const AxisCoupling& c) override {
    a_.set_axis_coupling(c);
    b_.set_axis_coupling(c);
  }
  void process_code(const ProcessCode& c) override {
    a_.process_code(c);
    b_.process_code(c);
  }
  void set_aux_output_value(int index, double value) override {
    a_.set_aux_output_value(index, value);
    b_.set_aux_output_value(index, value);
  }
  void wait_for_input(int index, bool digital, int mode, double timeout_s) override {
    a_.wait_for_input(index, digital, mode, timeout_s);
    b_.wait_for_input(index, digital, mode, timeout_s);
  }
  void turn_probe_on() override {
    a_.turn_probe_on();
    b_.turn_probe_on();
  }
  void turn_probe_off() override {
    a_.turn_probe_off();
    b_.turn_probe_off();
  }
  void comment(std::string_view text) override {
    a_.comment(text);
    b_.comment(text);
  }
  void message(std::string_view text) override {
    a_.message(text);
    b_.message(text);
  }
  void print(std::string_view text) override {
    a_.print(text);
    b_.print(text);
  }
  void log_open(std::string_view file) override {
    a_.log_open(file);
    b_.log_open(file);
  }
  void log_append(std::string_view file) override {
    a_.log_append(file);
    b_.log_append(file);
  }
  void log_close() override {
    a_.log_close();
    b_.log_close();
  }
  void log(std::string_view text) override {
    a_.log(text);
    b_.log(text);
  }
  void program_stop() override {
    a_.program_stop();
    b_.program_stop();
  }
  void optional_program_stop() override {
    a_.optional_program_stop();
    b_.optional_program_stop();
  }
  void pallet_shuttle() override {
    a_.pallet_shuttle();
    b_.pallet_shuttle();
  }
  void program_end() override {
    a_.program_end();
    b_.program_end();
  }
  void finish() override {
    a_.finish();
    b_.finish();
  }
  void on_reset() override {
    a_.on_reset();
    b_.on_reset();
  }

 private:
  Sink& a_;
  Sink& b_;
};

}  // namespace opencnc::canon
