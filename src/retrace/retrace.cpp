// SPDX-License-Identifier: GPL-3.0-or-later
// The retrace feature: its state machine over the controller's events and status, the path index
// built in the background, and the auxiliary programs it runs (torch off, approach and re-light,
// steps along the path).
#include "opencnc/retrace/retrace.hpp"

#include <cmath>

#include <fmt/format.h>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/retrace/path_scan.hpp"

namespace opencnc::recovery {

using control::CommandKind;
using control::Mode;
using control::State;
using controller::ControllerEventKind;
using controller::JobEnd;
using controller::JobKind;
using controller::Outcome;
using controller::Request;

namespace {

Outcome refuse(std::string why) {
  Outcome o;
  o.accepted = false;
  o.refusal = control::Refusal::BadValue;
  o.message = std::move(why);
  return o;
}

// Start and step move the machine: only from a pause with the machine standing and no job.
std::optional<Outcome> refuse_unless_paused_and_idle(RetracePhase phase,
                                                     const controller::ControllerStatus& s) {
  if (phase != RetracePhase::Paused)
    return refuse(fmt::format("retrace is {}, not paused", to_string(phase)));
  if (s.servo.state != State::Idle || s.run_active)
    return refuse(fmt::format("the machine is not idle ({}{})", control::to_string(s.servo.state),
                              s.run_active ? ", a job runs" : ""));
  return std::nullopt;
}

Outcome accept(std::string message = {}) {
  Outcome o;
  o.accepted = true;
  o.message = std::move(message);
  return o;
}

Vec3 xyz(const Pose& p) {
  return {p[0], p[1], p[2]};
}

Pose with_xyz(Pose p, double x, double y, double z) {
  p[0] = x;
  p[1] = y;
  p[2] = z;
  return p;
}

/// The auxiliary moves go exactly along their lines (G61): a blended corner between the move
/// over to C and the plunge to the pierce height would lower the torch while it still travels.
void exact_path(canon::ProgramBuilder& b) {
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
}

/// Steps along the path at most this long: the chords of an arc stay within 0.03 mm of it for
/// radii from 4 mm (sagitta l²/8r).
constexpr double kStepChordMm = 1.0;

}  // namespace

const char* to_string(RetracePhase p) noexcept {
  switch (p) {
    case RetracePhase::Idle:
      return "idle";
    case RetracePhase::Holding:
      return "holding";
    case RetracePhase::Stopping:
      return "stopping";
    case RetracePhase::TorchOff:
      return "torch-off";
    case RetracePhase::Paused:
      return "paused";
    case RetracePhase::Stepping:
      return "stepping";
    case RetracePhase::Approaching:
      return "approaching";
    case RetracePhase::Cutting:
      return "cutting";
  }
  return "";
}

RetraceFeature::RetraceFeature(std::shared_ptr<controller::ProgramSource> source,
                               const config::MachineProfile& profile)
    : source_(std::move(source)), cutting_(profile.cutting), status_period_s_(profile.servo_period_s) {
  for (const config::AxisProfile& a : profile.axes) {
    if (a.axis == Axis::X || a.axis == Axis::Y) min_accel_ = std::min(min_accel_, a.max_acceleration);
  }
  jerk_filter_s_ = plan::jerk_filter_s(controller::machine_limits(profile), profile.servo_period_s);
}

RetraceFeature::~RetraceFeature() {
  join();
}

std::vector<RetraceRecord> RetraceFeature::records() const {
  std::lock_guard lock(records_mutex_);
  return records_;
}

// --- the index -------------------------------------------------------------------------------

void RetraceFeature::build_index(const std::string& path, const Pose& start) {
  join();
  index_.reset();
  building_ = std::make_unique<PathIndex>();
  index_diags_ = {};
  // The scan runs beside the controller; the feature reads the result only after joining.
  builder_ = std::thread([this, path, start] {
    Diagnostics d;
    *building_ = scan_path(*source_, path, start, {}, d);
    index_diags_ = std::move(d);
  });
}

void RetraceFeature::join() {
  if (builder_.joinable()) builder_.join();
}

const PathIndex* RetraceFeature::index() {
  join();
  if (building_) index_ = std::move(building_);
  return index_.get();
}

std::string RetraceFeature::describe(const PathPoint& p) const {
  if (!index_ || !index_->sources()) return fmt::format("line {}", p.line);
  return controller::to_string(controller::locate(*index_->sources(), p.context, p.line));
}

// --- requests --------------------------------------------------------------------------------

Outcome RetraceFeature::handle(const controller::requests::Feature& r, controller::FeatureHost& host) {
  host_ = &host;
  if (r.action == "pause") return pause(host);
  if (r.action == "start") {
    const auto* args = std::any_cast<RetraceStart>(&r.args);
    return start(args != nullptr ? *args : RetraceStart{}, host);
  }
  if (r.action == "step") {
    const auto* args = std::any_cast<RetraceStep>(&r.args);
    if (args == nullptr) return refuse("retrace.step needs a distance (RetraceStep)");
    return step(*args, host);
  }
  if (r.action == "nearest") {
    const auto* b = std::any_cast<Vec3>(&r.args);
    if (b == nullptr) return refuse("retrace.nearest needs a point (x, y, z)");
    const PathIndex* ix = index();
    if (ix == nullptr) return refuse("no program is open");
    const Nearest n = ix->nearest(*b);
    if (!n.found) return refuse("the program has no feed moves");
    return accept(
        fmt::format("C ({:.4f}, {:.4f}, {:.4f}) on segment {} ({}), {:.4f} mm away; {} candidate(s)",
                    n.nearest.point[0], n.nearest.point[1], n.nearest.point[2], n.nearest.segment,
                    describe(n.nearest), n.nearest.distance_mm, n.candidates.size()));
  }
  if (r.action == "index") {
    const PathIndex* ix = index();
    if (ix == nullptr) return refuse("no program is open");
    return accept(fmt::format("{} feed moves indexed", ix->size()));
  }
  return refuse(fmt::format("retrace has no action '{}' (pause, start, step, nearest, index)", r.action));
}

Outcome RetraceFeature::pause(controller::FeatureHost& host) {
  const controller::ControllerStatus& s = host.current_status();
  if (phase() != RetracePhase::Idle && phase() != RetracePhase::Cutting)
    return refuse(fmt::format("retrace is {}", to_string(phase())));
  if (!s.run_active || s.job != JobKind::Program) return refuse("no program is running");
  if (s.servo.state != State::Held) pending_ = host.submit(Request::simple(CommandKind::FeedHold));
  set_phase(RetracePhase::Holding);
  return accept("feed hold; the torch goes out when the machine stands");
}

Outcome RetraceFeature::start(const RetraceStart& args, controller::FeatureHost& host) {
  if (std::optional<Outcome> no = refuse_unless_paused_and_idle(phase(), host.current_status())) return *no;
  const controller::ControllerStatus& s = host.current_status();
  const PathIndex* ix = index();
  if (ix == nullptr) return refuse("no program is open");
  QueryOptions q;
  q.metric = args.metric;
  q.margin_mm = args.margin_mm;
  const Pose b = s.servo.commanded;
  const Nearest n = ix->nearest(xyz(b), q);
  if (!n.found) return refuse("the program has no feed moves");
  if (args.candidate >= n.candidates.size())
    return refuse(fmt::format("there are {} candidates, not {}", n.candidates.size(), args.candidate + 1));
  const PathPoint& c = n.candidates[args.candidate];
  RetraceRecord rec;
  rec.a = a_position_;
  rec.a_known = a_.has_value();
  rec.b = xyz(b);
  rec.c = c.point;
  rec.segment = c.segment;
  rec.move = c.move;
  rec.line = describe(c);
  rec.distance_mm = c.distance_mm;
  rec.candidates = n.candidates.size();
  {
    std::lock_guard lock(records_mutex_);
    records_.push_back(rec);
  }
  c_ = c;
  stop_at_a_ = args.stop_at_a;
  next_aux_ = approach_program(b, c.point);
  next_aux_name_ = "retrace approach";
  pending_ = host.submit(Request::set_mode(Mode::Auto));
  set_phase(RetracePhase::Approaching);
  return accept(fmt::format("to C ({:.4f}, {:.4f}) on segment {} ({}), {:.3f} mm from here", c.point[0],
                            c.point[1], c.segment, rec.line, c.distance_mm));
}

Outcome RetraceFeature::step(const RetraceStep& args, controller::FeatureHost& host) {
  if (std::optional<Outcome> no = refuse_unless_paused_and_idle(phase(), host.current_status())) return *no;
  const controller::ControllerStatus& s = host.current_status();
  const PathIndex* ix = index();
  if (ix == nullptr || ix->size() == 0) return refuse("no program is open");
  if (!cursor_set_) {
    cursor_ = ix->nearest(xyz(s.servo.commanded)).nearest;
    cursor_set_ = true;
  }
  const PathPoint to = ix->advance(cursor_, args.distance_mm);
  next_aux_ = step_program(s.servo.commanded, cursor_, args.distance_mm);
  next_aux_name_ = "retrace step";
  cursor_ = to;
  pending_ = host.submit(Request::set_mode(Mode::Auto));
  set_phase(RetracePhase::Stepping);
  return accept(
      fmt::format("along the path to ({:.4f}, {:.4f}) on segment {}", to.point[0], to.point[1], to.segment));
}

// --- the state machine -----------------------------------------------------------------------

void RetraceFeature::on_event(const controller::ControllerEvent& e) {
  switch (e.kind) {
    case ControllerEventKind::ProgramOpened:
      if (host_ != nullptr) build_index(e.text, host_->current_status().servo.commanded);
      a_.reset();
      cursor_set_ = false;
      base_move_ = 0;
      return;
    case ControllerEventKind::JobStarted:
      if (e.job == JobKind::Program) base_move_ = phase() == RetracePhase::Cutting && c_ ? c_->move : 0;
      return;
    case ControllerEventKind::JobEnded:
      return when_job_ended(e);
    case ControllerEventKind::Answer:
      if (e.request_id == pending_ && !e.accepted && host_ != nullptr) {
        host_->note(Severity::Error, "retrace.refused", fmt::format("retrace: {} (still paused)", e.text));
        next_aux_.reset();
        set_phase(phase() == RetracePhase::Holding ? RetracePhase::Idle : RetracePhase::Paused);
        if (phase() == RetracePhase::Paused) host_->submit(Request::set_mode(Mode::Manual));
      }
      return;
    default:
      return;
  }
}

void RetraceFeature::on_status(const controller::ControllerStatus& s) {
  if (phase() == RetracePhase::Holding) return when_held(s);
  if (phase() == RetracePhase::Cutting) return check_stop_at_a(s);
  // Auto mode asked for an auxiliary program: it starts once the servo has switched.
  if (next_aux_ && s.servo.mode == Mode::Auto && s.servo.state == State::Idle && !s.run_active) {
    auto program = std::move(next_aux_);
    next_aux_.reset();
    run_auxiliary(next_aux_name_, std::move(program));
  }
}

void RetraceFeature::when_held(const controller::ControllerStatus& s) {
  if (s.servo.state != State::Held || s.servo.path_velocity != 0 || host_ == nullptr) return;
  a_position_ = xyz(s.servo.commanded);
  a_offset_ = s.segment_offset;
  const std::uint64_t move = base_move_ + s.run_segment;
  if (const PathIndex* ix = index()) a_ = ix->at_move(move, s.segment_offset);
  if (a_) {
    a_->move = move;
    cursor_ = *a_;
    cursor_set_ = true;
  }
  pending_ = host_->submit(Request::simple(CommandKind::Abort));
  set_phase(RetracePhase::Stopping);
}

void RetraceFeature::when_job_ended(const controller::ControllerEvent& e) {
  if (host_ == nullptr) return;
  switch (phase()) {
    case RetracePhase::Stopping:
      if (e.job != JobKind::Program) return;
      set_phase(RetracePhase::TorchOff);
      run_auxiliary("retrace torch off", torch_off_program(host_->current_status().servo.commanded));
      return;
    case RetracePhase::TorchOff:
    case RetracePhase::Stepping:
      if (e.job != JobKind::Auxiliary) return;
      host_->submit(Request::set_mode(Mode::Manual));
      set_phase(RetracePhase::Paused);
      return;
    case RetracePhase::Approaching:
      if (e.job != JobKind::Auxiliary) return;
      if (e.end != JobEnd::Finished || !c_) {
        host_->note(Severity::Error, "retrace.approach",
                    "retrace: the approach did not finish (still paused)");
        host_->submit(Request::set_mode(Mode::Manual));
        set_phase(RetracePhase::Paused);
        return;
      }
      set_phase(RetracePhase::Cutting);
      pending_ = host_->submit(Request::resume(c_->segment));
      return;
    case RetracePhase::Cutting:
      if (e.job != JobKind::Program) return;
      set_phase(RetracePhase::Idle);
      return;
    default:
      return;
  }
}

void RetraceFeature::check_stop_at_a(const controller::ControllerStatus& s) {
  if (!stop_at_a_ || !a_ || !c_ || !s.run_active || s.job != JobKind::Program || host_ == nullptr) return;
  if (c_->move > a_->move) return;  // B was ahead of A: the cut skipped forward past it
  const std::uint64_t move = base_move_ + s.run_segment;
  // The hold begins where the machine can still stop at A: the braking distance v²/2a (the
  // slowest of X and Y), with jerk limits the v·T/2 the commanded point trails the braking
  // generator by (plan::jerk_filter_s), and one status period ahead of it, measured straight to A
  // (never longer than along the path, so the stop comes at A or just before it).
  const bool passed = move > a_->move || (move == a_->move && s.segment_offset >= a_offset_);
  const double v = s.servo.path_velocity;
  const double brake = v * v / (2 * min_accel_) + v * (0.5 * jerk_filter_s_ + status_period_s_);
  const bool near = move + 2 >= a_->move && std::hypot(a_->point[0] - s.servo.commanded[0],
                                                       a_->point[1] - s.servo.commanded[1]) <= brake;
  if (!passed && !near) return;
  stop_at_a_ = false;
  host_->note(Severity::Note, "retrace.at-a",
              fmt::format("retrace: back at A ({:.3f}, {:.3f}): cut on (start at A) or retrace elsewhere",
                          a_position_[0], a_position_[1]));
  pause(*host_);
}

void RetraceFeature::run_auxiliary(const char* name, std::shared_ptr<const canon::Program> program) {
  pending_ = host_->submit(Request::run_auxiliary(name, std::move(program)));
}

// --- the auxiliary programs --------------------------------------------------------------------

std::shared_ptr<const canon::Program> RetraceFeature::torch_off_program(const Pose& at) const {
  canon::ProgramBuilder b(host_->profile().axis_mask(), at);
  exact_path(b);
  // Cutting oxygen first, then preheat, then the flame: the profile's order of putting it out.
  for (int output : {cutting_.cut_output, cutting_.preheat_output, cutting_.torch_output}) {
    if (output >= 0) b.clear_aux_output_bit(output);
  }
  if (cutting_.has_safe_height && at[2] < cutting_.safe_height_mm)
    b.straight_traverse(0, with_xyz(at, at[0], at[1], cutting_.safe_height_mm));
  return std::make_shared<canon::Program>(b.take());
}

std::shared_ptr<const canon::Program> RetraceFeature::approach_program(const Pose& from,
                                                                       const Vec3& c) const {
  canon::ProgramBuilder b(host_->profile().axis_mask(), from);
  exact_path(b);
  canon::SegmentId id = 0;
  const double travel_z = cutting_.has_safe_height ? cutting_.safe_height_mm : std::max(from[2], c[2]);
  if (from[2] != travel_z) b.straight_traverse(id++, with_xyz(from, from[0], from[1], travel_z));
  const Pose above = with_xyz(from, c[0], c[1], travel_z);
  if (cutting_.approach_mm_min > 0) {
    b.set_feed_rate(cutting_.approach_mm_min);
    b.straight_feed(id++, above);
  } else {
    b.straight_traverse(id++, above);
  }
  const double pierce_z = std::min(travel_z, c[2] + cutting_.pierce_lift_mm);
  if (pierce_z != travel_z) b.straight_traverse(id++, with_xyz(from, c[0], c[1], pierce_z));
  // Ignite, preheat, pierce: each output on, then its time.
  const std::pair<int, double> sequence[] = {{cutting_.torch_output, cutting_.ignite_s},
                                             {cutting_.preheat_output, cutting_.preheat_s},
                                             {cutting_.cut_output, cutting_.pierce_s}};
  for (const auto& [output, seconds] : sequence) {
    if (output >= 0) b.set_aux_output_bit(output);
    if (seconds > 0) b.dwell(seconds);
  }
  if (pierce_z != c[2]) {
    b.set_feed_rate(cutting_.retrace_mm_min);
    b.straight_feed(id++, with_xyz(from, c[0], c[1], c[2]));
  }
  return std::make_shared<canon::Program>(b.take());
}

std::shared_ptr<const canon::Program> RetraceFeature::step_program(const Pose& from, const PathPoint& along,
                                                                   double distance_mm) const {
  canon::ProgramBuilder b(host_->profile().axis_mask(), from);
  exact_path(b);
  b.set_feed_rate(cutting_.retrace_mm_min);
  canon::SegmentId id = 0;
  // Onto the path where stepping goes on from, then along it in chords, at the torch's height.
  if (from[0] != along.point[0] || from[1] != along.point[1])
    b.straight_feed(id++, with_xyz(from, along.point[0], along.point[1], from[2]));
  const auto chords = static_cast<long>(std::ceil(std::fabs(distance_mm) / kStepChordMm));
  for (long i = 1; i <= chords; ++i) {
    const PathPoint p =
        index_->advance(along, distance_mm * static_cast<double>(i) / static_cast<double>(chords));
    b.straight_feed(id++, with_xyz(from, p.point[0], p.point[1], from[2]));
  }
  return std::make_shared<canon::Program>(b.take());
}

}  // namespace opencnc::recovery
