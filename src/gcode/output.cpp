// SPDX-License-Identifier: GPL-3.0-or-later
// Forwarding of canonical calls: announce the block, number motions, queue, transform, map.
#include "output.hpp"

#include <utility>

#include "gcode_error.hpp"
#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::gcode {

Output::Output() {
  for (int i = 0; i < kAxisCount; ++i) axis_map_[static_cast<std::size_t>(i)] = static_cast<Axis>(i);
}

void Output::configure(const Options& options) {
  quiet_until_ = options.quiet_until_segment;
  view_units_ = options.initial_units;
  max_segments_ = options.limits.max_segments;
  axis_map_ = options.axis_map;
  identity_map_ = true;
  for (int i = 0; i < kAxisCount; ++i) {
    if (axis_map_[static_cast<std::size_t>(i)] != static_cast<Axis>(i)) identity_map_ = false;
  }
  transform_ = options.extensions ? options.extensions->transform : nullptr;
}

Pose Output::map_pose(const Pose& p) const noexcept {
  if (identity_map_) return p;
  Pose out{};
  for (int i = 0; i < kAxisCount; ++i) out[index(axis_map_[static_cast<std::size_t>(i)])] = p[i];
  return out;
}

void Output::map_arc(canon::ArcFeed& arc) const {
  if (identity_map_) return;
  const canon::PlaneAxes axes = canon::plane_axes(arc.plane);
  const int first = index(axis_map_[static_cast<std::size_t>(axes.first)]);
  const int second = index(axis_map_[static_cast<std::size_t>(axes.second)]);
  const int normal = index(axis_map_[static_cast<std::size_t>(axes.normal)]);
  static constexpr canon::Plane kPlanes[] = {canon::Plane::XY, canon::Plane::YZ, canon::Plane::XZ,
                                             canon::Plane::UV, canon::Plane::VW, canon::Plane::UW};
  for (canon::Plane p : kPlanes) {
    const canon::PlaneAxes t = canon::plane_axes(p);
    if (t.normal != normal) continue;
    if (t.first == first && t.second == second) {
      arc.plane = p;
    } else if (t.first == second && t.second == first) {
      // Exchanging the plane's two axes mirrors the arc: swap them and reverse the turn.
      arc.plane = p;
      std::swap(arc.first_end, arc.second_end);
      std::swap(arc.first_center, arc.second_center);
      arc.rotation = -arc.rotation;
    } else {
      continue;
    }
    arc.end = map_pose(arc.end);
    return;
  }
  fail(ErrorCode::Unsupported, "the axis map moves this arc out of a canonical plane");
}

Pose Output::motion_pose(const Pose& p) const {
  if (transforming()) return map_pose(transform_->point(*state_, p));
  return map_pose(p);
}

canon::Sink* Output::live_motion(canon::SegmentId& id) {
  id = segments_++;
  if (max_segments_ != 0 && segments_ > max_segments_)
    fail(ErrorCode::LimitSegments, "more than {} motions (limit max_segments)", max_segments_);
  // Replay: motions before the first forwarded segment are dropped; everything after the
  // motion just before it is forwarded (it leads up to that segment).
  if (id < quiet_until_) return nullptr;
  return live();
}

bool Output::enqueue(Queued&& q) {
  if (!queueing_) return false;
  q.origin = origin_;
  queue_.push_back(std::move(q));
  return true;
}

void Output::move_queued_end(canon::Plane plane, double first, double second) noexcept {
  const canon::PlaneAxes axes = canon::plane_axes(plane);
  for (Queued& q : queue_) {
    if (q.kind == Queued::Kind::Arc) {
      q.arc.first_end = first;
      q.arc.second_end = second;
      q.arc.end[axes.first] = first;
      q.arc.end[axes.second] = second;
    } else if (q.kind == Queued::Kind::Traverse || q.kind == Queued::Kind::Feed) {
      q.pose[axes.first] = first;
      q.pose[axes.second] = second;
    }
  }
}

// A change of length units converts the queued motions (held in program units) too.
void Output::scale_queue(double k) noexcept {
  constexpr int kLinear[] = {0, 1, 2, 6, 7, 8};
  for (Queued& q : queue_) {
    if (q.kind == Queued::Kind::Arc) {
      for (double* v : {&q.arc.first_end, &q.arc.second_end, &q.arc.first_center, &q.arc.second_center, &q.arc.axis_end})
        *v *= k;
      for (int i : kLinear) q.arc.end[i] *= k;
    } else if (q.kind == Queued::Kind::Traverse || q.kind == Queued::Kind::Feed) {
      for (int i : kLinear) q.pose[i] *= k;
    }
  }
}

void Output::flush_queue() {
  queueing_ = false;
  const canon::BlockOrigin current = origin_;
  // Swap with a second buffer rather than a new vector: compensation flushes after nearly
  // every move, and both buffers keep their capacity.
  flushing_.swap(queue_);
  for (const Queued& q : flushing_) {
    set_origin(q.origin);
    using K = Queued::Kind;
    switch (q.kind) {
      case K::Traverse: straight_traverse(0, q.pose); break;
      case K::Feed: straight_feed(0, q.pose); break;
      case K::Arc: arc_feed(0, q.arc); break;
      case K::Dwell: dwell(q.value); break;
      case K::FeedRate: set_feed_rate(q.value); break;
      case K::FeedMode: set_feed_mode(q.index, static_cast<canon::FeedMode>(q.index2)); break;
      case K::SpindleSpeed: set_spindle_speed(q.index, q.value); break;
      case K::SpindleCw: start_spindle_clockwise(q.index); break;
      case K::SpindleCcw: start_spindle_counterclockwise(q.index); break;
      case K::SpindleStop: stop_spindle_turning(q.index); break;
      case K::SpindleMode: set_spindle_mode(q.index, q.value); break;
      case K::Orient: orient_spindle(q.index, q.value, q.index2); break;
      case K::OrientWait: wait_spindle_orient_complete(q.index, q.value); break;
      case K::MistOn: mist_on(); break;
      case K::MistOff: mist_off(); break;
      case K::FloodOn: flood_on(); break;
      case K::FloodOff: flood_off(); break;
      case K::Comment: comment(q.text); break;
    }
  }
  flushing_.clear();
  set_origin(current);
}

// --- representation --------------------------------------------------------------------

void Output::use_length_units(canon::Units u) {
  if (u != view_units_) {
    const double k = u == canon::Units::Inch ? 1.0 / 25.4 : 25.4;
    scale_queue(k);
    for (int i = 0; view_ != nullptr && i < 3; ++i) {
      view_->canon_position[i] *= k;
      view_->canon_g5x[i] *= k;
      view_->canon_g92[i] *= k;
    }
  }
  view_units_ = u;
  if (auto* s = live()) s->use_length_units(u);
}
void Output::set_g5x_offset(int index, const Pose& offset) {
  if (view_ != nullptr) {
    for (int i = 0; i < kAxisCount; ++i) view_->canon_position[i] += view_->canon_g5x[i] - offset[i];
    view_->canon_g5x = offset;
  }
  if (auto* s = live()) s->set_g5x_offset(index, map_pose(offset));
}
void Output::set_g92_offset(const Pose& offset) {
  if (view_ != nullptr) {
    for (int i = 0; i < kAxisCount; ++i) view_->canon_position[i] += view_->canon_g92[i] - offset[i];
    view_->canon_g92 = offset;
  }
  if (auto* s = live()) s->set_g92_offset(map_pose(offset));
}
void Output::set_xy_rotation(double degrees) {
  if (auto* s = live()) s->set_xy_rotation(degrees);
}
void Output::select_plane(canon::Plane p) {
  if (auto* s = live()) s->select_plane(p);
}
void Output::set_feed_reference(canon::FeedReference r) {
  if (auto* s = live()) s->set_feed_reference(r);
}

// --- motion ----------------------------------------------------------------------------

void Output::straight_traverse(canon::SegmentId, const Pose& end) {
  if (queueing_) {
    Queued q = queued(Queued::Kind::Traverse);
    q.pose = end;
    enqueue(std::move(q));
    return;
  }
  straight_motion(&canon::Sink::straight_traverse, end);
}

void Output::straight_feed(canon::SegmentId, const Pose& end) {
  if (queueing_) {
    Queued q = queued(Queued::Kind::Feed);
    q.pose = end;
    enqueue(std::move(q));
    return;
  }
  straight_motion(&canon::Sink::straight_feed, end);
}

void Output::straight_motion(void (canon::Sink::*call)(canon::SegmentId, const Pose&), const Pose& end) {
  track_motion(end);
  canon::SegmentId id;
  if (identity_map_ && !transforming()) {   // the usual case: the pose goes out as it is
    if (auto* s = live_motion(id)) (s->*call)(id, end);
    return;
  }
  const Pose p = motion_pose(end);
  if (auto* s = live_motion(id)) (s->*call)(id, p);
}

void Output::arc_feed(canon::SegmentId, const canon::ArcFeed& arc) {
  if (queueing_) {
    Queued q = queued(Queued::Kind::Arc);
    q.arc = arc;
    enqueue(std::move(q));
    return;
  }
  track_motion(arc.end);
  canon::ArcFeed a = arc;
  if (transforming()) transform_->arc(*state_, a);
  map_arc(a);
  canon::SegmentId id;
  if (auto* s = live_motion(id)) s->arc_feed(id, a);
}

void Output::straight_probe(canon::SegmentId, const Pose& end) { straight_motion(&canon::Sink::straight_probe, end); }

void Output::rigid_tap(canon::SegmentId, const Pose& end, double scale) {
  canon::SegmentId id;
  const Pose p = motion_pose(end);
  if (auto* s = live_motion(id)) s->rigid_tap(id, p, scale);
}

void Output::nurbs_feed(canon::SegmentId, int order, std::span<const canon::NurbsPoint> points) {
  if (points.empty()) return;
  const Pose base = view_ != nullptr ? view_->canon_position : Pose{};
  if (view_ != nullptr) {
    view_->canon_position[0] = points.back().x;
    view_->canon_position[1] = points.back().y;
  }
  std::span<const canon::NurbsPoint> out = points;
  if (!identity_map_ || transforming()) {
    // The curve is planar and its control points transform like points (rotation, scaling,
    // mirroring, axis exchange within XY are affine), but it must stay in the XY plane.
    if ((axis_map_[0] != Axis::X && axis_map_[0] != Axis::Y) || (axis_map_[1] != Axis::X && axis_map_[1] != Axis::Y))
      fail(ErrorCode::Unsupported, "the axis map moves this spline out of the XY plane");
    mapped_points_.assign(points.begin(), points.end());
    for (canon::NurbsPoint& q : mapped_points_) {
      Pose p = base;
      p[0] = q.x;
      p[1] = q.y;
      const Pose m = motion_pose(p);
      q.x = m[0];
      q.y = m[1];
    }
    out = mapped_points_;
  }
  canon::SegmentId id;
  if (auto* s = live_motion(id)) s->nurbs_feed(id, order, out);
}

void Output::dwell(double seconds) {
  Queued q = queued(Queued::Kind::Dwell);
  q.value = seconds;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->dwell(seconds);
}

// --- feed and path control -------------------------------------------------------------

void Output::set_feed_rate(double rate) {
  Queued q = queued(Queued::Kind::FeedRate);
  q.value = rate;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->set_feed_rate(rate);
}
void Output::set_feed_mode(int spindle, canon::FeedMode mode) {
  Queued q = queued(Queued::Kind::FeedMode);
  q.index = spindle;
  q.index2 = static_cast<int>(mode);
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->set_feed_mode(spindle, mode);
}
void Output::set_motion_control_mode(canon::MotionControl mode, double tolerance) {
  if (auto* s = live()) s->set_motion_control_mode(mode, tolerance);
}
void Output::set_naivecam_tolerance(double tolerance) {
  if (auto* s = live()) s->set_naivecam_tolerance(tolerance);
}
void Output::start_speed_feed_synch(int spindle, double feed_per_rev, bool velocity_mode) {
  if (auto* s = live()) s->start_speed_feed_synch(spindle, feed_per_rev, velocity_mode);
}
void Output::stop_speed_feed_synch() {
  if (auto* s = live()) s->stop_speed_feed_synch();
}

// --- spindle ---------------------------------------------------------------------------

void Output::set_spindle_speed(int spindle, double rpm) {
  Queued q = queued(Queued::Kind::SpindleSpeed);
  q.index = spindle;
  q.value = rpm;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->set_spindle_speed(spindle, rpm);
}
void Output::start_spindle_clockwise(int spindle) {
  Queued q = queued(Queued::Kind::SpindleCw);
  q.index = spindle;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->start_spindle_clockwise(spindle);
}
void Output::start_spindle_counterclockwise(int spindle) {
  Queued q = queued(Queued::Kind::SpindleCcw);
  q.index = spindle;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->start_spindle_counterclockwise(spindle);
}
void Output::stop_spindle_turning(int spindle) {
  Queued q = queued(Queued::Kind::SpindleStop);
  q.index = spindle;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->stop_spindle_turning(spindle);
}
void Output::set_spindle_mode(int spindle, double css_max) {
  Queued q = queued(Queued::Kind::SpindleMode);
  q.index = spindle;
  q.value = css_max;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->set_spindle_mode(spindle, css_max);
}
void Output::orient_spindle(int spindle, double degrees, int direction) {
  Queued q = queued(Queued::Kind::Orient);
  q.index = spindle;
  q.value = degrees;
  q.index2 = direction;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->orient_spindle(spindle, degrees, direction);
}
void Output::wait_spindle_orient_complete(int spindle, double timeout_s) {
  Queued q = queued(Queued::Kind::OrientWait);
  q.index = spindle;
  q.value = timeout_s;
  if (enqueue(std::move(q))) return;
  if (auto* s = live()) s->wait_spindle_orient_complete(spindle, timeout_s);
}

// --- tools -----------------------------------------------------------------------------

void Output::select_tool(int tool) {
  if (auto* s = live()) s->select_tool(tool);
}
void Output::start_change() {
  if (auto* s = live()) s->start_change();
}
void Output::change_tool(int tool) {
  if (auto* s = live()) s->change_tool(tool);
}
void Output::change_tool_number(int tool) {
  if (auto* s = live()) s->change_tool_number(tool);
}
void Output::use_tool_length_offset(const Pose& offset) {
  if (auto* s = live()) s->use_tool_length_offset(map_pose(offset));
}
void Output::set_tool_table_entry(int index, int tool, const Pose& offset, double diameter, double front_angle,
                                  double back_angle, int orientation) {
  if (auto* s = live()) s->set_tool_table_entry(index, tool, offset, diameter, front_angle, back_angle, orientation);
}

// --- coolant, overrides, I/O, probe --------------------------------------------------------

void Output::mist_on() {
  if (enqueue(queued(Queued::Kind::MistOn))) return;
  if (auto* s = live()) s->mist_on();
}
void Output::mist_off() {
  if (enqueue(queued(Queued::Kind::MistOff))) return;
  if (auto* s = live()) s->mist_off();
}
void Output::flood_on() {
  if (enqueue(queued(Queued::Kind::FloodOn))) return;
  if (auto* s = live()) s->flood_on();
}
void Output::flood_off() {
  if (enqueue(queued(Queued::Kind::FloodOff))) return;
  if (auto* s = live()) s->flood_off();
}
void Output::enable_feed_override() {
  if (auto* s = live()) s->enable_feed_override();
}
void Output::disable_feed_override() {
  if (auto* s = live()) s->disable_feed_override();
}
void Output::enable_speed_override(int spindle) {
  if (auto* s = live()) s->enable_speed_override(spindle);
}
void Output::disable_speed_override(int spindle) {
  if (auto* s = live()) s->disable_speed_override(spindle);
}
void Output::enable_adaptive_feed() {
  if (auto* s = live()) s->enable_adaptive_feed();
}
void Output::disable_adaptive_feed() {
  if (auto* s = live()) s->disable_adaptive_feed();
}
void Output::enable_feed_hold() {
  if (auto* s = live()) s->enable_feed_hold();
}
void Output::disable_feed_hold() {
  if (auto* s = live()) s->disable_feed_hold();
}
void Output::set_motion_output_bit(int index) {
  if (auto* s = live()) s->set_motion_output_bit(index);
}
void Output::clear_motion_output_bit(int index) {
  if (auto* s = live()) s->clear_motion_output_bit(index);
}
void Output::set_aux_output_bit(int index) {
  if (auto* s = live()) s->set_aux_output_bit(index);
}
void Output::clear_aux_output_bit(int index) {
  if (auto* s = live()) s->clear_aux_output_bit(index);
}
void Output::set_motion_output_value(int index, double value) {
  if (auto* s = live()) s->set_motion_output_value(index, value);
}
void Output::set_axis_coupling(const canon::AxisCoupling& coupling) {
  if (auto* s = live()) s->set_axis_coupling(coupling);
}
void Output::process_code(const canon::ProcessCode& code) {
  if (auto* s = live()) s->process_code(code);
}
void Output::set_aux_output_value(int index, double value) {
  if (auto* s = live()) s->set_aux_output_value(index, value);
}
void Output::wait_for_input(int index, bool digital, int mode, double timeout_s) {
  if (auto* s = live()) s->wait_for_input(index, digital, mode, timeout_s);
}
void Output::turn_probe_on() {
  if (auto* s = live()) s->turn_probe_on();
}
void Output::turn_probe_off() {
  if (auto* s = live()) s->turn_probe_off();
}

// --- messages and program flow ----------------------------------------------------------

void Output::comment(std::string_view text) {
  Queued q = queued(Queued::Kind::Comment);
  if (queueing_) {
    q.text = std::string(text);
    enqueue(std::move(q));
    return;
  }
  if (auto* s = live()) s->comment(text);
}
void Output::message(std::string_view text) {
  if (auto* s = live()) s->message(text);
}
void Output::print(std::string_view text) {
  if (auto* s = live()) s->print(text);
}
void Output::log_open(std::string_view file) {
  if (auto* s = live()) s->log_open(file);
}
void Output::log_append(std::string_view file) {
  if (auto* s = live()) s->log_append(file);
}
void Output::log_close() {
  if (auto* s = live()) s->log_close();
}
void Output::log(std::string_view text) {
  if (auto* s = live()) s->log(text);
}
void Output::program_stop() {
  if (auto* s = live()) s->program_stop();
}
void Output::optional_program_stop() {
  if (auto* s = live()) s->optional_program_stop();
}
void Output::pallet_shuttle() {
  if (auto* s = live()) s->pallet_shuttle();
}
void Output::program_end() {
  if (auto* s = live()) s->program_end();
}
void Output::finish() {
  if (auto* s = live()) s->finish();
}
void Output::on_reset() {
  if (auto* s = live()) s->on_reset();
}

}  // namespace opencnc::gcode
