// SPDX-License-Identifier: GPL-3.0-or-later
// Plasma cutting's part of `opencnc run`: arc losses injected into the simulated plate
// (--inject arc-loss@SECONDS), the operator who answers them and a float switch that tripped (resume
// where the run held), and the run's
// `cutting` report (docs/cutting.md).
#include <fmt/format.h>

#include "opencnc/cutting/cutting_recorder.hpp"
#include "opencnc/machine/sim_machine.hpp"
#include "run_features_parts.hpp"

namespace opencnc::cli {

namespace {

class CuttingRun final : public RunFeature {
 public:
  std::vector<InjectionForm> injections() const override {
    return {
        {"arc-loss@SECONDS",
         "the plasma arc goes out (a simulated plate); the run holds on its path and the scripted operator "
         "resumes there: the torch finds the plate and pierces again",
         ""}};
  }
  bool parse_injection(const std::string& text, bool& ok) override {
    if (text.rfind("arc-loss@", 0) != 0) return false;
    const char* end = nullptr;
    const double at = injection_number(text.c_str() + 9, '\0', end);
    ok = at >= 0;
    if (ok) losses_at_.push_back(at);
    return true;
  }
  bool check(const config::MachineProfile* profile, SessionOptions& session) override {
    if (!losses_at_.empty() && profile && !profile->plasma.sim.present) {
      fmt::print(stderr, "error: --inject arc-loss needs a simulated plate ([process.plasma.sim] in {})\n",
                 session.machine);
      return false;
    }
    std::sort(losses_at_.begin(), losses_at_.end());
    return true;
  }
  bool set_up(controller::MachineSetup& machine) override {
    for (const auto& [observer, options] : machine.observers())
      if (auto r = std::dynamic_pointer_cast<cutting::CuttingRecorder>(observer)) recorder_ = r;
    return true;
  }
  void tick(controller::Controller& c, const controller::ControllerStatus& st,
            machine::SimMachine* sim) override {
    if (t0_ < 0 && st.run_active && st.job == controller::JobKind::Program) t0_ = st.servo.time_s;
    if (sim != nullptr && t0_ >= 0 && next_ < losses_at_.size() &&
        st.servo.time_s - t0_ >= losses_at_[next_]) {
      sim->inject_arc_loss();
      ++next_;
    }
    operate(c, st);
  }
  bool report(nlohmann::json& j) override {
    if (!recorder_) return true;
    fmt::print("{}", recorder_->report_text());
    nlohmann::json r = nlohmann::json::parse(recorder_->report_json());
    r["recoveries"] = recoveries_;
    j[recorder_->report_key()] = std::move(r);
    return true;
  }

 private:
  // The operator at an arc loss or a float switch that tripped while the torch burned (a plate
  // that rose into it): the run stands held on its path with the torch out; a resume finds the
  // plate and pierces again there (the torch stage), and the cut goes on. (A breakaway, or
  // failed starts, need a person: those holds are left standing.)
  void operate(controller::Controller& c, const controller::ControllerStatus& st) {
    using controller::Request;
    if (asked_ != 0 && !c.outcome(asked_)) return;
    if (asked_ != 0) {
      if (!c.outcome(asked_)->accepted)
        fmt::print(stderr, "error: the resume after the torch's hold was refused: {}\n",
                   c.outcome(asked_)->message);
      asked_ = 0;
    }
    const control::TorchStatus& t = st.servo.torch;
    const bool held = st.servo.state == control::State::Held && st.servo.path_velocity == 0;
    if ((t.arc_losses == losses_seen_ && t.float_trips == trips_seen_) || !held || !st.run_active) return;
    losses_seen_ = t.arc_losses;
    trips_seen_ = t.float_trips;
    ++recoveries_;
    asked_ = c.submit(Request::simple(control::CommandKind::Resume));
  }

  std::vector<double> losses_at_;
  std::size_t next_ = 0;
  double t0_ = -1;
  std::uint64_t asked_ = 0;
  std::uint32_t losses_seen_ = 0, trips_seen_ = 0;
  int recoveries_ = 0;
  std::shared_ptr<cutting::CuttingRecorder> recorder_;
};

}  // namespace

std::unique_ptr<RunFeature> cutting_run() {
  return std::make_unique<CuttingRun>();
}

}  // namespace opencnc::cli
