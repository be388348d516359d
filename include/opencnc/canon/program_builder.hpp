// SPDX-License-Identifier: GPL-3.0-or-later
// ProgramBuilder — a canonical sink that turns canonical calls into a canon::Program in
// machine coordinates, applying units, G5x/G92 offsets, XY rotation and tool length offset.
#pragma once

#include <memory>

#include "opencnc/canon/program.hpp"
#include "opencnc/canon/sink.hpp"

namespace opencnc::canon {

/// Builds a Program from the canonical stream. The conversion from canonical (program units,
/// work coordinates) to machine coordinates is LinuxCNC's: add the G92 offset, rotate about Z
/// by the XY rotation, add the G5x offset and the tool length offset, then scale to mm.
/// Non-real-time; one builder per run.
class ProgramBuilder final : public Sink {
 public:
  /// Largest distance between a spline and the chords it is split into (0.5 µm).
  static constexpr double kCurveToleranceMm = 0.0005;

  /// `start` is the machine position (mm) the program starts from.
  explicit ProgramBuilder(AxisMask axes = kXyzabc, const Pose& start = {});
  /// With `on`, a move appended with the id of the move before it continues that segment (a
  /// pass over the calls split the move: controller::CallPass) and the program notes the split.
  /// Off by default: a program built by hand may number every move 0.
  void note_repeated_ids_as_splits(bool on) noexcept { split_repeats_ = on; }

  /// The program built so far; take it when the run has ended.
  Program& program() noexcept { return program_; }
  Program take() { return std::move(program_); }
  /// Drops the moves and actions built so far and goes on into an empty program that starts
  /// where the machine is; the conversion state (units, offsets, rotation, plane, feed and
  /// modes) and the source map are kept. For readers that take the moves as they come and need
  /// not keep them (`opencnc scan`'s summary): memory stays bounded however long the program.
  /// Non-real-time.
  void restart();
  /// Current machine position (mm) after the last motion.
  const Pose& position() const noexcept { return position_; }
  /// The block the last canonical calls came from.
  const BlockOrigin& origin() const noexcept { return origin_; }
  /// Converts a canonical position to machine coordinates with the current offsets.
  Pose to_machine(const Pose& canonical) const noexcept;
  /// Streams: a builder for what follows when the machine stopped elsewhere than this program's
  /// last move ends (a probe tripped): a new program starting at `start` (machine coordinates)
  /// with the same offsets, units and feed, the settings the planner reads as it goes (path
  /// control, naive-CAM tolerance, feed override and hold switches, spindle sync) repeated as
  /// its first actions, and the segment ids going on. This builder is left as it is.
  std::unique_ptr<ProgramBuilder> continuation(const Pose& start) const;

  void begin_block(const BlockOrigin& origin) override { origin_ = origin; }
  void use_length_units(Units u) override;
  void set_g5x_offset(int index, const Pose& offset) override;
  void set_g92_offset(const Pose& offset) override;
  void set_xy_rotation(double degrees) override;
  void select_plane(Plane p) override { plane_ = p; }

  void straight_traverse(SegmentId id, const Pose& end) override;
  void straight_feed(SegmentId id, const Pose& end) override;
  void arc_feed(SegmentId id, const ArcFeed& arc) override;
  void straight_probe(SegmentId id, const Pose& end) override;
  void rigid_tap(SegmentId id, const Pose& end, double scale) override;
  /// A NURBS (G5, G5.1, G5.2/G5.3) becomes feed moves along chords no further than
  /// kCurveToleranceMm from the curve, flagged kCurveChord, the last ending exactly on the
  /// curve's end; they all belong to segment `id` (Program::segment_of / first_move_of).
  void nurbs_feed(SegmentId id, int order, std::span<const NurbsPoint> points) override;
  void dwell(double seconds) override;

  void set_feed_rate(double rate) override { feed_ = rate; }
  void set_feed_mode(int spindle, FeedMode mode) override;
  void set_motion_control_mode(MotionControl mode, double tolerance) override;
  void set_naivecam_tolerance(double tolerance) override;
  void start_speed_feed_synch(int spindle, double feed_per_rev, bool velocity_mode) override;
  void stop_speed_feed_synch() override;

  void set_spindle_speed(int spindle, double rpm) override;
  void start_spindle_clockwise(int spindle) override;
  void start_spindle_counterclockwise(int spindle) override;
  void stop_spindle_turning(int spindle) override;
  void set_spindle_mode(int spindle, double css_max) override;
  void orient_spindle(int spindle, double degrees, int direction) override;

  void select_tool(int tool) override;
  void change_tool(int tool) override;
  void change_tool_number(int tool) override;
  void use_tool_length_offset(const Pose& offset) override;

  void mist_on() override { simple(ActionKind::MistOn); }
  void mist_off() override { simple(ActionKind::MistOff); }
  void flood_on() override { simple(ActionKind::FloodOn); }
  void flood_off() override { simple(ActionKind::FloodOff); }
  void enable_feed_override() override { simple(ActionKind::FeedOverrideEnable); }
  void disable_feed_override() override { simple(ActionKind::FeedOverrideDisable); }
  void enable_speed_override(int spindle) override { simple(ActionKind::SpeedOverrideEnable, spindle); }
  void disable_speed_override(int spindle) override { simple(ActionKind::SpeedOverrideDisable, spindle); }
  void enable_adaptive_feed() override { simple(ActionKind::AdaptiveFeedEnable); }
  void disable_adaptive_feed() override { simple(ActionKind::AdaptiveFeedDisable); }
  void enable_feed_hold() override { simple(ActionKind::FeedHoldEnable); }
  void disable_feed_hold() override { simple(ActionKind::FeedHoldDisable); }

  void set_motion_output_bit(int index) override { simple(ActionKind::MotionOutputBit, index, 1); }
  void clear_motion_output_bit(int index) override { simple(ActionKind::MotionOutputBit, index, 0); }
  void set_aux_output_bit(int index) override { simple(ActionKind::AuxOutputBit, index, 1); }
  void clear_aux_output_bit(int index) override { simple(ActionKind::AuxOutputBit, index, 0); }
  void set_motion_output_value(int index, double value) override;
  void set_aux_output_value(int index, double value) override;
  void set_axis_coupling(const AxisCoupling& coupling) override;
  void process_code(const ProcessCode& code) override;
  void wait_for_input(int index, bool digital, int mode, double timeout_s) override;

  void turn_probe_on() override { simple(ActionKind::ProbeOn); }
  void turn_probe_off() override { simple(ActionKind::ProbeOff); }
  void comment(std::string_view text) override;
  void message(std::string_view text) override;

  void program_stop() override { simple(ActionKind::ProgramStop); }
  void optional_program_stop() override { simple(ActionKind::OptionalStop); }
  void pallet_shuttle() override { simple(ActionKind::PalletShuttle); }
  void program_end() override { simple(ActionKind::ProgramEnd); }

 private:
  Action make(ActionKind kind, int index = 0, int index2 = 0, double value = 0) const;
  void simple(ActionKind kind, int index = 0, int index2 = 0) { add(make(kind, index, index2)); }
  /// Appends an action; remembers the last one of each planner setting (for continuation()).
  void add(const Action& a);
  Pose offset_to_mm(const Pose& offset) const noexcept;
  void to_machine(const Pose& canonical, Pose& machine) const noexcept;
  void update_work_offset() noexcept;
  /// Appends the move to position_ (the machine position it ends at, already set).
  void append(MoveKind kind, SegmentId id, std::uint32_t param, std::uint8_t extra_flags = 0);
  std::uint32_t current_feed_index();
  void add_spindle_speed(int spindle);
  std::uint8_t move_flags() const noexcept;

  Program program_;
  SegmentId last_id_ = 0;      ///< of the last move appended (has_last_id_)
  std::size_t run_first_ = 0;  ///< the first move of last_id_
  bool has_last_id_ = false;
  bool in_split_ = false;       ///< appending the moves of a rigid tap or a NURBS (noted whole)
  bool split_repeats_ = false;  ///< note_repeated_ids_as_splits
  /// The last action of each setting the planner reads as it goes: path control, naive-CAM
  /// tolerance, feed override on/off, feed hold on/off, spindle sync on/off.
  enum Setting { kPathControl, kNaiveCam, kFeedOverride, kFeedHold, kSpindleSync, kSettings };
  Action settings_[kSettings] = {};
  bool has_setting_[kSettings] = {};
  BlockOrigin origin_;
  Units units_ = Units::Mm;
  double unit_scale_[kAxisCount] = {};   ///< mm per program unit by axis (1 for rotary axes)
  Plane plane_ = Plane::XY;
  Pose g5x_{}, g92_{}, tool_{};   ///< mm (converted when received, like LinuxCNC's canon)
  Pose work_offset_{};            ///< g5x_ + tool_, added to every point
  double rotation_deg_ = 0, rot_cos_ = 1, rot_sin_ = 0;
  double feed_ = 0;
  FeedMode feed_mode_ = FeedMode::UnitsPerMinute;
  bool synced_ = false;
  double css_max_rpm_ = 0;        ///< G96's limit (0: G97, rpm)
  double spindle_speed_ = 0;      ///< the last S, as programmed
  double last_feed_mm_ = -1;
  std::uint32_t last_feed_index_ = 0;
  Pose position_{};
};

}  // namespace opencnc::canon
