// SPDX-License-Identifier: GPL-3.0-or-later
// BreakpointJournal's recovery choices after the power returns: resume (the program unchanged, the
// axes where they rest, the program replayed to the segment with its coupling, cut on), retract
// along the path with the slave on the law, discard; the valid flag cleared once one completed.
#include <cmath>

#include <fmt/format.h>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/broaching/modal_digest.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/motion/coupling.hpp"

namespace opencnc::recovery {

using control::Refusal;
using controller::ControllerEventKind;
using controller::Outcome;

namespace {

Outcome refuse(Refusal r, std::string why) {
  Outcome o;
  o.refusal = r;
  o.message = std::move(why);
  return o;
}

/// The law of the record, in the slave's units per the master's (the profile's tables).
motion::CouplingLaw law_of(const BreakpointCoupling& c, const motion::CouplingConfig& config) {
  return motion::law_for(config, static_cast<motion::CouplingKind>(c.kind), c.pitch_mm, c.pitch_rate,
                         c.table);
}

/// The first axis of the profile farther from the record's rest than the tolerance, in words.
std::string moved_axis(const config::MachineProfile& profile, const Pose& actual, const Pose& rest,
                       const ResumeArgs& args) {
  for (const config::AxisProfile& a : profile.axes) {
    const auto i = static_cast<std::size_t>(index(a.axis));
    const bool rotary = a.rotary;
    const double tol = rotary ? args.tolerance_deg : args.tolerance_mm;
    double off = actual.v[i] - rest.v[i];
    if (a.wrapped) off = std::remainder(off, 360.0);  // a table that turns without end
    if (std::fabs(off) > tol) {
      return fmt::format(
          "{} is {:.4f} {} from where it came to rest (tolerance {}): home the machine and "
          "approach the breakpoint before resuming, or retract or discard",
          letter(a.axis), off, rotary ? "deg" : "mm", tol);
    }
  }
  return {};
}

}  // namespace

Outcome BreakpointJournal::start_resume(const BreakpointRecord& r, const ResumeArgs& args,
                                        controller::FeatureHost& host) {
  const controller::ControllerStatus& st = host.current_status();
  const std::optional<FileHash> h = hash_file(r.program_path);
  if (!h)
    return refuse(Refusal::NoProgram, "cannot read " + r.program_path + ": the program the record names");
  if (h->hash != r.program_hash || h->size != r.program_size) {
    return refuse(
        Refusal::ProgramError,
        fmt::format("{} changed since the power failed (content hash {:016x}, the record's {:016x}): "
                    "resume refused; retract or discard",
                    r.program_path, h->hash, r.program_hash));
  }
  if (const std::string moved = moved_axis(host.profile(), st.servo.actual, r.actual, args); !moved.empty())
    return refuse(Refusal::StartMismatch, moved);
  if (r.modal_digest != 0 && source_) {
    source_->profile_changed(host.profile());  // the conditions an admin changed since
    std::string why;
    const auto d = modal_digest_at(source_->options_for(r.program_path, {}), r.program_path, r.program_start,
                                   r.segment, &why);
    if (!d) return refuse(Refusal::ProgramError, "the program cannot be replayed to the breakpoint: " + why);
    if (*d != r.modal_digest) {
      return refuse(Refusal::ProgramError,
                    "the program's modal state at the breakpoint differs from the record's (a subprogram, "
                    "parameter or tool table it reads changed): resume refused");
    }
  }
  recovering_ = r;
  resume_args_ = args;
  phase_ = RecoveryPhase::Opening;
  recovery_error_.clear();
  pending_ = host.submit(controller::Request::open(r.program_path));
  Outcome o;
  o.accepted = true;
  o.message = fmt::format("resuming {} at segment {} (line {})", r.program_path, r.segment, r.line);
  return o;
}

// An auxiliary program of one move: the master by the distance, the slave's end by the law from
// the record's origin, the law engaged with that origin so that the tick holds it every period.
std::shared_ptr<const canon::Program> BreakpointJournal::along_helix(const BreakpointRecord& r,
                                                                     double distance_mm, bool onward,
                                                                     double speed_mm_min,
                                                                     controller::FeatureHost& host,
                                                                     std::string* why) const {
  const int m = r.coupling.master_axis, s = r.coupling.slave_axis;
  if (r.coupling.kind == 0 || m < 0 || s < 0) {
    *why = "no coupling held when the power failed: jog the axes instead";
    return nullptr;
  }
  const motion::CouplingLaw law = law_of(r.coupling, control::coupling_config(host.profile().coupling));
  if (!law.active()) {
    *why = "the record's coupling law is not this machine's";
    return nullptr;
  }
  const Pose at = host.current_status().servo.commanded;
  const auto mi = static_cast<std::size_t>(m), si = static_cast<std::size_t>(s);
  const double cutting = r.move_end.v[mi] - r.move_start.v[mi];
  const double sign = (cutting >= 0 ? 1.0 : -1.0) * (onward ? 1.0 : -1.0);
  Pose end = at;
  end.v[mi] = at.v[mi] + sign * distance_mm;
  end.v[si] = r.coupling.slave_origin + law.slave(end.v[mi] - r.coupling.master_origin);
  canon::ProgramBuilder b(host.profile().axis_mask(), at);
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
  canon::AxisCoupling c;
  c.law = r.coupling.kind;
  c.table = r.coupling.table;
  c.pitch = r.coupling.pitch_mm;
  c.rate = r.coupling.pitch_rate;
  c.has_origin = true;
  c.origin.v[mi] = r.coupling.master_origin;
  c.origin.v[si] = r.coupling.slave_origin;
  b.set_axis_coupling(c);
  // The planner's path length counts the slave's degrees too: the feed that moves the master at
  // the asked speed.
  double len2 = 0;
  for (std::size_t i = 0; i < end.v.size(); ++i) len2 += (end.v[i] - at.v[i]) * (end.v[i] - at.v[i]);
  b.set_feed_rate(speed_mm_min * std::sqrt(len2) / distance_mm);
  b.straight_feed(0, end);
  return std::make_shared<canon::Program>(b.take());
}

Outcome BreakpointJournal::start_retract(const BreakpointRecord& r, const RetractArgs& args,
                                         controller::FeatureHost& host) {
  if (!(args.distance_mm > 0) || !(args.speed_mm_min > 0) || !std::isfinite(args.distance_mm) ||
      !std::isfinite(args.speed_mm_min)) {
    return refuse(Refusal::BadValue, "retract needs a distance and a speed above 0");
  }
  std::string why;
  auto program = along_helix(r, args.distance_mm, args.onward, args.speed_mm_min, host, &why);
  if (!program) return refuse(Refusal::NotApplicable, why);
  recovering_ = r;
  phase_ = RecoveryPhase::Retracting;
  recovery_error_.clear();
  pending_ = host.submit(controller::Request::run_auxiliary("breakpoint retract", std::move(program)));
  Outcome o;
  o.accepted = true;
  o.message = fmt::format("retracting {} by {} mm {} with {} on the law",
                          letter(static_cast<Axis>(r.coupling.master_axis)), args.distance_mm,
                          args.onward ? "onward" : "back", letter(static_cast<Axis>(r.coupling.slave_axis)));
  return o;
}

// The steps of a choice under way: the answers to what it asked, the job's end.
void BreakpointJournal::recovery_event(const controller::ControllerEvent& e) {
  if (phase_ == RecoveryPhase::None || phase_ == RecoveryPhase::Done || phase_ == RecoveryPhase::Failed)
    return;
  if (e.kind == ControllerEventKind::Answer && e.request_id == pending_) {
    if (!e.accepted) return finish_recovery(false, e.text);
    if (phase_ == RecoveryPhase::Opening) run_in();
    return;
  }
  if (e.kind == ControllerEventKind::JobEnded && phase_ == RecoveryPhase::RunningIn &&
      e.job == controller::JobKind::Auxiliary) {
    if (e.end != controller::JobEnd::Finished)
      return finish_recovery(false, "the run-in did not complete: " + e.text);
    phase_ = RecoveryPhase::Resuming;
    pending_ = host_->submit(controller::Request::resume(recovering_.segment, recovering_.program_start));
    return;
  }
  if (e.kind == ControllerEventKind::JobEnded) {
    const bool mine = (phase_ == RecoveryPhase::Resuming && e.job == controller::JobKind::Program) ||
                      (phase_ == RecoveryPhase::Retracting && e.job == controller::JobKind::Auxiliary);
    if (mine)
      finish_recovery(e.end == controller::JobEnd::Finished,
                      e.end == controller::JobEnd::Finished ? "" : e.text);
  }
}

// The program is open: back off along the interrupted move (no farther than its part already cut,
// so the machine stays on the segment), or resume at once without a coupling or a run-in.
void BreakpointJournal::run_in() {
  const BreakpointRecord& r = recovering_;
  const int m = r.coupling.master_axis;
  double back = 0;
  if (r.coupling.kind != 0 && m >= 0) {
    const auto mi = static_cast<std::size_t>(m);
    back = std::min(resume_args_.run_in_mm, std::fabs(r.actual.v[mi] - r.move_start.v[mi]));
  }
  std::string why;
  auto program =
      back > 0 ? along_helix(r, back, false, resume_args_.run_in_speed_mm_min, *host_, &why) : nullptr;
  if (program) {
    phase_ = RecoveryPhase::RunningIn;
    pending_ = host_->submit(controller::Request::run_auxiliary("breakpoint run-in", std::move(program)));
    return;
  }
  phase_ = RecoveryPhase::Resuming;
  pending_ = host_->submit(controller::Request::resume(r.segment, r.program_start));
}

void BreakpointJournal::finish_recovery(bool ok, std::string why) {
  phase_ = ok ? RecoveryPhase::Done : RecoveryPhase::Failed;
  recovery_error_ = std::move(why);
  if (ok) {
    clear_valid();
  } else if (host_ != nullptr) {
    host_->note(Severity::Error, "recovery.failed",
                "the breakpoint's recovery did not complete (the record stays valid): " + recovery_error_);
  }
}

// The record as it is, valid no more: written through the writer thread like any record.
void BreakpointJournal::clear_valid() {
  Work w;
  w.record = recovering_;
  w.record.valid = false;
  post(std::move(w));
}

}  // namespace opencnc::recovery
