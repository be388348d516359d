// SPDX-License-Identifier: GPL-3.0-or-later
// canon::Program → path elements and markers, with modal path-control state and G64 Q merging.
#include "program_reader.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "path_geometry.hpp"
#include "vec.hpp"

namespace opencnc::plan::detail {

using canon::ActionKind;
using canon::MoveKind;
using traj::FeedClass;
using traj::MarkerKind;
using traj::MotionBlock;

namespace {

constexpr std::size_t kMaxRunPoints = 512;

std::string file_name(const canon::Program& p, canon::SegmentId id) {
  const std::uint32_t f = p.file_of(id);
  return f < p.sources().file_count() ? p.sources().file(f) : std::string();
}

bool finite_pose(const Pose& p) {
  for (double v : p.v) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

/// What the tick does for each action kind: nothing (the planner applies it or it needs no
/// motion), report it when passed, or stop there.
MarkerKind marker_for(ActionKind k) {
  switch (k) {
    case ActionKind::Dwell:
      return MarkerKind::Dwell;
    case ActionKind::AxisCoupling:
    case ActionKind::ProcessCode:
      return MarkerKind::Dwell;  // an exact stop of no time: the law engages where the path stands
    case ActionKind::ProgramStop:
      return MarkerKind::ProgramStop;
    case ActionKind::OptionalStop:
      return MarkerKind::OptionalStop;
    case ActionKind::ProgramEnd:
      return MarkerKind::ProgramEnd;
    case ActionKind::ChangeTool:
    case ActionKind::WaitInput:
    case ActionKind::PalletShuttle:
    case ActionKind::SpindleOrient:
    case ActionKind::HandAxisWait:
      return MarkerKind::Sync;
    case ActionKind::SpindleSpeed:
    case ActionKind::SpindleCw:
    case ActionKind::SpindleCcw:
    case ActionKind::SpindleStop:
    case ActionKind::SpindleMode:
    case ActionKind::SelectTool:
    case ActionKind::ChangeToolNumber:
    case ActionKind::MistOn:
    case ActionKind::MistOff:
    case ActionKind::FloodOn:
    case ActionKind::FloodOff:
    case ActionKind::SpeedOverrideEnable:
    case ActionKind::SpeedOverrideDisable:
    case ActionKind::MotionOutputBit:
    case ActionKind::AuxOutputBit:
    case ActionKind::MotionOutputValue:
    case ActionKind::AuxOutputValue:
    case ActionKind::ProbeOn:
    case ActionKind::ProbeOff:
    case ActionKind::Message:
      return MarkerKind::Report;
    default:
      return MarkerKind::None;
  }
}

}  // namespace

}  // namespace opencnc::plan::detail

namespace opencnc::plan {

bool check_move(const canon::Program& program, canon::SegmentId id, const MachineLimits& limits,
                Diagnostics& diags) {
  using canon::MoveKind;
  using detail::file_name;
  using detail::finite_pose;
  using detail::make_arc;
  const std::size_t before = diags.error_count();
  const auto fail = [&](std::string msg, const char* code) {
    // Column 1: the block that made the move (the planner knows lines, not words).
    diags.error(file_name(program, id), program.move(id).line, 1, std::move(msg), code);
  };
  const canon::Move& m = program.move(id);
  const Pose start = program.start_of(id), end = program.end(id);
  if (!finite_pose(start) || !finite_pose(end)) {
    fail("the move's end point is not a finite number", "plan.not-finite");
    return false;
  }
  if (m.kind == MoveKind::RigidTap) {
    // A tap is a pair, appended together: in to the bottom, then (kTapReturn) back out, both
    // following the spindle. (A way out whose way in a stream has released was checked with it.)
    const bool out = (m.flags & canon::kTapReturn) != 0;
    bool paired;
    if (out) {
      paired = id > 0 &&
               (id - 1 < program.first_held_move() || (program.move(id - 1).kind == MoveKind::RigidTap &&
                                                       !(program.move(id - 1).flags & canon::kTapReturn)));
    } else {
      paired = id + 1 < program.size() && program.move(id + 1).kind == MoveKind::RigidTap &&
               (program.move(id + 1).flags & canon::kTapReturn);
    }
    if (!paired || !(m.flags & canon::kSpindleSynced)) {
      fail("a rigid tap needs its way out and spindle synchronisation (START_SPEED_FEED_SYNCH) around it",
           "plan.unsupported-move");
      return false;
    }
  }
  for (int i = 0; i < kAxisCount; ++i) {
    if (end[i] != start[i] && !limits.axes.has(static_cast<Axis>(i))) {
      fail(fmt::format("the move drives axis {}, which this machine does not have", kAxisLetters[i]),
           "plan.axis-not-configured");
      break;
    }
  }
  if (m.kind == MoveKind::Arc) {
    traj::MotionBlock b;
    std::string why;
    if (!make_arc(start, end, program.arc(id), b, why) && !why.empty()) fail(why, "plan.bad-arc");
  }
  if (m.kind != MoveKind::Traverse && !(m.flags & canon::kSpindleSynced) && !(program.feed(id) > 0)) {
    fail("feed move with a zero feed rate", "plan.feed-zero");
  }
  return diags.error_count() == before;
}

}  // namespace opencnc::plan

namespace opencnc::plan::detail {

bool check_program(const canon::Program& program, const MachineLimits& limits, Diagnostics& diags) {
  bool ok = true;
  for (canon::SegmentId id = 0; id < program.size(); ++id) ok = check_move(program, id, limits, diags) && ok;
  return ok;
}

ProgramReader::ProgramReader(const canon::Program& program, bool streaming)
    : program_(&program), streaming_(streaming), gated_(streaming) {}

std::size_t ProgramReader::readable_limit() const noexcept {
  return gated_ ? std::min(readable_, program_->size()) : program_->size();
}

std::size_t ProgramReader::oldest_move_needed() const noexcept {
  return next_move_ == 0 ? 0 : next_move_ - 1;  // the end of the move before is the next one's start
}

std::uint8_t ProgramReader::flags() const noexcept {
  std::uint8_t f = 0;
  if (override_enabled_) f |= traj::kFeedOverrideAllowed;
  if (hold_enabled_) f |= traj::kFeedHoldAllowed;
  return f;
}

// A marker item at the end of ready_, every field set.
traj::MotionBlock& ProgramReader::new_marker() {
  Item& it = ready_.append();
  it.is_marker = true;
  it.element = Element{};
  it.element.b.kind = traj::BlockKind::Marker;
  return it.element.b;
}

void ProgramReader::add_marker(std::size_t index, MarkerKind kind) {
  const canon::Action& a = program_->action(index);
  flush_smoother();
  flush_run();
  traj::MotionBlock& m = new_marker();
  m.marker = kind;
  m.action = static_cast<std::uint32_t>(index);
  m.segment = m.segment_first = m.segment_last = a.before_move;
  m.line = a.line;
  m.context = a.context;
  const bool record = a.kind == ActionKind::AxisCoupling || a.kind == ActionKind::ProcessCode;
  m.value = record ? 0.0 : a.value;  // its stop takes no time
  m.flags = flags();
  // A law engages where master and slave are commanded: it waits for the drives to stand there
  // (the servo's in-position check), or it would take them while they still settle.
  if (a.kind == ActionKind::AxisCoupling && a.index != 0) m.flags |= traj::kWaitInPosition;
  if (kind == MarkerKind::ProgramEnd) ended_ = true;
}

void ProgramReader::read_actions_before(std::uint32_t move) {
  while (next_action_ < program_->action_count() && program_->action(next_action_).before_move <= move) {
    const std::size_t index = next_action_++;
    const canon::Action& a = program_->action(index);
    switch (a.kind) {
      case ActionKind::MotionControl:
        mode_ = static_cast<canon::MotionControl>(a.index);
        tolerance_ = a.value;
        break;
      case ActionKind::NaiveCamTolerance:
        naive_tolerance_ = a.value;
        break;
      case ActionKind::FeedOverrideEnable:
        override_enabled_ = true;
        break;
      case ActionKind::FeedOverrideDisable:
        override_enabled_ = false;
        break;
      case ActionKind::FeedHoldEnable:
        hold_enabled_ = true;
        break;
      case ActionKind::FeedHoldDisable:
        hold_enabled_ = false;
        break;
      case ActionKind::SpeedFeedSyncStart:
        sync_per_rev_ = a.value;
        break;
      default:
        break;
    }
    const MarkerKind kind = marker_for(a.kind);
    if (kind != MarkerKind::None) add_marker(index, kind);
    // The tick stops for the spindle to reach speed before the motion that follows a start.
    if (a.kind == ActionKind::SpindleCw || a.kind == ActionKind::SpindleCcw)
      add_marker(index, MarkerKind::SpindleWait);
  }
}

bool ProgramReader::make_element(canon::SegmentId id, Element& e) const {
  const canon::Move& m = program_->move(id);
  const Pose start = program_->start_of(id), end = program_->end(id);
  traj::MotionBlock& b = e.b;
  if (m.kind == MoveKind::Arc) {
    std::string why;
    if (!make_arc(start, end, program_->arc(id), b, why)) return false;  // rejected by the check
  } else if (!make_line(start, end, b)) {
    return false;  // no motion
  }
  b.segment = b.segment_first = b.segment_last = id;
  b.line = m.line;
  b.context = m.context;
  b.flags = flags();
  if (m.kind == MoveKind::Probe) b.flags |= traj::kProbe;
  if (m.kind == MoveKind::RigidTap) {
    b.flags |= traj::kRigidTap;
    if (m.flags & canon::kTapReturn) b.flags |= traj::kTapReturn;
    b.tap_scale = program_->feed(id);  // the way out's spindle speed factor (G33.1 I)
  }
  const double f = program_->feed(id);
  const double ratio = feed_length_ratio(start, end, b);
  if (m.kind == MoveKind::Traverse) {
    b.feed_class = FeedClass::Rapid;
    b.feed = 0;  // the rapid rate comes from the limits
  } else if (m.flags & canon::kSpindleSynced) {
    b.feed_class = FeedClass::SpindleSync;
    b.feed = sync_per_rev_ * ratio;
    b.flags &= static_cast<std::uint8_t>(~(traj::kFeedHoldAllowed | traj::kFeedOverrideAllowed));
  } else if (m.flags & canon::kPerRevolution) {
    b.feed_class = FeedClass::PerRevolution;
    b.feed = f * ratio;
  } else if (m.flags & canon::kInverseTime) {
    b.feed_class = FeedClass::Feed;
    b.feed = b.length * f / 60.0;  // the move takes 1/F minutes
  } else {
    b.feed_class = FeedClass::Feed;
    b.feed = f / 60.0 * ratio;
  }
  e.orig_length = b.length;
  e.merge_deviation = 0;
  e.mode = mode_;
  e.tolerance = tolerance_;
  e.stop_after = m.kind == MoveKind::Probe;
  if (m.kind == MoveKind::Arc) chord_small_arc(start, end, f, e);
  return true;
}

// G64 Q, as LinuxCNC's naive-CAM detector: a flat arc that never leaves its chord by more than
// the tolerance is the chord (tiny arcs from CAM output), and may then be merged with others.
void ProgramReader::chord_small_arc(const Pose& start, const Pose& end, double feed, Element& e) const {
  if (e.mode != canon::MotionControl::Continuous || naive_tolerance_ <= 0 ||
      e.b.feed_class != FeedClass::Feed)
    return;
  if (norm(e.b.lin) > 1e-12) return;  // helix or other axes: not a flat arc
  const double sweep = std::fabs(e.b.omega) * e.b.length;
  if (sweep > 3.14159265358979323846) return;
  // A spiral lies within its largest radius's sagitta of the chord between the points at that
  // radius, and its ends are within the radius change of those points: the sum bounds it.
  const double r0 = norm(e.b.u), r_end = r0 * (1 + e.b.spiral * e.b.omega * e.b.length);
  const double r_max = std::max(r0, r_end);
  const double sagitta = r_max * (1 - std::cos(0.5 * sweep)) + 2 * std::fabs(r_end - r0);
  if (sagitta > merge_budget()) return;
  MotionBlock line = e.b;
  if (!make_line(start, end, line)) return;
  line.feed = feed / 60.0 * feed_length_ratio(start, end, line);
  e.b = line;
  e.orig_length = line.length;
  e.merge_deviation = sagitta;
}

double ProgramReader::merge_budget() const noexcept {
  return tolerance_ > 0 ? std::min(naive_tolerance_, tolerance_) : naive_tolerance_;
}

// G64 Q: a run of feed lines whose inner vertices all lie within Q of the segment from the run's
// start to the candidate end (and in order along it, up to a step back of Q: CAM output's
// jitter) becomes that one line. With a blend tolerance P the merge uses at most P/2, and the
// blends then keep within P minus the merge's deviation, so the path stays within P of the
// programmed one. Both ways: each programmed move lies within Q of the segment (its ends do, and
// the points within Q of a segment form a convex set), and each point of the segment within Q of
// a programmed move (the nearest points of consecutive vertices on the segment, both within Q of
// the move between them, span a piece of the segment within Q of it; the pieces chain from the
// start to the end, in order or not).
bool ProgramReader::can_extend_run(const Element& e) const {
  if (!run_active_ || run_points_.size() >= kMaxRunPoints) return false;
  if (e.b.kind != traj::BlockKind::Line || e.b.feed_class != FeedClass::Feed || e.stop_after) return false;
  if (e.mode != run_.mode || e.tolerance != run_.tolerance || e.b.flags != run_.b.flags) return false;
  if (program_->feed(e.b.segment_first) != run_feed_) return false;
  // Vertices within Q (at most P/2, to leave the blends room), and all of it within the budget
  // together with what chorded arcs already deviate.
  const double floor = std::max(run_floor_, e.merge_deviation);
  const double q_vertex =
      run_.tolerance > 0 ? std::min(naive_tolerance_, 0.5 * run_.tolerance) : naive_tolerance_;
  const double q = std::min(q_vertex, merge_budget() - floor);
  if (q < 0) return false;
  const Pose chord = end_point(e.b) - run_start_;
  const double len = norm(chord);
  if (len < kMinLength) return false;
  const Pose dir = (1.0 / len) * chord;
  // A vertex at r from the start lies t = r·dir along the chord and √(|r|² − t²) from it. Every
  // run is checked again for each new end, so this is the planner's inner loop on dense paths.
  double last = 0;
  const auto inside = [&](double t, double r_squared) {
    if (t < last - q) return false;
    last = std::max(last, t);
    const double beyond = t < 0 ? -t : (t > len ? t - len : 0.0);
    return r_squared - t * t + beyond * beyond <= q * q;
  };
  for (std::size_t k = 0; k < run_points_.size(); ++k) {
    double t = 0;
    for (int a = 0; a < run_axis_count_; ++a) {
      const int i = run_axes_[static_cast<std::size_t>(a)];
      t += run_points_[k][i] * dir[i];
    }
    if (!inside(t, run_squares_[k])) return false;
  }
  const Pose r = e.b.base - run_start_;
  return inside(dot(r, dir), dot(r, r));
}

void ProgramReader::add_run_point(const Pose& rel) {
  run_points_.push_back(rel);
  run_squares_.push_back(dot(rel, rel));
  for (int i = 0; i < kAxisCount; ++i) {
    if (rel[i] == 0) continue;
    const auto end = run_axes_.begin() + run_axis_count_;
    if (std::find(run_axes_.begin(), end, i) == end)
      run_axes_[static_cast<std::size_t>(run_axis_count_++)] = i;
  }
}

void ProgramReader::flush_run() {
  if (!run_active_) return;
  run_active_ = false;
  Element e = run_;
  if (!run_points_.empty()) {
    const Pose end = end_point(run_.b);
    make_line(run_start_, end, e.b);
    e.b.feed = run_feed_ / 60.0 * feed_length_ratio(run_start_, end, e.b);
    e.orig_length = e.b.length;
    double dev = 0;
    for (const Pose& r : run_points_)  // to the segment: a vertex may lie a little beyond an end
      dev = std::max(dev, norm(r - std::clamp(dot(r, e.b.lin), 0.0, e.b.length) * e.b.lin));
    e.merge_deviation = dev + run_floor_;
  }
  run_points_.clear();
  run_squares_.clear();
  run_axis_count_ = 0;
  Item& it = ready_.append();
  it.is_marker = false;
  it.element = e;
}

void ProgramReader::push_element(const Element& e) {
  if (can_extend_run(e)) {
    add_run_point(e.b.base - run_start_);
    run_.b.segment_last = e.b.segment_last;
    run_.b.base = e.b.base;  // the run's current last line, for end_point()
    run_.b.lin = e.b.lin;
    run_.b.length = e.b.length;
    run_floor_ = std::max(run_floor_, e.merge_deviation);
    ++merged_;
    return;
  }
  flush_run();
  const bool mergeable = naive_tolerance_ > 0 && e.mode == canon::MotionControl::Continuous &&
                         e.b.kind == traj::BlockKind::Line && e.b.feed_class == FeedClass::Feed &&
                         !e.stop_after;
  if (mergeable) {
    run_active_ = true;
    run_ = e;
    run_start_ = e.b.base;
    run_feed_ = program_->feed(e.b.segment_first);
    run_floor_ = e.merge_deviation;
    return;
  }
  Item& it = ready_.append();
  it.is_marker = false;
  it.element = e;
}

// Short feed lines go to the smoother first; what it does not take, or gives back unfitted, goes
// on to G64 Q's merge. The merge's open run comes before the smoother's moves, so it is closed
// when a smoother run begins and before fitted spans go out.
void ProgramReader::take_element(const Element& e) {
  if (smoothing_) {
    if (!smoother_.accepts(e)) flush_smoother();
    if (smoother_.accepts(e)) {
      if (smoother_.empty()) flush_run();
      smoother_.add(e);
      if (smoother_.full()) {  // the fitted curve so far goes out; the run goes on without a kink
        smoothed_.clear();
        smoother_.flush_part(smoothed_);
        put_smoothed();
      }
      return;
    }
  }
  push_element(e);
}

void ProgramReader::flush_smoother() {
  if (smoother_.empty()) return;
  smoothed_.clear();
  smoother_.flush(smoothed_);
  put_smoothed();
}

void ProgramReader::put_smoothed() {
  for (const Element& e : smoothed_) {
    if (e.b.kind != traj::BlockKind::Bezier) {  // given back as it came
      push_element(e);
      continue;
    }
    flush_run();
    Item& it = ready_.append();
    it.is_marker = false;
    it.element = e;
  }
}

void ProgramReader::read_move(canon::SegmentId id) {
  ++moves_read_;
  Element e;
  if (!make_element(id, e)) return;
  take_element(e);
  if (e.stop_after) {  // the controller reads the probe result before anything goes on
    flush_run();
    traj::MotionBlock& m = new_marker();
    m.marker = MarkerKind::Sync;
    m.segment = m.segment_first = m.segment_last = id + 1;
    m.line = e.b.line;
    m.context = e.b.context;
    m.action = traj::kNoAction;
  }
}

// Reads the next move (with the actions before it), or at the end of a stream what can be read
// for now; returns false when nothing could be.
bool ProgramReader::read_more() {
  const std::size_t n = readable_limit();
  if (next_move_ < n) {
    read_actions_before(static_cast<std::uint32_t>(next_move_));
    read_move(next_move_++);
    return true;
  }
  if (streaming_) {
    // The actions after the last readable move are complete: they come before whatever follows.
    const std::size_t before = ready_.size();
    read_actions_before(static_cast<std::uint32_t>(n));
    if (flush_) {
      flush_ = false;
      flush_smoother();
      flush_run();
    }
    return ready_.size() != before;
  }
  read_actions_before(static_cast<std::uint32_t>(n));
  flush_smoother();
  flush_run();
  if (!ended_) {  // a program without M2/M30 still ends with a stop
    traj::MotionBlock& m = new_marker();
    m.marker = MarkerKind::ProgramEnd;
    m.segment = m.segment_first = m.segment_last = n;
    m.action = traj::kNoAction;
    ended_ = true;
  }
  done_ = true;
  return true;
}

Item* ProgramReader::next() {
  if (handed_out_) ready_.pop_front();
  // Keep a run open until something else arrives, so that merging can look ahead.
  while (ready_.empty() && !done_) {
    if (!read_more()) break;
  }
  handed_out_ = !ready_.empty();
  return handed_out_ ? &ready_.front() : nullptr;
}

}  // namespace opencnc::plan::detail
