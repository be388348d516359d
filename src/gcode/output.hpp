// SPDX-License-Identifier: GPL-3.0-or-later
// Output — the last stage before the caller's sink: block origins, segment ids, the
// canonical-call queue (cutter compensation), coordinate transform and axis mapping.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

/// A canonical sink in front of the caller's sink. The interpreter calls it through the
/// concrete type (no virtual dispatch); extensions call it as a canon::Sink.
/// Interpreter thread only; allocates only for queued calls and texts.
class Output final : public canon::Sink {
 public:
  Output();
  void configure(const Options& options);
  void attach(canon::Sink* sink) noexcept { sink_ = sink; }
  /// Where to keep the canonical view of the position (PositionState::canon_position).
  void track(PositionState* view) noexcept { view_ = view; }
  /// The state the coordinate transform reads (what G68, G51, G51.1 set).
  void transform_state(const InterpState* state) noexcept { state_ = state; }
  /// The block the next calls belong to; announced to the sink before its first call.
  void set_origin(const canon::BlockOrigin& origin) noexcept {
    origin_ = origin;
    announced_ = false;
  }
  const canon::BlockOrigin& origin() const noexcept { return origin_; }
  /// set_origin() for a caller that fills in the fields itself: returns the origin to fill.
  canon::BlockOrigin& new_origin() noexcept {
    announced_ = false;
    return origin_;
  }
  /// Motions emitted so far (the next segment id).
  std::uint64_t segments() const noexcept { return segments_; }

  void open_queue() noexcept { queueing_ = true; }
  void flush_queue();
  std::size_t queued() const noexcept { return queue_.size(); }
  /// Moves the end of every queued motion to (first, second) of `plane` (cutter compensation
  /// settling a corner).
  void move_queued_end(canon::Plane plane, double first, double second) noexcept;

  // --- canon::Sink ----------------------------------------------------------------------
  void begin_block(const canon::BlockOrigin& origin) override { set_origin(origin); }
  void use_length_units(canon::Units u) override;
  void set_g5x_offset(int index, const Pose& offset) override;
  void set_g92_offset(const Pose& offset) override;
  void set_xy_rotation(double degrees) override;
  void select_plane(canon::Plane p) override;
  void set_feed_reference(canon::FeedReference r) override;
  void straight_traverse(canon::SegmentId, const Pose& end) override;
  void straight_feed(canon::SegmentId, const Pose& end) override;
  void arc_feed(canon::SegmentId, const canon::ArcFeed& arc) override;
  void straight_probe(canon::SegmentId, const Pose& end) override;
  void rigid_tap(canon::SegmentId, const Pose& end, double scale) override;
  void nurbs_feed(canon::SegmentId, int order, std::span<const canon::NurbsPoint> points) override;
  void dwell(double seconds) override;
  void set_feed_rate(double rate) override;
  void set_feed_mode(int spindle, canon::FeedMode mode) override;
  void set_motion_control_mode(canon::MotionControl mode, double tolerance) override;
  void set_naivecam_tolerance(double tolerance) override;
  void start_speed_feed_synch(int spindle, double feed_per_rev, bool velocity_mode) override;
  void stop_speed_feed_synch() override;
  void set_spindle_speed(int spindle, double rpm) override;
  void start_spindle_clockwise(int spindle) override;
  void start_spindle_counterclockwise(int spindle) override;
  void stop_spindle_turning(int spindle) override;
  void set_spindle_mode(int spindle, double css_max) override;
  void orient_spindle(int spindle, double degrees, int direction) override;
  void wait_spindle_orient_complete(int spindle, double timeout_s) override;
  void select_tool(int tool) override;
  void start_change() override;
  void change_tool(int tool) override;
  void change_tool_number(int tool) override;
  void use_tool_length_offset(const Pose& offset) override;
  void set_tool_table_entry(int index, int tool, const Pose& offset, double diameter, double front_angle,
                            double back_angle, int orientation) override;
  void mist_on() override;
  void mist_off() override;
  void flood_on() override;
  void flood_off() override;
  void enable_feed_override() override;
  void disable_feed_override() override;
  void enable_speed_override(int spindle) override;
  void disable_speed_override(int spindle) override;
  void enable_adaptive_feed() override;
  void disable_adaptive_feed() override;
  void enable_feed_hold() override;
  void disable_feed_hold() override;
  void set_motion_output_bit(int index) override;
  void clear_motion_output_bit(int index) override;
  void set_aux_output_bit(int index) override;
  void clear_aux_output_bit(int index) override;
  void set_motion_output_value(int index, double value) override;
  void set_aux_output_value(int index, double value) override;
  void set_axis_coupling(const canon::AxisCoupling& coupling) override;
  void process_code(const canon::ProcessCode& code) override;
  void wait_for_input(int index, bool digital, int mode, double timeout_s) override;
  void turn_probe_on() override;
  void turn_probe_off() override;
  void comment(std::string_view text) override;
  void message(std::string_view text) override;
  void print(std::string_view text) override;
  void log_open(std::string_view file) override;
  void log_append(std::string_view file) override;
  void log_close() override;
  void log(std::string_view text) override;
  void program_stop() override;
  void optional_program_stop() override;
  void pallet_shuttle() override;
  void program_end() override;
  void finish() override;
  void on_reset() override;

 private:
  // A recorded canonical call (only the calls LinuxCNC queues during cutter compensation).
  struct Queued {
    enum class Kind : std::uint8_t {
      Traverse, Feed, Arc, Dwell, FeedRate, FeedMode, SpindleSpeed, SpindleCw, SpindleCcw, SpindleStop,
      SpindleMode, Orient, OrientWait, MistOn, MistOff, FloodOn, FloodOff, Comment
    };
    Kind kind = Kind::Comment;
    canon::BlockOrigin origin;
    Pose pose{};
    canon::ArcFeed arc{};
    double value = 0;
    int index = 0;
    int index2 = 0;
    std::string text;
  };

  static Queued queued(Queued::Kind kind) {
    Queued q;
    q.kind = kind;
    return q;
  }
  // Returns the sink to write to now (announcing the block first), or nullptr while quiet.
  canon::Sink* live() {
    if (sink_ == nullptr || segments_ < quiet_until_) return nullptr;
    if (!announced_) {
      sink_->begin_block(origin_);
      announced_ = true;
    }
    return sink_;
  }
  // Motions: count the segment, leave quiet mode at the first forwarded segment.
  canon::Sink* live_motion(canon::SegmentId& id);
  Pose map_pose(const Pose& p) const noexcept;
  void map_arc(canon::ArcFeed& arc) const;
  Pose motion_pose(const Pose& p) const;
  /// A straight motion to `end` (program coordinates) forwarded as (sink->*call)(id, pose).
  void straight_motion(void (canon::Sink::*call)(canon::SegmentId, const Pose&), const Pose& end);
  bool transforming() const { return transform_ && state_ != nullptr && transform_->active(*state_); }
  bool enqueue(Queued&& q);
  void scale_queue(double k) noexcept;

  void track_motion(const Pose& end) noexcept {
    if (view_ != nullptr) view_->canon_position = end;
  }

  canon::Sink* sink_ = nullptr;
  PositionState* view_ = nullptr;
  const InterpState* state_ = nullptr;
  canon::Units view_units_ = canon::Units::Mm;
  canon::BlockOrigin origin_;
  bool announced_ = false;
  std::uint64_t segments_ = 0;
  std::uint64_t quiet_until_ = 0;
  std::uint64_t max_segments_ = 0;
  bool identity_map_ = true;
  std::array<Axis, kAxisCount> axis_map_{};
  std::shared_ptr<CoordinateTransform> transform_;
  bool queueing_ = false;
  std::vector<Queued> queue_;
  std::vector<Queued> flushing_;
  std::vector<canon::NurbsPoint> mapped_points_;   ///< control points after transform and axis map
};

}  // namespace opencnc::gcode
