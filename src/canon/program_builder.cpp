// SPDX-License-Identifier: GPL-3.0-or-later
// Canonical calls → machine-coordinate program (units, offsets, rotation, tool offset).
#include "opencnc/canon/program_builder.hpp"

#include <cmath>
#include <numbers>
#include <vector>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/canon/nurbs.hpp"

namespace opencnc::canon {

namespace {
bool is_linear(int axis) { return !is_rotary(static_cast<Axis>(axis)); }
}  // namespace

ProgramBuilder::ProgramBuilder(AxisMask axes, const Pose& start) : program_(axes), position_(start) {
  program_.set_start(start);
  use_length_units(units_);
}

void ProgramBuilder::restart() {
  Program next(program_.axes());
  next.set_start(position_);
  next.set_sources(program_.sources_ptr());
  program_ = std::move(next);
  last_feed_mm_ = -1;  // the feed table starts empty again
}

void ProgramBuilder::use_length_units(Units u) {
  units_ = u;
  for (int i = 0; i < kAxisCount; ++i) unit_scale_[i] = is_linear(i) ? mm_per_unit(u) : 1.0;
}

Pose ProgramBuilder::offset_to_mm(const Pose& offset) const noexcept {
  Pose out = offset;
  const double k = mm_per_unit(units_);
  for (int i = 0; i < kAxisCount; ++i) {
    if (is_linear(i)) out[i] *= k;
  }
  return out;
}

Pose ProgramBuilder::to_machine(const Pose& canonical) const noexcept {
  Pose p;
  to_machine(canonical, p);
  return p;
}

// Once per move: one pass per stage, written in place (position_ for a move).
void ProgramBuilder::to_machine(const Pose& canonical, Pose& p) const noexcept {
  // (a rotary axis is scaled by 1.0, which leaves it exactly as it is)
  if (rotation_deg_ == 0) {   // one pass, the same sums in the same order
    for (int i = 0; i < kAxisCount; ++i) p[i] = (canonical[i] * unit_scale_[i] + g92_[i]) + work_offset_[i];
    return;
  }
  for (int i = 0; i < kAxisCount; ++i) p[i] = canonical[i] * unit_scale_[i] + g92_[i];
  const double x = p[0], y = p[1];
  p[0] = x * rot_cos_ - y * rot_sin_;
  p[1] = x * rot_sin_ + y * rot_cos_;
  for (int i = 0; i < kAxisCount; ++i) p[i] += work_offset_[i];
}

void ProgramBuilder::update_work_offset() noexcept {
  for (int i = 0; i < kAxisCount; ++i) work_offset_[i] = g5x_[i] + tool_[i];
}

void ProgramBuilder::set_g5x_offset(int index, const Pose& offset) {
  g5x_ = offset_to_mm(offset);
  update_work_offset();
  Action a = make(ActionKind::WorkOffset, index);
  a.pose = program_.add_action_pose(g5x_);
  add(a);
  if (css_max_rpm_ > 0) add_spindle_speed(0);  // the spindle axis moved (LinuxCNC's canon)
}

void ProgramBuilder::set_g92_offset(const Pose& offset) {
  g92_ = offset_to_mm(offset);
  Action a = make(ActionKind::G92Offset);
  a.pose = program_.add_action_pose(g92_);
  add(a);
  if (css_max_rpm_ > 0) add_spindle_speed(0);
}

void ProgramBuilder::set_xy_rotation(double degrees) {
  rotation_deg_ = degrees;
  const double r = degrees * std::numbers::pi / 180.0;
  rot_cos_ = std::cos(r);
  rot_sin_ = std::sin(r);
  add(make(ActionKind::XyRotation, 0, 0, degrees));
}

void ProgramBuilder::use_tool_length_offset(const Pose& offset) {
  tool_ = offset_to_mm(offset);
  update_work_offset();
  Action a = make(ActionKind::ToolLengthOffset);
  a.pose = program_.add_action_pose(tool_);
  add(a);
}

void ProgramBuilder::add(const Action& a) {
  int setting = -1;
  switch (a.kind) {
    case ActionKind::MotionControl:
      setting = kPathControl;
      break;
    case ActionKind::NaiveCamTolerance:
      setting = kNaiveCam;
      break;
    case ActionKind::FeedOverrideEnable:
    case ActionKind::FeedOverrideDisable:
      setting = kFeedOverride;
      break;
    case ActionKind::FeedHoldEnable:
    case ActionKind::FeedHoldDisable:
      setting = kFeedHold;
      break;
    case ActionKind::SpeedFeedSyncStart:
    case ActionKind::SpeedFeedSyncStop:
      setting = kSpindleSync;
      break;
    default:
      break;
  }
  if (setting >= 0) {
    settings_[setting] = a;
    has_setting_[setting] = true;
  }
  program_.add_action(a);
}

std::unique_ptr<ProgramBuilder> ProgramBuilder::continuation(const Pose& start) const {
  auto next = std::make_unique<ProgramBuilder>(program_.axes(), start);
  next->program_.set_sources(program_.sources_ptr());
  next->origin_ = origin_;
  next->use_length_units(units_);
  next->plane_ = plane_;
  next->g5x_ = g5x_;
  next->g92_ = g92_;
  next->tool_ = tool_;
  next->work_offset_ = work_offset_;
  next->rotation_deg_ = rotation_deg_;
  next->rot_cos_ = rot_cos_;
  next->rot_sin_ = rot_sin_;
  next->feed_ = feed_;
  next->feed_mode_ = feed_mode_;
  next->split_repeats_ = split_repeats_;
  next->synced_ = synced_;
  next->css_max_rpm_ = css_max_rpm_;
  next->spindle_speed_ = spindle_speed_;
  for (int k = 0; k < kSettings; ++k) {
    if (!has_setting_[k]) continue;
    Action a = settings_[k];
    a.before_move = 0;
    next->add(a);
  }
  return next;
}

Action ProgramBuilder::make(ActionKind kind, int index, int index2, double value) const {
  Action a;
  a.kind = kind;
  a.index = index;
  a.index2 = index2;
  a.value = value;
  a.before_move = static_cast<std::uint32_t>(program_.size());
  a.context = origin_.context;
  a.line = origin_.line;
  return a;
}

std::uint8_t ProgramBuilder::move_flags() const noexcept {
  std::uint8_t f = 0;
  if (feed_mode_ == FeedMode::InverseTime) f |= kInverseTime;
  if (feed_mode_ == FeedMode::UnitsPerRevolution) f |= kPerRevolution;
  if (synced_) f |= kSpindleSynced;
  return f;
}

std::uint32_t ProgramBuilder::current_feed_index() {
  // Inverse-time feeds are 1/min whatever the units; length feeds convert to mm.
  const double mm = feed_mode_ == FeedMode::InverseTime ? feed_ : feed_ * mm_per_unit(units_);
  if (mm != last_feed_mm_) {
    last_feed_index_ = program_.add_feed(mm);
    last_feed_mm_ = mm;
  }
  return last_feed_index_;
}

void ProgramBuilder::append(MoveKind kind, SegmentId id, std::uint32_t param, std::uint8_t extra_flags) {
  // Ids are ordinals: after the first move, the program's count follows the interpreter's
  // except where a segment is split (recorded by note_split).
  // A move with the id of the one before it (from straight_feed, arc_feed or straight_traverse)
  // continues its segment: a pass over the calls split it (rigid taps and NURBS note their own).
  const bool continues = split_repeats_ && !program_.empty() && has_last_id_ && id == last_id_ && !in_split_;
  if (program_.empty()) program_.set_first_segment(id);
  if (!continues) run_first_ = program_.size();
  last_id_ = id;
  has_last_id_ = true;
  Move& m = program_.append(position_);
  m.kind = kind;
  m.flags = static_cast<std::uint8_t>((kind == MoveKind::Traverse ? 0 : move_flags()) | extra_flags);
  m.reserved = 0;
  m.context = origin_.context;
  m.line = origin_.line;
  m.param = param;
  if (continues) program_.note_split(id, run_first_, program_.size() - run_first_);
}

void ProgramBuilder::straight_traverse(SegmentId id, const Pose& end) {
  to_machine(end, position_);
  append(MoveKind::Traverse, id, 0);
}

void ProgramBuilder::straight_feed(SegmentId id, const Pose& end) {
  to_machine(end, position_);
  append(MoveKind::Feed, id, current_feed_index());
}

void ProgramBuilder::straight_probe(SegmentId id, const Pose& end) {
  to_machine(end, position_);
  append(MoveKind::Probe, id, current_feed_index());
}

void ProgramBuilder::rigid_tap(SegmentId id, const Pose& end, double scale) {
  // The tap goes in to `end`, reverses and comes back: two moves of one segment, so that the
  // next move starts where the tap started. Their feed is the way out's speed factor.
  const Pose start = position_;
  in_split_ = true;
  const std::uint32_t factor = program_.add_feed(scale);
  last_feed_mm_ = -1;  // later moves refer to a feed added after this one (streams release in order)
  const std::size_t first = program_.size();
  to_machine(end, position_);
  append(MoveKind::RigidTap, id, factor);
  position_ = start;
  append(MoveKind::RigidTap, id, factor, kTapReturn);
  in_split_ = false;
  program_.note_split(id, first, 2);
}

void ProgramBuilder::arc_feed(SegmentId id, const ArcFeed& arc) {
  const PlaneAxes axes = plane_axes(arc.plane);
  const Pose machine_end = to_machine(arc.end);
  Pose center_c = arc.end;
  center_c[axes.first] = arc.first_center;
  center_c[axes.second] = arc.second_center;
  const Pose center_m = to_machine(center_c);

  const int base = plane_base(arc.plane);
  Vec3 n{0, 0, 0};
  n[axes.normal - base] = 1.0;
  if (base == 0) {  // the XY rotation turns the plane's normal about Z
    const double nx = n[0], ny = n[1];
    n[0] = nx * rot_cos_ - ny * rot_sin_;
    n[1] = nx * rot_sin_ + ny * rot_cos_;
  }
  // The centre lies on the plane through the start point (the helix rises along the normal).
  const Vec3 c = take3(center_m, base), s = take3(position_, base);
  ArcGeometry g;
  g.center = c - dot(c - s, n) * n;
  g.normal = n;
  g.turns = arc.rotation;
  g.plane = arc.plane;
  g.feed = current_feed_index();
  position_ = machine_end;
  append(MoveKind::Arc, id, program_.add_arc(g));
}

void ProgramBuilder::nurbs_feed(SegmentId id, int order, std::span<const NurbsPoint> points) {
  if (points.empty()) return;
  // Units, G92, the rotation about Z, G5x and tool offsets are affine in XY, and a NURBS maps
  // under an affine map by mapping its control points (weights unchanged).
  std::vector<NurbsPoint> machine(points.begin(), points.end());
  for (NurbsPoint& q : machine) {
    Pose c{};
    c[0] = q.x;
    c[1] = q.y;
    const Pose m = to_machine(c);
    q.x = m[0];
    q.y = m[1];
  }
  std::vector<CurvePoint> chords = tessellate_nurbs(machine, order, kCurveToleranceMm);
  if (chords.empty()) chords.push_back({machine.back().x, machine.back().y, 0});
  const std::size_t first = program_.size();
  const std::uint32_t feed = current_feed_index();
  in_split_ = true;
  for (const CurvePoint& v : chords) {
    position_[0] = v.x;
    position_[1] = v.y;
    append(MoveKind::Feed, id, feed, kCurveChord);
  }
  in_split_ = false;
  program_.note_split(id, first, chords.size());
}

void ProgramBuilder::dwell(double seconds) { add(make(ActionKind::Dwell, 0, 0, seconds)); }

void ProgramBuilder::set_feed_mode(int /*spindle*/, FeedMode mode) { feed_mode_ = mode; }

void ProgramBuilder::set_motion_control_mode(MotionControl mode, double tolerance) {
  add(make(ActionKind::MotionControl, static_cast<int>(mode), 0, tolerance * mm_per_unit(units_)));
}

void ProgramBuilder::set_naivecam_tolerance(double tolerance) {
  add(make(ActionKind::NaiveCamTolerance, 0, 0, tolerance * mm_per_unit(units_)));
}

void ProgramBuilder::start_speed_feed_synch(int spindle, double feed_per_rev, bool velocity_mode) {
  synced_ = true;
  add(
      make(ActionKind::SpeedFeedSyncStart, spindle, velocity_mode ? 1 : 0, feed_per_rev * mm_per_unit(units_)));
}

void ProgramBuilder::stop_speed_feed_synch() {
  synced_ = false;
  simple(ActionKind::SpeedFeedSyncStop);
}

void ProgramBuilder::set_spindle_speed(int spindle, double rpm) {
  spindle_speed_ = rpm;
  add_spindle_speed(spindle);
}

// Under G96 the S word is a surface speed (m/min, or ft/min in inch programs): the action holds
// it in mm/min with the X of the spindle axis in machine coordinates, where program X = 0 lies
// (G5x, G92 and tool offsets, as LinuxCNC's canon sends them; rotation left out, as there).
void ProgramBuilder::add_spindle_speed(int spindle) {
  if (css_max_rpm_ <= 0) {
    add(make(ActionKind::SpindleSpeed, spindle, 0, spindle_speed_));
    return;
  }
  const double per_min = units_ == Units::Inch ? 12.0 * 25.4 : 1000.0;
  Action a = make(ActionKind::SpindleSpeed, spindle, 1, spindle_speed_ * per_min);
  Pose axis{};
  axis[0] = g5x_[0] + g92_[0] + tool_[0];
  a.pose = program_.add_action_pose(axis);
  add(a);
}
void ProgramBuilder::start_spindle_clockwise(int spindle) { simple(ActionKind::SpindleCw, spindle); }
void ProgramBuilder::start_spindle_counterclockwise(int spindle) { simple(ActionKind::SpindleCcw, spindle); }
void ProgramBuilder::stop_spindle_turning(int spindle) { simple(ActionKind::SpindleStop, spindle); }
void ProgramBuilder::set_spindle_mode(int spindle, double css_max) {
  css_max_rpm_ = std::fabs(css_max);
  add(make(ActionKind::SpindleMode, spindle, 0, css_max_rpm_));
}
void ProgramBuilder::orient_spindle(int spindle, double degrees, int direction) {
  add(make(ActionKind::SpindleOrient, spindle, direction, degrees));
}

void ProgramBuilder::select_tool(int tool) { simple(ActionKind::SelectTool, tool); }
void ProgramBuilder::change_tool(int tool) { simple(ActionKind::ChangeTool, tool); }
void ProgramBuilder::change_tool_number(int tool) { simple(ActionKind::ChangeToolNumber, tool); }

void ProgramBuilder::set_motion_output_value(int index, double value) {
  add(make(ActionKind::MotionOutputValue, index, 0, value));
}
// The pitch in mm; the rate (mm per mm) and the table number need no conversion.
void ProgramBuilder::set_axis_coupling(const AxisCoupling& c) {
  Action a = make(ActionKind::AxisCoupling, c.law, c.table, c.pitch * mm_per_unit(units_));
  Pose rate{};
  rate[0] = c.rate;
  a.pose = program_.add_action_pose(rate);
  if (c.has_origin) a.origin = 1 + program_.add_action_pose(to_machine(c.origin));
  add(a);
}
// Passed as programmed: the module's words have their own units (a condition number, …).
void ProgramBuilder::process_code(const ProcessCode& c) {
  Action a = make(ActionKind::ProcessCode, c.code, 0, c.p);
  Pose q{};
  q[0] = c.q;
  a.pose = program_.add_action_pose(q);
  add(a);
}
void ProgramBuilder::set_aux_output_value(int index, double value) {
  add(make(ActionKind::AuxOutputValue, index, 0, value));
}
void ProgramBuilder::wait_for_input(int index, bool digital, int mode, double timeout_s) {
  Action a = make(ActionKind::WaitInput, index, mode, timeout_s);
  a.text = program_.add_text(digital ? "digital" : "analog");
  add(a);
}

void ProgramBuilder::comment(std::string_view text) {
  Action a = make(ActionKind::Comment);
  a.text = program_.add_text(std::string(text));
  add(a);
}

void ProgramBuilder::message(std::string_view text) {
  Action a = make(ActionKind::Message);
  a.text = program_.add_text(std::string(text));
  add(a);
}

}  // namespace opencnc::canon
