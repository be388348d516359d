// SPDX-License-Identifier: GPL-3.0-or-later
// The canonical machining interface: the calls the interpreter makes, injected as a sink.
#pragma once

#include <span>
#include <string_view>

#include "opencnc/canon/types.hpp"

namespace opencnc::canon {

/// Receives canonical machining calls in execution order. Positions are in the active program
/// units and work coordinates, after the interpreter's own transformations (cutter
/// compensation, rotation/scaling/mirroring, axis exchange), before G5x/G92/rotation offsets
/// and tool length offset, exactly as LinuxCNC's interpreter hands them to its canon layer.
/// Every method has an empty default so a sink implements only what it needs.
/// Called from the interpreter's thread (non-real-time); sinks may allocate.
class Sink {
 public:
  virtual ~Sink() = default;

  /// The block whose execution produces the following calls.
  virtual void begin_block(const BlockOrigin& /*origin*/) {}

  // --- representation -----------------------------------------------------------------
  virtual void use_length_units(Units) {}
  /// G54..G59.3 offsets; `index` 1..9.
  virtual void set_g5x_offset(int /*index*/, const Pose& /*offset*/) {}
  virtual void set_g92_offset(const Pose& /*offset*/) {}
  virtual void set_xy_rotation(double /*degrees*/) {}
  virtual void select_plane(Plane) {}
  virtual void set_feed_reference(FeedReference) {}

  // --- motion (each carries its segment id) ------------------------------------------
  virtual void straight_traverse(SegmentId, const Pose& /*end*/) {}
  virtual void straight_feed(SegmentId, const Pose& /*end*/) {}
  virtual void arc_feed(SegmentId, const ArcFeed&) {}
  virtual void straight_probe(SegmentId, const Pose& /*end*/) {}
  /// G33.1 rigid tapping to `end` (x, y, z), spindle reversal and back out.
  virtual void rigid_tap(SegmentId, const Pose& /*end*/, double /*scale*/) {}
  /// G5.1 / G5.2+G5.3: a NURBS curve in the XY plane of the given order (LinuxCNC's
  /// NURBS_FEED). The start point is the current position; the last control point is the end.
  virtual void nurbs_feed(SegmentId, int /*order*/, std::span<const NurbsPoint> /*control_points*/) {}
  virtual void dwell(double /*seconds*/) {}

  // --- feed and path control ---------------------------------------------------------
  virtual void set_feed_rate(double /*units_per_min_or_rev_or_inverse_time*/) {}
  virtual void set_feed_mode(int /*spindle*/, FeedMode) {}
  virtual void set_motion_control_mode(MotionControl, double /*tolerance*/) {}
  virtual void set_naivecam_tolerance(double /*tolerance*/) {}
  /// G33 / G95 spindle synchronisation: feed per revolution in program units.
  virtual void start_speed_feed_synch(int /*spindle*/, double /*feed_per_rev*/, bool /*velocity_mode*/) {}
  virtual void stop_speed_feed_synch() {}

  // --- spindle -----------------------------------------------------------------------
  virtual void set_spindle_speed(int /*spindle*/, double /*rpm_or_surface_speed*/) {}
  virtual void start_spindle_clockwise(int /*spindle*/) {}
  virtual void start_spindle_counterclockwise(int /*spindle*/) {}
  virtual void stop_spindle_turning(int /*spindle*/) {}
  /// G96 (css_max > 0: constant surface speed with that rpm cap) / G97 (css_max = 0).
  virtual void set_spindle_mode(int /*spindle*/, double /*css_max*/) {}
  virtual void orient_spindle(int /*spindle*/, double /*degrees*/, int /*direction*/) {}
  virtual void wait_spindle_orient_complete(int /*spindle*/, double /*timeout_s*/) {}

  // --- tools -------------------------------------------------------------------------
  virtual void select_tool(int /*tool*/) {}
  virtual void start_change() {}
  virtual void change_tool(int /*tool*/) {}
  virtual void change_tool_number(int /*tool*/) {}
  virtual void use_tool_length_offset(const Pose& /*offset*/) {}
  /// G10 L1/L10/L11 changed entry `index` of the tool table (0 = the spindle): tool number,
  /// offsets, diameter, lathe angles and orientation, in the table's units.
  virtual void set_tool_table_entry(int /*index*/, int /*tool*/, const Pose& /*offset*/, double /*diameter*/,
                                    double /*front_angle*/, double /*back_angle*/, int /*orientation*/) {}

  // --- coolant -----------------------------------------------------------------------
  virtual void mist_on() {}
  virtual void mist_off() {}
  virtual void flood_on() {}
  virtual void flood_off() {}

  // --- overrides (M48..M53) ----------------------------------------------------------
  virtual void enable_feed_override() {}
  virtual void disable_feed_override() {}
  virtual void enable_speed_override(int /*spindle*/) {}
  virtual void disable_speed_override(int /*spindle*/) {}
  virtual void enable_adaptive_feed() {}
  virtual void disable_adaptive_feed() {}
  virtual void enable_feed_hold() {}
  virtual void disable_feed_hold() {}

  // --- digital and analog I/O (M62..M68) ---------------------------------------------
  virtual void set_motion_output_bit(int /*index*/) {}
  virtual void clear_motion_output_bit(int /*index*/) {}
  virtual void set_aux_output_bit(int /*index*/) {}
  virtual void clear_aux_output_bit(int /*index*/) {}
  virtual void set_motion_output_value(int /*index*/, double /*value*/) {}
  virtual void set_aux_output_value(int /*index*/, double /*value*/) {}
  /// Couples the machine's slave axis to its master by a law, or uncouples it (law 0).
  virtual void set_axis_coupling(const AxisCoupling& /*coupling*/) {}
  /// A machine module's process code (EDM condition, generator off), passed to the machine.
  virtual void process_code(const ProcessCode& /*code*/) {}
  /// M66: wait for input `index` (digital if `digital`), `mode` = L word, up to `timeout_s`.
  virtual void wait_for_input(int /*index*/, bool /*digital*/, int /*mode*/, double /*timeout_s*/) {}

  // --- probe -------------------------------------------------------------------------
  virtual void turn_probe_on() {}
  virtual void turn_probe_off() {}

  // --- messages ----------------------------------------------------------------------
  virtual void comment(std::string_view) {}
  virtual void message(std::string_view) {}
  /// (PRINT,...) text, which LinuxCNC writes to stderr instead of the canonical stream.
  virtual void print(std::string_view) {}
  virtual void log_open(std::string_view /*file*/) {}
  virtual void log_append(std::string_view /*file*/) {}
  virtual void log_close() {}
  virtual void log(std::string_view) {}

  // --- program flow ------------------------------------------------------------------
  virtual void program_stop() {}
  virtual void optional_program_stop() {}
  virtual void pallet_shuttle() {}
  virtual void program_end() {}
  /// End of a program without M2/M30 (a `%` delimited file).
  virtual void finish() {}
  virtual void on_reset() {}
};

}  // namespace opencnc::canon
