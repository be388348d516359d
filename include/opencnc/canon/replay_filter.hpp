// SPDX-License-Identifier: GPL-3.0-or-later
// ReplayFilter — the canonical calls of a program resumed at segment k: before it, only what
// sets the builder's state (units, offsets, rotation, plane, feed, path control, override
// switches) passes; motions and the machine's actions are held back, the last spindle, coolant,
// output states, modal process codes and axis coupling noted and restored just before segment k
// runs. Non-real-time; one thread.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "opencnc/canon/sink.hpp"

namespace opencnc::canon {

class ReplayFilter final : public Sink {
 public:
  /// Forwards to `next` from segment `first` on.
  ReplayFilter(Sink& next, SegmentId first) : next_(&next), first_(first) {}
  /// The sink to forward to from now on (the stream's pipeline changes with a new leg).
  void set_next(Sink& next) noexcept { next_ = &next; }

  /// Whether segment `first` has been reached (everything passes from then on).
  bool live() const noexcept { return live_; }

  void begin_block(const BlockOrigin& o) override { next_->begin_block(o); }
  void use_length_units(Units u) override { next_->use_length_units(u); }
  void set_g5x_offset(int index, const Pose& offset) override { next_->set_g5x_offset(index, offset); }
  void set_g92_offset(const Pose& offset) override { next_->set_g92_offset(offset); }
  void set_xy_rotation(double degrees) override { next_->set_xy_rotation(degrees); }
  void select_plane(Plane p) override { next_->select_plane(p); }
  void set_feed_reference(FeedReference r) override { next_->set_feed_reference(r); }

  void straight_traverse(SegmentId id, const Pose& end) override {
    if (motion(id, &end)) next_->straight_traverse(id, end);
  }
  void straight_feed(SegmentId id, const Pose& end) override {
    if (motion(id, &end)) next_->straight_feed(id, end);
  }
  void arc_feed(SegmentId id, const ArcFeed& arc) override {
    if (motion(id, &arc.end)) next_->arc_feed(id, arc);
  }
  void straight_probe(SegmentId id, const Pose& end) override {
    if (motion(id, &end)) next_->straight_probe(id, end);
  }
  void rigid_tap(SegmentId id, const Pose& end, double scale) override {
    // The tap returns to where it started: the path stands at its start again.
    if (motion(id, nullptr)) next_->rigid_tap(id, end, scale);
  }
  void nurbs_feed(SegmentId id, int order, std::span<const NurbsPoint> points) override {
    if (motion(id, nullptr, true)) next_->nurbs_feed(id, order, points);
  }
  /// The coupling codes before segment k: the one that holds at k passes just before it with the
  /// origin it had (where the path stood: the end of the motion before it), so the resumed run's
  /// law is the original one, not one engaged where the machine stands now.
  void set_axis_coupling(const AxisCoupling& c) override;
  /// A modal process code (group ≠ 0) before segment k is held, the last of each group passed
  /// just before k (an EDM condition and the generator on, or off); one-shot codes are dropped.
  void process_code(const ProcessCode& c) override;
  void dwell(double s) override {
    if (live_) next_->dwell(s);
  }

  void set_feed_rate(double f) override { next_->set_feed_rate(f); }
  void set_feed_mode(int spindle, FeedMode m) override { next_->set_feed_mode(spindle, m); }
  void set_motion_control_mode(MotionControl m, double t) override { next_->set_motion_control_mode(m, t); }
  void set_naivecam_tolerance(double t) override { next_->set_naivecam_tolerance(t); }
  void start_speed_feed_synch(int spindle, double fpr, bool velocity) override {
    next_->start_speed_feed_synch(spindle, fpr, velocity);
  }
  void stop_speed_feed_synch() override { next_->stop_speed_feed_synch(); }

  void set_spindle_speed(int spindle, double rpm) override;
  void start_spindle_clockwise(int spindle) override;
  void start_spindle_counterclockwise(int spindle) override;
  void stop_spindle_turning(int spindle) override;
  void set_spindle_mode(int spindle, double css_max) override { next_->set_spindle_mode(spindle, css_max); }
  void orient_spindle(int spindle, double degrees, int direction) override {
    if (live_) next_->orient_spindle(spindle, degrees, direction);
  }
  void wait_spindle_orient_complete(int spindle, double timeout_s) override {
    if (live_) next_->wait_spindle_orient_complete(spindle, timeout_s);
  }

  // The tool in the spindle is the one the program had changed to: no change is repeated.
  void select_tool(int tool) override {
    if (live_) next_->select_tool(tool);
  }
  void start_change() override {
    if (live_) next_->start_change();
  }
  void change_tool(int tool) override {
    if (live_) next_->change_tool(tool);
  }
  void change_tool_number(int tool) override {
    if (live_) next_->change_tool_number(tool);
  }
  void use_tool_length_offset(const Pose& offset) override { next_->use_tool_length_offset(offset); }
  // G10 L1 before the segment was written to the table when the program ran it.
  void set_tool_table_entry(int index, int tool, const Pose& offset, double diameter, double front,
                            double back, int orientation) override {
    if (live_) next_->set_tool_table_entry(index, tool, offset, diameter, front, back, orientation);
  }

  void mist_on() override { coolant(mist_, true, &Sink::mist_on); }
  void mist_off() override { coolant(mist_, false, &Sink::mist_off); }
  void flood_on() override { coolant(flood_, true, &Sink::flood_on); }
  void flood_off() override { coolant(flood_, false, &Sink::flood_off); }

  void enable_feed_override() override { next_->enable_feed_override(); }
  void disable_feed_override() override { next_->disable_feed_override(); }
  void enable_speed_override(int spindle) override { next_->enable_speed_override(spindle); }
  void disable_speed_override(int spindle) override { next_->disable_speed_override(spindle); }
  void enable_adaptive_feed() override { next_->enable_adaptive_feed(); }
  void disable_adaptive_feed() override { next_->disable_adaptive_feed(); }
  void enable_feed_hold() override { next_->enable_feed_hold(); }
  void disable_feed_hold() override { next_->disable_feed_hold(); }

  void set_motion_output_bit(int index) override { output(index, 1, true); }
  void clear_motion_output_bit(int index) override { output(index, 0, true); }
  void set_aux_output_bit(int index) override { output(index, 1, false); }
  void clear_aux_output_bit(int index) override { output(index, 0, false); }
  void set_motion_output_value(int index, double v) override {
    if (live_) return next_->set_motion_output_value(index, v);
    analog_[index] = v;
  }
  void set_aux_output_value(int index, double v) override {
    if (live_) return next_->set_aux_output_value(index, v);
    analog_[index] = v;
  }
  void wait_for_input(int index, bool digital, int mode, double timeout_s) override {
    if (live_) next_->wait_for_input(index, digital, mode, timeout_s);
  }
  void turn_probe_on() override {
    if (live_) next_->turn_probe_on();
  }
  void turn_probe_off() override {
    if (live_) next_->turn_probe_off();
  }
  void comment(std::string_view t) override {
    if (live_) next_->comment(t);
  }
  void message(std::string_view t) override {
    if (live_) next_->message(t);
  }
  void print(std::string_view t) override {
    if (live_) next_->print(t);
  }
  void log_open(std::string_view f) override {
    if (live_) next_->log_open(f);
  }
  void log_append(std::string_view f) override {
    if (live_) next_->log_append(f);
  }
  void log_close() override {
    if (live_) next_->log_close();
  }
  void log(std::string_view t) override {
    if (live_) next_->log(t);
  }
  void program_stop() override {
    if (live_) next_->program_stop();
  }
  void optional_program_stop() override {
    if (live_) next_->optional_program_stop();
  }
  void pallet_shuttle() override {
    if (live_) next_->pallet_shuttle();
  }
  void program_end() override { next_->program_end(); }
  void finish() override { next_->finish(); }
  void on_reset() override { next_->on_reset(); }

 private:
  /// Whether a motion passes; the first that does restores the machine's state first.
  bool motion(SegmentId id, const Pose* end, bool end_unknown = false);
  void coolant(int& state, bool on, void (Sink::*call)());
  void output(int index, int value, bool motion);

  Sink* next_;
  SegmentId first_;
  bool live_ = false;
  /// Where the path stands in the replayed part (program coordinates), if known: the end of the
  /// last motion (not after a NURBS, whose end the filter does not compute, nor before the first).
  Pose at_{};
  bool at_known_ = false;
  AxisCoupling coupling_{};           ///< the coupling code that holds (law 0: none)
  std::vector<ProcessCode> process_;  ///< the last code of each modal group, in program order
  // What the replayed part left on (−1: never set, so left as the machine has it).
  struct Spindle {
    double speed = 0;
    bool speed_set = false;
    int direction = -2;  ///< 1 clockwise, −1 counterclockwise, 0 stopped, −2 never set
  };
  std::map<int, Spindle> spindles_;
  int mist_ = -1, flood_ = -1;
  std::map<int, std::pair<int, bool>> digital_;  ///< index → (value, synchronised with motion)
  std::map<int, double> analog_;                 ///< restored as immediate (aux) values
};

}  // namespace opencnc::canon
