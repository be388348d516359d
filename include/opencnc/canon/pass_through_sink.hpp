// SPDX-License-Identifier: GPL-3.0-or-later
// PassThroughSink — forwards every canonical call to the next sink: the base of a filter that
// handles a few calls itself (a feature's pass over the calls before the builder).
#pragma once

#include "opencnc/canon/sink.hpp"

namespace opencnc::canon {

/// Forwards each call to `next`, after `before_call()` (a filter hands on what it holds there).
/// A filter overrides the calls it handles. Same thread and real-time rules as the sink it wraps.
class PassThroughSink : public Sink {
 public:
  explicit PassThroughSink(Sink* next = nullptr) : next_(next) {}
  /// The sink calls go to from now on.
  void set_next(Sink& next) noexcept { next_ = &next; }

  void begin_block(const BlockOrigin& origin) override {
    before_call();
    next_->begin_block(origin);
  }
  void use_length_units(Units units) override {
    before_call();
    next_->use_length_units(units);
  }
  void set_g5x_offset(int index, const Pose& offset) override {
    before_call();
    next_->set_g5x_offset(index, offset);
  }
  void set_g92_offset(const Pose& offset) override {
    before_call();
    next_->set_g92_offset(offset);
  }
  void set_xy_rotation(double degrees) override {
    before_call();
    next_->set_xy_rotation(degrees);
  }
  void select_plane(Plane plane) override {
    before_call();
    next_->select_plane(plane);
  }
  void set_feed_reference(FeedReference reference) override {
    before_call();
    next_->set_feed_reference(reference);
  }
  void straight_traverse(SegmentId id, const Pose& end) override {
    before_call();
    next_->straight_traverse(id, end);
  }
  void straight_feed(SegmentId id, const Pose& end) override {
    before_call();
    next_->straight_feed(id, end);
  }
  void arc_feed(SegmentId id, const ArcFeed& arc) override {
    before_call();
    next_->arc_feed(id, arc);
  }
  void straight_probe(SegmentId id, const Pose& end) override {
    before_call();
    next_->straight_probe(id, end);
  }
  void rigid_tap(SegmentId id, const Pose& end, double scale) override {
    before_call();
    next_->rigid_tap(id, end, scale);
  }
  void nurbs_feed(SegmentId id, int order, std::span<const NurbsPoint> control_points) override {
    before_call();
    next_->nurbs_feed(id, order, control_points);
  }
  void dwell(double seconds) override {
    before_call();
    next_->dwell(seconds);
  }
  void set_feed_rate(double units_per_min_or_rev_or_inverse_time) override {
    before_call();
    next_->set_feed_rate(units_per_min_or_rev_or_inverse_time);
  }
  void set_feed_mode(int spindle, FeedMode mode) override {
    before_call();
    next_->set_feed_mode(spindle, mode);
  }
  void set_motion_control_mode(MotionControl mode, double tolerance) override {
    before_call();
    next_->set_motion_control_mode(mode, tolerance);
  }
  void set_naivecam_tolerance(double tolerance) override {
    before_call();
    next_->set_naivecam_tolerance(tolerance);
  }
  void start_speed_feed_synch(int spindle, double feed_per_rev, bool velocity_mode) override {
    before_call();
    next_->start_speed_feed_synch(spindle, feed_per_rev, velocity_mode);
  }
  void stop_speed_feed_synch() override {
    before_call();
    next_->stop_speed_feed_synch();
  }
  void set_spindle_speed(int spindle, double rpm_or_surface_speed) override {
    before_call();
    next_->set_spindle_speed(spindle, rpm_or_surface_speed);
  }
  void start_spindle_clockwise(int spindle) override {
    before_call();
    next_->start_spindle_clockwise(spindle);
  }
  void start_spindle_counterclockwise(int spindle) override {
    before_call();
    next_->start_spindle_counterclockwise(spindle);
  }
  void stop_spindle_turning(int spindle) override {
    before_call();
    next_->stop_spindle_turning(spindle);
  }
  void set_spindle_mode(int spindle, double css_max) override {
    before_call();
    next_->set_spindle_mode(spindle, css_max);
  }
  void orient_spindle(int spindle, double degrees, int direction) override {
    before_call();
    next_->orient_spindle(spindle, degrees, direction);
  }
  void wait_spindle_orient_complete(int spindle, double timeout_s) override {
    before_call();
    next_->wait_spindle_orient_complete(spindle, timeout_s);
  }
  void select_tool(int tool) override {
    before_call();
    next_->select_tool(tool);
  }
  void start_change() override {
    before_call();
    next_->start_change();
  }
  void change_tool(int tool) override {
    before_call();
    next_->change_tool(tool);
  }
  void change_tool_number(int tool) override {
    before_call();
    next_->change_tool_number(tool);
  }
  void use_tool_length_offset(const Pose& offset) override {
    before_call();
    next_->use_tool_length_offset(offset);
  }
  void set_tool_table_entry(int index, int tool, const Pose& offset, double diameter, double front_angle,
                            double back_angle, int orientation) override {
    before_call();
    next_->set_tool_table_entry(index, tool, offset, diameter, front_angle, back_angle, orientation);
  }
  void mist_on() override {
    before_call();
    next_->mist_on();
  }
  void mist_off() override {
    before_call();
    next_->mist_off();
  }
  void flood_on() override {
    before_call();
    next_->flood_on();
  }
  void flood_off() override {
    before_call();
    next_->flood_off();
  }
  void enable_feed_override() override {
    before_call();
    next_->enable_feed_override();
  }
  void disable_feed_override() override {
    before_call();
    next_->disable_feed_override();
  }
  void enable_speed_override(int spindle) override {
    before_call();
    next_->enable_speed_override(spindle);
  }
  void disable_speed_override(int spindle) override {
    before_call();
    next_->disable_speed_override(spindle);
  }
  void enable_adaptive_feed() override {
    before_call();
    next_->enable_adaptive_feed();
  }
  void disable_adaptive_feed() override {
    before_call();
    next_->disable_adaptive_feed();
  }
  void enable_feed_hold() override {
    before_call();
    next_->enable_feed_hold();
  }
  void disable_feed_hold() override {
    before_call();
    next_->disable_feed_hold();
  }
  void set_motion_output_bit(int index) override {
    before_call();
    next_->set_motion_output_bit(index);
  }
  void clear_motion_output_bit(int index) override {
    before_call();
    next_->clear_motion_output_bit(index);
  }
  void set_aux_output_bit(int index) override {
    before_call();
    next_->set_aux_output_bit(index);
  }
  void clear_aux_output_bit(int index) override {
    before_call();
    next_->clear_aux_output_bit(index);
  }
  void set_motion_output_value(int index, double value) override {
    before_call();
    next_->set_motion_output_value(index, value);
  }
  void set_axis_coupling(const AxisCoupling& c) override {
    before_call();
    next_->set_axis_coupling(c);
  }
  void process_code(const ProcessCode& c) override {
    before_call();
    next_->process_code(c);
  }
  void set_aux_output_value(int index, double value) override {
    before_call();
    next_->set_aux_output_value(index, value);
  }
  void wait_for_input(int index, bool digital, int mode, double timeout_s) override {
    before_call();
    next_->wait_for_input(index, digital, mode, timeout_s);
  }
  void turn_probe_on() override {
    before_call();
    next_->turn_probe_on();
  }
  void turn_probe_off() override {
    before_call();
    next_->turn_probe_off();
  }
  void comment(std::string_view text) override {
    before_call();
    next_->comment(text);
  }
  void message(std::string_view text) override {
    before_call();
    next_->message(text);
  }
  void print(std::string_view text) override {
    before_call();
    next_->print(text);
  }
  void log_open(std::string_view file) override {
    before_call();
    next_->log_open(file);
  }
  void log_append(std::string_view file) override {
    before_call();
    next_->log_append(file);
  }
  void log_close() override {
    before_call();
    next_->log_close();
  }
  void log(std::string_view text) override {
    before_call();
    next_->log(text);
  }
  void program_stop() override {
    before_call();
    next_->program_stop();
  }
  void optional_program_stop() override {
    before_call();
    next_->optional_program_stop();
  }
  void pallet_shuttle() override {
    before_call();
    next_->pallet_shuttle();
  }
  void program_end() override {
    before_call();
    next_->program_end();
  }
  void finish() override {
    before_call();
    next_->finish();
  }
  void on_reset() override {
    before_call();
    next_->on_reset();
  }

 protected:
  /// Called before a call is forwarded (default: nothing).
  virtual void before_call() {}
  Sink* next_;
};

}  // namespace opencnc::canon
