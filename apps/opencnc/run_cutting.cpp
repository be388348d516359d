// SPDX-License-Identifier: GPL-3.0-or-later
// Plasma and oxy-fuel cutting's part of `opencnc run`: arc losses injected into the simulated plate
// (--inject arc-loss@SECONDS), the operator who answers them and a float switch that tripped —
// resume where the run held, or (--hold-retrace-back MM) the retrace: back along the path and cut
// on from there — who starts an oxy-fuel cut whose preheat waits for them (Start cut, after
// --inject start-cut@SECONDS of preheat), and the run's `cutting` report (docs/cutting.md).
#include <fmt/format.h>

#include <cmath>

#include "opencnc/cutting/cutting_recorder.hpp"
#include "opencnc/machine/sim_machine.hpp"
#include "opencnc/retrace/retrace.hpp"
#include "run_features_parts.hpp"

namespace opencnc::cli {

namespace {

class CuttingRun final : public RunFeature {
 public:
  void add_options(CLI::App& run) override {
    run.add_option(
           "--hold-retrace-back", back_mm_,
           "Answer an arc loss or a float switch's trip with the retrace instead of a resume where the "
           "run held: torch out and up, MM back along the path, start there (pierce again); the report "
           "lists them as `retraces`")
        ->check(CLI::PositiveNumber);
  }
  std::vector<InjectionForm> injections() const override {
    return {
        {"arc-loss@SECONDS",
         "the plasma arc goes out (a simulated plate); the run holds on its path and the scripted operator "
         "resumes there: the torch finds the plate and pierces again",
         ""},
        {"start-cut@SECONDS",
         "oxy-fuel, preheat = \"operator\": the scripted operator presses Start cut once a preheat that "
         "waits for them has lasted SECONDS (without it: the profile's preheat_s)",
         ""}};
  }
  bool parse_injection(const std::string& text, bool& ok) override {
    if (text.rfind("start-cut@", 0) == 0) {
      const char* end = nullptr;
      start_after_s_ = injection_number(text.c_str() + 10, '\0', end);
      ok = start_after_s_ >= 0;
      start_given_ = true;
      return true;
    }
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
    if (!losses_at_.empty() && profile && profile->plasma.config.oxy_fuel()) {
      fmt::print(stderr, "error: --inject arc-loss: the torch of {} is oxy-fuel, a flame without an arc\n",
                 session.machine);
      return false;
    }
    if (start_given_ && profile && !(profile->plasma.present && profile->plasma.config.oxy_fuel())) {
      fmt::print(stderr, "error: --inject start-cut needs an oxy-fuel torch ([process.oxyfuel] in {})\n",
                 session.machine);
      return false;
    }
    if (!start_given_ && profile) start_after_s_ = profile->plasma.config.preheat_s;
    std::sort(losses_at_.begin(), losses_at_.end());
    return true;
  }
  bool set_up(controller::MachineSetup& machine) override {
    for (const auto& [observer, options] : machine.observers())
      if (auto r = std::dynamic_pointer_cast<cutting::CuttingRecorder>(observer)) recorder_ = r;
    if (back_mm_ > 0) {
      retrace_ = std::dynamic_pointer_cast<recovery::RetraceFeature>(machine.feature("retrace"));
      if (!retrace_) {
        fmt::print(
            stderr,
            "error: --hold-retrace-back: the machine has no torch to retrace with ([process.cutting])\n");
        return false;
      }
    }
    return true;
  }
  bool goes_on(const controller::ControllerEvent& e) const override {
    return e.end == controller::JobEnd::Aborted && stage_ != Stage::Waiting;
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
    start_cut(c, st);
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
  // that rose into it): the run stands held on its path with the torch out. Either a resume finds
  // the plate and pierces again there (the torch stage), or the retrace takes the torch out and up,
  // steps back along the path (over the stretch the lost arc may have left uncut) and starts there.
  // (A breakaway, or failed starts, need a person: those holds are left standing.)
  void operate(controller::Controller& c, const controller::ControllerStatus& st) {
    using controller::Request;
    if (asked_ != 0 && !c.outcome(asked_)) return;
    if (asked_ != 0) {
      const controller::Outcome o = *c.outcome(asked_);
      asked_ = 0;
      if (!o.accepted) {
        fmt::print(stderr, "error: the answer to the torch's hold was refused: {}\n", o.message);
        stage_ = Stage::Waiting;
        return;
      }
    }
    const bool paused_idle = retrace_ && retrace_->phase() == recovery::RetracePhase::Paused &&
                             st.servo.mode == control::Mode::Manual &&
                             st.servo.state == control::State::Idle && !st.run_active;
    switch (stage_) {
      case Stage::Waiting:
        break;
      case Stage::Pausing:
        if (!paused_idle) return;
        asked_ = c.submit(Request::feature("retrace", "step", recovery::RetraceStep{-back_mm_}));
        stage_ = Stage::Stepping;
        return;
      case Stage::Stepping:
        if (!paused_idle) return;
        asked_ = c.submit(Request::feature("retrace", "start"));
        stage_ = Stage::Waiting;
        return;
    }
    const control::TorchStatus& t = st.servo.torch;
    const bool held = st.servo.state == control::State::Held && st.servo.path_velocity == 0;
    if ((t.arc_losses == losses_seen_ && t.float_trips == trips_seen_) || !held || !st.run_active) return;
    losses_seen_ = t.arc_losses;
    trips_seen_ = t.float_trips;
    ++recoveries_;
    if (retrace_) {
      asked_ = c.submit(Request::feature("retrace", "pause"));
      stage_ = Stage::Pausing;
    } else {
      asked_ = c.submit(Request::simple(control::CommandKind::Resume));
    }
  }

  // The operator at an oxy-fuel preheat that waits for them: Start cut once it has lasted
  // start_after_s_ (the steel glowing at the start of the kerf, as a person would judge it).
  void start_cut(controller::Controller& c, const controller::ControllerStatus& st) {
    if (starting_ != 0) {
      const auto o = c.outcome(starting_);
      if (!o) return;
      if (!o->accepted) fmt::print(stderr, "error: Start cut was refused: {}\n", o->message);
      starting_ = 0;
      started_preheats_ = st.servo.torch.preheats;
    }
    const control::TorchStatus& t = st.servo.torch;
    if (!t.waiting_start || t.preheat_s < start_after_s_ || t.preheats == started_preheats_) return;
    starting_ = c.submit(controller::Request::simple(control::CommandKind::StartCut));
  }

  enum class Stage : std::uint8_t { Waiting, Pausing, Stepping };
  double back_mm_ = 0;
  std::shared_ptr<recovery::RetraceFeature> retrace_;
  Stage stage_ = Stage::Waiting;
  std::vector<double> losses_at_;
  double start_after_s_ = 4;
  bool start_given_ = false;
  std::uint64_t starting_ = 0;
  std::uint32_t started_preheats_ = 0;
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
