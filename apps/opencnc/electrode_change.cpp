// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc run --electrode-change`: stop, lift, replace, measure, resume — one stage per period.
#include "electrode_change.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "opencnc/machine/sim_machine.hpp"

namespace opencnc::cli {

std::optional<ElectrodeChangeAt> parse_electrode_change(const std::string& text) {
  ElectrodeChangeAt r;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf:%lf,%lf,%lf%c", &r.at_s, &r.offset[0], &r.offset[1], &r.offset[2],
                  &tail) != 4 ||
      !std::isfinite(r.at_s) || r.at_s < 0)
    return std::nullopt;
  for (double v : r.offset)
    if (!std::isfinite(v)) return std::nullopt;
  return r;
}

ElectrodeChangeScript::ElectrodeChangeScript(std::vector<ElectrodeChangeAt> steps,
                                             std::shared_ptr<edm::ElectrodeSetting> feature, Axis tool_axis,
                                             double lift_mm, double min_mm, double max_mm)
    : steps_(std::move(steps)),
      feature_(std::move(feature)),
      tool_axis_(tool_axis),
      lift_mm_(lift_mm),
      min_mm_(min_mm),
      max_mm_(max_mm) {}

void ElectrodeChangeScript::fail(const std::string& why) {
  fmt::print(stderr, "error: electrode change at {:g} s: {}\n", steps_[next_].at_s, why);
  stage_ = Stage::Failed;
}

// The last request's outcome: false while it is not known; a refusal ends the changes.
bool ElectrodeChangeScript::answered(controller::Controller& c) {
  if (asked_ == 0) return true;
  const std::optional<controller::Outcome> o = c.outcome(asked_);
  if (!o) return false;
  asked_ = 0;
  if (!o->accepted) fail(o->message);
  return o->accepted;
}

void ElectrodeChangeScript::tick(controller::Controller& c, const controller::ControllerStatus& st,
                                 machine::SimMachine* sim) {
  using controller::Request;
  if (t0_ < 0 && st.run_active && st.job == controller::JobKind::Program) t0_ = st.servo.time_s;
  if (stage_ == Stage::Failed || !answered(c)) return;
  const bool idle = st.servo.state == control::State::Idle && !st.run_active;
  switch (stage_) {
    case Stage::Waiting:
      if (next_ >= steps_.size() || t0_ < 0 || st.servo.time_s - t0_ < steps_[next_].at_s) return;
      if (!st.run_active || st.job != controller::JobKind::Program) return;  // between jobs: at the next
      if (sim == nullptr || st.servo.tool <= 0)
        return fail("no simulated machine, or no tool in the spindle");
      records_.push_back(ElectrodeChangeRecord{st.servo.time_s - t0_, st.servo.tool, 0, {}, false});
      asked_ = c.submit(Request::simple(control::CommandKind::FeedHold));
      stage_ = Stage::Holding;
      return;
    case Stage::Holding:
      if (st.servo.state != control::State::Held || st.servo.path_velocity != 0) return;
      asked_ = c.submit(Request::simple(control::CommandKind::Abort));
      stage_ = Stage::Aborting;
      return;
    case Stage::Aborting:
      if (!idle) return;
      if (!feature_->stop()) return fail("the job ended without a stop point to resume");
      records_.back().segment = feature_->stop()->segment;
      asked_ = c.submit(Request::set_mode(control::Mode::Mdi));
      stage_ = Stage::Lifting;
      mdi_sent_ = false;
      return;
    case Stage::Lifting: {
      if (!idle) return;
      if (!mdi_sent_) {  // out of the cavity along the tool axis, in machine coordinates
        const double to = std::clamp(st.servo.commanded[tool_axis_] + lift_mm_, min_mm_, max_mm_);
        asked_ = c.submit(Request::mdi(fmt::format("G53 G0 {}{:.4f}", letter(tool_axis_), to)));
        mdi_sent_ = true;
        return;
      }
      const machine::SimElectrode& now = sim->electrode();
      sim->replace_electrode(records_.back().tool, steps_[next_].offset, now.tip_radius);
      asked_ =
          c.submit(Request::feature("electrode", "measure", edm::ElectrodeMeasure{records_.back().tool}));
      stage_ = Stage::Measuring;
      return;
    }
    case Stage::Measuring: {
      if (feature_->phase() != edm::ElectrodePhase::Idle || !idle) return;
      const std::optional<edm::ElectrodeResult> r = feature_->last();
      if (!r || !r->ok) return fail(r ? r->message : "no measurement");
      records_.back().measured = *r;
      asked_ = c.submit(Request::feature("electrode", "resume"));
      stage_ = Stage::Resuming;
      return;
    }
    case Stage::Resuming:
      if (feature_->phase() != edm::ElectrodePhase::Idle || !st.run_active ||
          st.job != controller::JobKind::Program)
        return;
      records_.back().resumed = true;
      stage_ = Stage::Waiting;
      ++next_;
      return;
    case Stage::Failed:
      return;
  }
}

bool ElectrodeChangeScript::goes_on(const controller::ControllerEvent& e) const {
  return e.end == controller::JobEnd::Aborted && stage_ != Stage::Waiting && stage_ != Stage::Failed;
}

nlohmann::json ElectrodeChangeScript::json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const ElectrodeChangeRecord& r : records_) {
    const edm::ElectrodeResult& m = r.measured;
    out.push_back({{"at_s", r.at_s},
                   {"tool", r.tool},
                   {"segment", r.segment},
                   {"measured", m.ok},
                   {"previous", m.previous},
                   {"offset", m.offset},
                   {"max_residual_um", m.max_residual_mm * 1000},
                   {"resumed", r.resumed}});
  }
  return out;
}

}  // namespace opencnc::cli
