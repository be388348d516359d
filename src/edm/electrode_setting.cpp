// SPDX-License-Identifier: GPL-3.0-or-later
// Electrode setting: the touches planned around the reference sphere, their auxiliary programs,
// the evaluation of the touch points, and the feature's state machine over the controller's events.
#include "opencnc/edm/electrode_setting.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/edm/sphere_fit.hpp"

namespace opencnc::edm {

namespace {

controller::Outcome refuse(std::string why) {
  controller::Outcome o;
  o.refusal = control::Refusal::BadValue;
  o.message = std::move(why);
  return o;
}

controller::Outcome accept(std::string message) {
  controller::Outcome o;
  o.accepted = true;
  o.message = std::move(message);
  return o;
}

Pose with_xyz(Pose p, const Vec3& xyz) {
  for (int i = 0; i < 3; ++i) p[i] = xyz[static_cast<std::size_t>(i)];
  return p;
}

Vec3 xyz(const Pose& p) {
  return {p[0], p[1], p[2]};
}

Vec3 offsets_of(const tools::ToolEntry& e) {
  return {e.offset[0], e.offset[1], e.offset[2]};
}

std::string show(const Vec3& p) {
  return fmt::format("X{:.4f} Y{:.4f} Z{:.4f}", p[0], p[1], p[2]);
}

/// The touch directions' names: the axes where they lie on one, else the angle.
std::string around_name(int k, int n) {
  static const char* const kAxisNames[] = {"+X", "+Y", "-X", "-Y"};
  if ((4 * k) % n == 0) return kAxisNames[(4 * k) / n];
  return fmt::format("{:g}°", 360.0 * k / n);
}

/// A touch that closed the contact closer than this to its start began in contact, mm.
constexpr double kMinTravelMm = 0.001;
/// … and one latched farther than this off the probe move's line closed it on the way there.
constexpr double kMaxLateralMm = 0.002;

/// Whether the contact closed during the probe move: the servo's latch of the edge lies on the
/// move's line, past its start. A contact closed before (the electrode went down into the sphere,
/// or met something on the way) latches where it closed, and the probe move trips at once.
bool on_probe_path(const SphereTouch& t, const Vec3& at) {
  Vec3 d{}, v{};
  for (std::size_t i = 0; i < 3; ++i) {
    d[i] = t.end[i] - t.start[i];
    v[i] = at[i] - t.start[i];
  }
  const double length = std::hypot(d[0], d[1], d[2]);
  const double along = (v[0] * d[0] + v[1] * d[1] + v[2] * d[2]) / length;
  double lateral2 = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const double w = v[i] - along * d[i] / length;
    lateral2 += w * w;
  }
  return along >= kMinTravelMm && std::sqrt(lateral2) <= kMaxLateralMm;
}

}  // namespace

const char* to_string(ElectrodePhase p) noexcept {
  switch (p) {
    case ElectrodePhase::Idle:
      return "idle";
    case ElectrodePhase::Measuring:
      return "measuring";
    case ElectrodePhase::Approaching:
      return "approaching";
    case ElectrodePhase::Resuming:
      return "resuming";
    case ElectrodePhase::Calibrating:
      return "calibrating";
  }
  return "";
}

// --- planning and evaluation -------------------------------------------------------------------

std::vector<SphereTouch> plan_touches(const config::ReferenceSphereProfile& sphere, const Vec3& offset,
                                      double tip_radius) {
  const double reach = sphere.diameter / 2 + tip_radius;  // tip ball's centre to the sphere's centre
  // The controlled point that puts the tip ball's centre at q.
  const auto controlled = [&](const Vec3& q) {
    return Vec3{q[0] + offset[0], q[1] + offset[1], q[2] + offset[2] - tip_radius};
  };
  const auto touch = [&](std::string name, const Vec3& u) {
    SphereTouch t;
    t.name = std::move(name);
    t.direction = u;
    Vec3 out{}, in{};
    for (std::size_t i = 0; i < 3; ++i) {
      out[i] = sphere.position[i] + (reach + sphere.clearance) * u[i];
      in[i] = sphere.position[i] + (reach - sphere.clearance) * u[i];
    }
    t.start = controlled(out);
    t.end = controlled(in);
    return t;
  };
  std::vector<SphereTouch> plan;
  const int n = sphere.touches_around;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * k / n;
    plan.push_back(touch(around_name(k, n), {std::cos(a), std::sin(a), 0.0}));
  }
  plan.push_back(touch("top", {0.0, 0.0, 1.0}));
  return plan;
}

std::shared_ptr<const canon::Program> touch_program(AxisMask axes, const Pose& from, const SphereTouch& touch,
                                                    const config::ReferenceSphereProfile& sphere,
                                                    bool turn_b) {
  canon::ProgramBuilder b(axes, from);
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);  // no blended corner near the sphere
  canon::SegmentId id = 0;
  Pose at = from;
  const auto traverse = [&](const Pose& to) {
    if (to == at) return;
    b.straight_traverse(id++, to);
    at = to;
  };
  // Over at the safe height (or higher, where the machine already is), then straight down.
  const double travel_z = std::max(at[2], sphere.safe_z);
  traverse(with_xyz(at, {at[0], at[1], travel_z}));
  if (turn_b) {
    Pose turned = at;
    turned[Axis::B] = sphere.b_deg;
    traverse(turned);
  }
  traverse(with_xyz(at, {touch.start[0], touch.start[1], travel_z}));
  traverse(with_xyz(at, touch.start));
  const bool fast = sphere.fast_feed > 0;
  b.set_feed_rate(fast ? sphere.fast_feed : sphere.probe_feed);
  b.straight_probe(id++, with_xyz(at, touch.end));
  if (!fast) {
    // After the contact the rest runs from where the machine stopped: back out, then up.
    b.straight_traverse(id++, with_xyz(at, touch.start));
    b.straight_traverse(id++, with_xyz(at, {touch.start[0], touch.start[1], sphere.safe_z}));
  }
  return std::make_shared<canon::Program>(b.take());
}

std::shared_ptr<const canon::Program> slow_touch_program(AxisMask axes, const Pose& from,
                                                         const SphereTouch& touch, const Vec3& contact,
                                                         const config::ReferenceSphereProfile& sphere,
                                                         SphereTouch& slow) {
  Vec3 u{};  // along the probe move
  const double length =
      std::hypot(touch.end[0] - touch.start[0], touch.end[1] - touch.start[1], touch.end[2] - touch.start[2]);
  for (std::size_t i = 0; i < 3; ++i) u[i] = (touch.end[i] - touch.start[i]) / length;
  slow = touch;
  for (std::size_t i = 0; i < 3; ++i) {
    slow.start[i] = contact[i] - sphere.back_off * u[i];
    slow.end[i] = contact[i] + sphere.back_off * u[i];
  }
  canon::ProgramBuilder b(axes, from);
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
  canon::SegmentId id = 0;
  b.straight_traverse(id++, with_xyz(from, slow.start));
  b.set_feed_rate(sphere.probe_feed);
  b.straight_probe(id++, with_xyz(from, slow.end));
  b.straight_traverse(id++, with_xyz(from, touch.start));
  b.straight_traverse(id++, with_xyz(from, {touch.start[0], touch.start[1], sphere.safe_z}));
  return std::make_shared<canon::Program>(b.take());
}

ElectrodeResult evaluate_touches(const config::ReferenceSphereProfile& sphere, int tool, const Vec3& previous,
                                 double tip_radius, std::span<const std::string> names,
                                 std::span<const Vec3> touched) {
  ElectrodeResult r;
  r.tool = tool;
  r.tip_radius = tip_radius;
  r.previous = previous;
  r.names.assign(names.begin(), names.end());
  r.touched.assign(touched.begin(), touched.end());
  // The tip ball's centre is the controlled point less the offsets plus the tip radius up: fit
  // the controlled points lifted by the tip radius, and the centre found is sphere + offsets.
  std::vector<Vec3> lifted(touched.begin(), touched.end());
  for (Vec3& p : lifted) p[2] += tip_radius;
  Vec3 guess{};
  for (std::size_t i = 0; i < 3; ++i) guess[i] = sphere.position[i] + previous[i];
  guess[2] -= tip_radius;
  const std::optional<SphereFit> fit = fit_sphere(lifted, sphere.diameter / 2 + tip_radius, guess);
  if (!fit) {
    r.code = "electrode.fit";
    r.message = fmt::format("the {} touches do not fix a sphere's centre", touched.size());
    return r;
  }
  r.centre = fit->centre;
  r.centre[2] -= tip_radius;
  r.rms_residual_mm = fit->rms_residual;
  r.max_residual_mm = fit->max_residual;
  for (std::size_t i = 0; i < 3; ++i) r.offset[i] = fit->centre[i] - sphere.position[i];
  if (fit->max_residual > sphere.tolerance) {
    r.code = "electrode.fit";
    std::size_t worst = 0;
    for (std::size_t i = 1; i < fit->residuals.size(); ++i) {
      if (std::fabs(fit->residuals[i]) > std::fabs(fit->residuals[worst])) worst = i;
    }
    r.message = fmt::format(
        "the touches are not on a sphere of {:g} mm: the touch from {} is {:.4f} mm off it (tolerance {:g} "
        "mm); "
        "dirt on the sphere or the electrode, or a loose sphere",
        sphere.diameter + 2 * tip_radius, worst < names.size() ? names[worst] : "?", fit->residuals[worst],
        sphere.tolerance);
    return r;
  }
  const double moved =
      std::hypot(r.offset[0] - previous[0], r.offset[1] - previous[1], r.offset[2] - previous[2]);
  if (moved > sphere.max_deviation) {
    r.code = "electrode.far";
    r.message = fmt::format(
        "the sphere was found {:.4f} mm from where the profile and tool {}'s offsets put it (at most {:g} "
        "mm): "
        "check the sphere's position in the profile and the electrode in the spindle",
        moved, tool, sphere.max_deviation);
    return r;
  }
  r.ok = true;
  r.message = fmt::format("tool {}: offsets {} (were {}), fit residual {:.4f} mm rms", tool, show(r.offset),
                          show(previous), r.rms_residual_mm);
  return r;
}

// --- the feature -------------------------------------------------------------------------------

ElectrodeSetting::ElectrodeSetting(std::shared_ptr<tools::ToolTableService> tools,
                                   const config::MachineProfile& profile)
    : tools_(std::move(tools)),
      profile_sphere_(profile.probe.reference_sphere),
      sphere_(profile_sphere_),
      at_(profile_sphere_),
      axes_(profile.axis_mask()) {}

config::ReferenceSphereProfile ElectrodeSetting::sphere() const {
  std::lock_guard lock(mutex_);
  return sphere_;
}

std::optional<BAxisResult> ElectrodeSetting::last_b_axis() const {
  std::lock_guard lock(mutex_);
  return last_b_;
}

ElectrodePhase ElectrodeSetting::phase() const {
  std::lock_guard lock(mutex_);
  return phase_;
}

std::optional<ElectrodeResult> ElectrodeSetting::last() const {
  std::lock_guard lock(mutex_);
  return last_;
}

std::optional<ProgramStop> ElectrodeSetting::stop() const {
  std::lock_guard lock(mutex_);
  return stop_;
}

void ElectrodeSetting::set_phase(ElectrodePhase p) {
  std::lock_guard lock(mutex_);
  phase_ = p;
}

controller::Outcome ElectrodeSetting::handle(const controller::requests::Feature& request,
                                             controller::FeatureHost& host) {
  host_ = &host;
  if (request.action == "measure") {
    const auto* args = std::any_cast<ElectrodeMeasure>(&request.args);
    if (args == nullptr) return refuse("electrode measure needs the tool number (ElectrodeMeasure)");
    return measure(*args, host);
  }
  if (request.action == "resume") return resume(host);
  if (request.action == "write") return write();
  if (request.action == "calibrate-b") {
    const auto* args = std::any_cast<BAxisCalibrate>(&request.args);
    if (args == nullptr)
      return refuse("electrode calibrate-b needs the tool and the angles (BAxisCalibrate)");
    return calibrate_b(*args, host);
  }
  return refuse(
      fmt::format("electrode: unknown action \"{}\" (measure, write, resume, calibrate-b)", request.action));
}

controller::Outcome ElectrodeSetting::measure(const ElectrodeMeasure& args, controller::FeatureHost& host) {
  if (std::optional<controller::Outcome> refused = start_measurement(args.tool, args.b_deg, host))
    return *refused;
  write_ = args.write;
  set_phase(ElectrodePhase::Measuring);
  next_touch();
  return accept(fmt::format("measuring tool {} against the reference sphere{}: {} touches", tool_,
                            args.b_deg ? fmt::format(" with B at {:g}°", *args.b_deg) : "", plan_.size()));
}

// The checks and the plan of one measurement with B at `b_deg` (the profile's b if absent): a
// refusal, or nothing when the touches are planned.
std::optional<controller::Outcome> ElectrodeSetting::start_measurement(int tool, std::optional<double> b_deg,
                                                                       controller::FeatureHost& host) {
  if (!sphere_.present) return refuse("the profile has no [probe.reference_sphere]");
  if (phase() != ElectrodePhase::Idle)
    return refuse(fmt::format("electrode setting is {}", to_string(phase())));
  const controller::ControllerStatus& s = host.current_status();
  if (s.servo.state != control::State::Idle || s.run_active)
    return refuse(fmt::format("the machine is not idle ({}{})", to_string(s.servo.state),
                              s.run_active ? ", a job runs" : ""));
  if (!s.servo.all_homed) return refuse("the machine is not homed");
  if (tools_ == nullptr) return refuse("the machine has no tool table");
  const double b = b_deg.value_or(sphere_.b_deg);
  if (b_deg && !axes_.has(Axis::B)) return refuse("the machine has no B axis to measure at an angle of");
  if (b_deg && !std::isfinite(*b_deg)) return refuse("the B angle must be a finite number");
  if (b != sphere_.b_deg && !sphere_.has_b_axis)
    return refuse(
        fmt::format("B's axis is not known (probe.reference_sphere.b_axis): the sphere can be measured only "
                    "with B at {:g}° "
                    "until calibrate-b has measured it",
                    sphere_.b_deg));
  const auto table = tools_->snapshot();
  const std::optional<std::size_t> index = table->find(tool);
  if (tool <= 0 || !index) return refuse(fmt::format("tool {} is not in the tool table", tool));
  tool_ = tool;
  tool_index_ = *index;
  entry_ = table->at_index(*index);
  // The sphere as B turns it: its centre there, and B turned there by the first touch.
  at_ = sphere_;
  at_.position = sphere_centre_at(sphere_, b);
  at_.b_deg = b;
  plan_ = plan_touches(at_, offsets_of(entry_), entry_.diameter / 2);
  const double top_start = plan_.back().start[2];
  if (top_start > at_.safe_z)
    return refuse(fmt::format(
        "tool {}'s touch from above starts at machine Z{:.3f}, above probe.reference_sphere.safe_z ({:g}): "
        "raise safe_z or check the tool's Z offset",
        tool_, top_start, at_.safe_z));
  touched_.clear();
  fast_touched_.clear();
  touch_ = 0;
  slow_ = false;
  return std::nullopt;
}

controller::Outcome ElectrodeSetting::calibrate_b(const BAxisCalibrate& args, controller::FeatureHost& host) {
  if (!axes_.has(Axis::B)) return refuse("the machine has no B axis");
  std::vector<double> distinct = args.angles_deg;
  std::sort(distinct.begin(), distinct.end());
  if (std::unique(distinct.begin(), distinct.end()) - distinct.begin() < 3 ||
      !std::all_of(distinct.begin(), distinct.end(), [](double a) { return std::isfinite(a); }))
    return refuse("calibrate-b needs at least three different B angles, spread over B's travel");
  // Each angle's sphere is looked for where the axis known so far turns it (the drawing's, or the
  // last calibration's): it must be found within the clearance.
  if (!sphere_.has_b_axis)
    return refuse(
        "calibrate-b looks for the sphere where B's nominal axis turns it: give "
        "probe.reference_sphere.b_axis "
        "from the machine's drawing (within the touches' clearance)");
  if (std::optional<controller::Outcome> refused = start_measurement(args.tool, args.angles_deg[0], host))
    return *refused;
  calibration_ = BAxisResult{};
  calibration_.tool = args.tool;
  calibration_.angles_deg = args.angles_deg;
  calibration_.previous = BAxisLine{sphere_.b_axis, sphere_.b_axis_direction};
  write_ = false;
  set_phase(ElectrodePhase::Calibrating);
  next_touch();
  return accept(fmt::format("calibrating B's axis with tool {}: the sphere at {} B angles", args.tool,
                            args.angles_deg.size()));
}

// One angle measured: its centre kept, then the next angle, or the fit once all are.
void ElectrodeSetting::next_calibration_angle(const ElectrodeResult& r) {
  BAxisResult& c = calibration_;
  const std::size_t done = c.centres.size();
  if (!r.ok) {
    c.code = r.code;
    c.message = fmt::format("with B at {:g}°: {}", c.angles_deg[done], r.message);
    return finish_calibration();
  }
  c.centres.push_back(r.centre);
  if (c.centres.size() < c.angles_deg.size()) {
    set_phase(ElectrodePhase::Idle);
    if (std::optional<controller::Outcome> refused =
            start_measurement(c.tool, c.angles_deg[c.centres.size()], *host_)) {
      c.code = "electrode.refused";
      c.message = fmt::format("with B at {:g}°: {}", c.angles_deg[c.centres.size()], refused->message);
      return finish_calibration();
    }
    set_phase(ElectrodePhase::Calibrating);
    return next_touch();
  }
  const std::optional<BAxisFit> fit = fit_b_axis(c.angles_deg, c.centres, sphere_);
  if (!fit) {
    c.code = "electrode.b-axis-fit";
    c.message = "the sphere's centres fix no axis (the same point at every angle, or on a line)";
  } else {
    c.fit = *fit;
    if (fit->max_residual_mm > sphere_.tolerance) {
      c.code = "electrode.b-axis-fit";
      c.message = fmt::format(
          "the sphere's centres are not on one circle about an axis: {:.4f} mm off it (tolerance {:g} mm); "
          "a loose sphere or table, or B's position is not what its encoder says",
          fit->max_residual_mm, sphere_.tolerance);
    } else {
      c.ok = true;
      c.message = fmt::format(
          "B's axis crosses X{:.4f} Z{:.4f} (at Y{:.4f}) along [{:.6f}, {:.6f}, {:.6f}]; the sphere {:.4f} "
          "mm "
          "from it; residual {:.4f} mm rms",
          fit->axis.crossing[0], fit->axis.crossing[1], sphere_.position[1], fit->axis.direction[0],
          fit->axis.direction[1], fit->axis.direction[2], fit->radius_mm, fit->rms_residual_mm);
    }
  }
  finish_calibration();
}

void ElectrodeSetting::finish_calibration() {
  BAxisResult& c = calibration_;
  {
    std::lock_guard lock(mutex_);
    if (c.ok) {
      sphere_.has_b_axis = true;
      sphere_.b_axis = c.fit.axis.crossing;
      sphere_.b_axis_direction = c.fit.axis.direction;
    }
    last_b_ = c;
    phase_ = ElectrodePhase::Idle;
  }
  next_aux_.reset();
  host_->note(c.ok ? Severity::Note : Severity::Error, c.ok ? "electrode.b-axis" : c.code,
              fmt::format("calibrate-b: {}{}", c.message, c.ok ? "" : " (the axis is unchanged)"));
}

void ElectrodeSetting::next_touch() {
  const SphereTouch& t = plan_[touch_];
  slow_ = false;
  next_aux_ = touch_program(axes_, host_->current_status().servo.commanded, t, at_,
                            touch_ == 0 && axes_.has(Axis::B));
  next_aux_name_ = fmt::format("electrode touch {}", t.name);
  if (host_->current_status().servo.mode != control::Mode::Auto)
    pending_ = host_->submit(controller::Request::set_mode(control::Mode::Auto));
}

controller::Outcome ElectrodeSetting::resume(controller::FeatureHost& host) {
  if (phase() != ElectrodePhase::Idle)
    return refuse(fmt::format("electrode setting is {}", to_string(phase())));
  const std::optional<ProgramStop> at = stop();
  if (!at) return refuse("no program stopped before its end since it was opened");
  const std::optional<ElectrodeResult> r = last();
  if (!r || !r->ok || !stop_offset_) return refuse("measure the new electrode first (electrode measure)");
  const controller::ControllerStatus& s = host.current_status();
  if (s.servo.state != control::State::Idle || s.run_active) return refuse("the machine is not idle");
  // The program's path moves with the tool's offsets (G43 adds them): so does the point to go on from.
  Pose target = at->position;
  for (std::size_t i = 0; i < 3; ++i) target[static_cast<int>(i)] += r->offset[i] - (*stop_offset_)[i];
  canon::ProgramBuilder b(axes_, s.servo.commanded);
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
  Pose p = s.servo.commanded;
  canon::SegmentId id = 0;
  // Over at a height from which the last `clearance` down is at the probe feed: a stop point above
  // safe_z (a sinker's work above the sphere) is not come at sideways.
  const double travel_z = std::max({p[2], sphere_.safe_z, target[2] + sphere_.clearance});
  const auto traverse = [&](const Pose& to) {
    if (to == p) return;
    b.straight_traverse(id++, to);
    p = to;
  };
  traverse(with_xyz(p, {p[0], p[1], travel_z}));
  Pose over = target;
  over[2] = travel_z;
  traverse(over);  // B and C too, at the safe height
  // Down at rapid to the clearance above the point, the last of it at the probe feed.
  const double slow_from = std::min(travel_z, target[2] + sphere_.clearance);
  traverse(with_xyz(target, {target[0], target[1], slow_from}));
  if (p != target) {
    b.set_feed_rate(sphere_.probe_feed);
    b.straight_feed(id++, target);
  }
  next_aux_ = std::make_shared<canon::Program>(b.take());
  next_aux_name_ = "electrode approach";
  set_phase(ElectrodePhase::Approaching);
  if (s.servo.mode != control::Mode::Auto)
    pending_ = host.submit(controller::Request::set_mode(control::Mode::Auto));
  return accept(
      fmt::format("back to where the program stopped (segment {}), moved by the new offsets", at->segment));
}

// --- the state machine -----------------------------------------------------------------------

void ElectrodeSetting::on_trace(const control::TraceSample& s, const controller::TraceContext& c) {
  if (c.job != controller::JobKind::Program || c.program == nullptr ||
      s.activity != control::Activity::Program)
    return;
  if (s.segment < c.program->first_held_move() || s.segment >= c.program->size()) return;
  running_segment_ = c.program->segment_of(s.segment);
  running_position_ = s.commanded;
  running_seen_ = true;
}

void ElectrodeSetting::on_event(const controller::ControllerEvent& e) {
  switch (e.kind) {
    case controller::ControllerEventKind::ProgramOpened: {
      std::lock_guard lock(mutex_);
      stop_.reset();
      stop_offset_.reset();
      running_seen_ = false;
      return;
    }
    case controller::ControllerEventKind::JobStarted:
      if (e.job == controller::JobKind::Program) {
        running_seen_ = false;
        if (phase() == ElectrodePhase::Resuming) set_phase(ElectrodePhase::Idle);
      }
      return;
    case controller::ControllerEventKind::JobEnded:
      if (e.job == controller::JobKind::Program) {
        std::lock_guard lock(mutex_);
        if (e.end == controller::JobEnd::Finished) {
          stop_.reset();
        } else if (running_seen_) {
          stop_ = ProgramStop{running_segment_, running_position_};
          stop_offset_.reset();
        }
        return;
      }
      if (e.job == controller::JobKind::Auxiliary) when_aux_ended(e);
      return;
    case controller::ControllerEventKind::Answer:
      if (e.request_id == pending_ && !e.accepted && phase() != ElectrodePhase::Idle) {
        next_aux_.reset();
        const ElectrodePhase was = phase();
        if (was == ElectrodePhase::Measuring || was == ElectrodePhase::Calibrating)
          return fail("electrode.refused", e.text);
        host_->note(Severity::Error, "electrode.refused", fmt::format("electrode resume: {}", e.text));
        set_phase(ElectrodePhase::Idle);
      }
      return;
    default:
      return;
  }
}

void ElectrodeSetting::on_status(const controller::ControllerStatus& s) {
  // Auto mode asked for an auxiliary program: it starts once the servo has switched.
  if (!next_aux_ || s.servo.mode != control::Mode::Auto || s.servo.state != control::State::Idle ||
      s.run_active)
    return;
  auto program = std::move(next_aux_);
  next_aux_.reset();
  pending_ = host_->submit(controller::Request::run_auxiliary(next_aux_name_, std::move(program)));
}

void ElectrodeSetting::when_aux_ended(const controller::ControllerEvent& e) {
  if (host_ == nullptr) return;
  switch (phase()) {
    case ElectrodePhase::Measuring:
    case ElectrodePhase::Calibrating: {
      if (e.end != controller::JobEnd::Finished)
        return fail("electrode.stopped", fmt::format("the touch from {} did not finish ({})",
                                                     plan_[touch_].name, to_string(e.end)));
      const control::ServoStatus& servo = host_->current_status().servo;
      const SphereTouch& t = slow_ ? slow_line_ : plan_[touch_];
      const char* const stage = slow_ ? "slow touch" : "touch";
      const double within = slow_ ? at_.back_off : at_.clearance;
      const char* const where = slow_ ? "fast touch closed" : "sphere should be";
      if (!servo.probe_tripped)
        return fail("electrode.missing-touch",
                    fmt::format("the {} from {} met nothing within {:g} mm past where the {}: no sphere, or "
                                "the electrode is far off its offsets",
                                stage, t.name, within, where));
      const Vec3 at = xyz(servo.probe_position);
      if (!on_probe_path(t, at))
        return fail("electrode.contact-at-start",
                    fmt::format("the {} from {} was in contact where it began, {:g} mm off where the {}: the "
                                "electrode is far off its offsets, or something else touches",
                                stage, t.name, within, where));
      return touched(at);
    }
    case ElectrodePhase::Approaching:
      if (e.end != controller::JobEnd::Finished) {
        host_->note(Severity::Error, "electrode.stopped", "electrode resume: the approach did not finish");
        set_phase(ElectrodePhase::Idle);
        return;
      }
      set_phase(ElectrodePhase::Resuming);
      pending_ = host_->submit(controller::Request::resume(stop()->segment));
      return;
    default:
      return;
  }
}

// A touch closed at `at`: after a fast one, the slow one from just before it; after a slow (or
// the only) one, the point is kept and the next direction follows.
void ElectrodeSetting::touched(const Vec3& at) {
  if (at_.fast_feed > 0 && !slow_) {
    fast_touched_.push_back(at);
    next_aux_ = slow_touch_program(axes_, host_->current_status().servo.commanded, plan_[touch_], at, at_,
                                   slow_line_);
    next_aux_name_ = fmt::format("electrode slow touch {}", plan_[touch_].name);
    slow_ = true;
    if (host_->current_status().servo.mode != control::Mode::Auto)
      pending_ = host_->submit(controller::Request::set_mode(control::Mode::Auto));
    return;
  }
  touched_.push_back(at);
  if (++touch_ < plan_.size()) return next_touch();
  finish_measurement();
}

void ElectrodeSetting::finish_measurement() {
  std::vector<std::string> names;
  for (const SphereTouch& t : plan_) names.push_back(t.name);
  ElectrodeResult r = evaluate_touches(at_, tool_, offsets_of(entry_), entry_.diameter / 2, names, touched_);
  r.fast_touched = fast_touched_;
  if (phase() == ElectrodePhase::Calibrating) return next_calibration_angle(r);
  if (r.ok && write_) store(r);
  {
    std::lock_guard lock(mutex_);
    if (r.ok && r.written && stop_ && !stop_offset_) stop_offset_ = r.previous;
    last_ = r;
    phase_ = ElectrodePhase::Idle;
  }
  const char* const code = !r.ok ? r.code.c_str() : r.written ? "electrode.set" : "electrode.measured";
  host_->note(
      r.ok ? Severity::Note : Severity::Error, code,
      fmt::format("electrode setting: {}{}", r.message, r.ok && !r.written ? " (not stored yet)" : ""));
}

// The measured offsets into the tool table (the tool's entry as it was measured against, with
// X, Y, Z replaced); a refusal makes the result failed with the table's reason.
bool ElectrodeSetting::store(ElectrodeResult& r) {
  tools::ToolEntry changed = entry_;
  for (int i = 0; i < 3; ++i) changed.offset[i] = r.offset[static_cast<std::size_t>(i)];
  Diagnostics d;
  if (!tools_->update(tool_index_, changed, tools::ChangeSource::Operator, d)) {
    r.ok = false;
    r.code = "electrode.table";
    r.message = fmt::format("tool {} measured ({}) but the tool table refused it: {}", r.tool, show(r.offset),
                            d.items().empty() ? std::string("?") : d.items()[0].format());
    return false;
  }
  r.written = true;
  return true;
}

// After a measurement kept for the operator's look: stored only if the table still holds the
// offsets it was measured against (nobody changed the tool meanwhile).
controller::Outcome ElectrodeSetting::write() {
  if (phase() != ElectrodePhase::Idle)
    return refuse(fmt::format("electrode setting is {}", to_string(phase())));
  std::optional<ElectrodeResult> r = last();
  if (!r || !r->ok) return refuse("no passed measurement to store (electrode measure)");
  if (r->written) return refuse(fmt::format("tool {}'s measured offsets are stored already", r->tool));
  const auto table = tools_->snapshot();
  const std::optional<std::size_t> index = table->find(r->tool);
  if (!index || *index != tool_index_ || offsets_of(table->at_index(*index)) != r->previous)
    return refuse(
        fmt::format("tool {}'s offsets changed in the table since the measurement: measure again", r->tool));
  entry_ = table->at_index(*index);
  const bool ok = store(*r);
  {
    std::lock_guard lock(mutex_);
    if (ok && stop_ && !stop_offset_) stop_offset_ = r->previous;
    last_ = r;
  }
  host_->note(ok ? Severity::Note : Severity::Error, ok ? "electrode.set" : r->code,
              fmt::format("electrode setting: {}",
                          ok ? fmt::format("tool {} stored ({})", r->tool, show(r->offset)) : r->message));
  return ok ? accept(fmt::format("tool {}'s offsets stored: {}", r->tool, show(r->offset)))
            : refuse(r->message);
}

void ElectrodeSetting::fail(std::string code, std::string message) {
  if (phase() == ElectrodePhase::Calibrating) {
    calibration_.code = std::move(code);
    calibration_.message =
        fmt::format("with B at {:g}°: {}", calibration_.angles_deg[calibration_.centres.size()], message);
    return finish_calibration();
  }
  ElectrodeResult r;
  r.tool = tool_;
  r.code = std::move(code);
  r.message = std::move(message);
  r.previous = offsets_of(entry_);
  for (std::size_t i = 0; i < touched_.size(); ++i) r.names.push_back(plan_[i].name);
  r.touched = touched_;
  r.fast_touched = fast_touched_;
  {
    std::lock_guard lock(mutex_);
    last_ = r;
    phase_ = ElectrodePhase::Idle;
  }
  next_aux_.reset();
  host_->note(Severity::Error, r.code, fmt::format("electrode setting: {} (nothing stored)", r.message));
}

std::string ElectrodeSetting::state_json(const controller::ControllerStatus&) {
  using nlohmann::json;
  json last = nullptr;
  if (const std::optional<ElectrodeResult> r = this->last()) {
    last = {{"ok", r->ok},
            {"code", r->code},
            {"message", r->message},
            {"tool", r->tool},
            {"touches", r->names.size()},
            {"previous", r->previous},
            {"offset", r->offset},
            {"rms_residual_mm", r->rms_residual_mm},
            {"max_residual_mm", r->max_residual_mm},
            {"written", r->written}};
  }
  json b_axis = nullptr;
  if (const std::optional<BAxisResult> c = last_b_axis()) {
    b_axis = {{"ok", c->ok},
              {"code", c->code},
              {"message", c->message},
              {"angles_deg", c->angles_deg},
              {"b_axis", c->fit.axis.crossing},
              {"b_axis_direction", c->fit.axis.direction},
              {"max_residual_mm", c->fit.max_residual_mm}};
  }
  return json{{"phase", to_string(phase())},
              {"last", last},
              {"b_axis", b_axis},
              {"stopped_program", stop().has_value()}}
      .dump();
}

}  // namespace opencnc::edm
