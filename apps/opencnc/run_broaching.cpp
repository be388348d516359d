// SPDX-License-Identifier: GPL-3.0-or-later
// Broaching's part of `opencnc run`: the cutter worn by --inject tool-dull, the operator's answer
// where the load guard holds the feed, the power failure's report, and the breakpoint journal
// (--journal) with what it wrote.
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/broaching/power_fail_recorder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/machine/sim_machine.hpp"
#include "run_features_parts.hpp"
#include "run_journal.hpp"

namespace opencnc::cli {

namespace {

using control::CommandKind;
using controller::Request;

class BroachingRun final : public RunFeature {
 public:
  void add_options(CLI::App& run) override {
    run.add_option("--journal", journal_dir_,
                   "Write the breakpoint journal in this folder when the mains fail (two checksummed slots; "
                   "`opencnc recover` reads it; the report gains `journal`)");
  }
  std::vector<InjectionForm> injections() const override {
    return {{"tool-dull@SECONDS=FACTOR", "the broach's cutter wears: its force grows by FACTOR, 1 = sharp",
             "the cutter's force grows by FACTOR, 0 < FACTOR <= 100, 1 = sharp"}};
  }
  bool parse_injection(const std::string& text, bool& ok) override {
    if (text.rfind("tool-dull@", 0) != 0) return false;
    const char* end = nullptr;
    dull_s_ = injection_number(text.c_str() + 10, '=', end);
    const double f = dull_s_ >= 0 ? injection_number(end + 1, '\0', end) : -1;
    ok = f > 0 && f <= 100;
    if (ok) dull_factor_ = f;
    return true;
  }
  bool check(const config::MachineProfile* profile, SessionOptions& session) override {
    if (dull_s_ >= 0 && profile && !profile->broaching.sim.present) {
      fmt::print(stderr,
                 "error: --inject tool-dull needs a simulated broach ([process.broaching.sim] in {})\n",
                 session.machine);
      return false;
    }
    mains_off_ = session.mains_off_s >= 0;
    if (!journal_dir_.empty()) session.settings["journal"] = journal_dir_;
    return true;
  }
  bool set_up(controller::MachineSetup& machine) override {
    if (journal_dir_.empty()) return true;
    journal_ = std::dynamic_pointer_cast<recovery::BreakpointJournal>(machine.feature("journal"));
    if (!journal_) {
      fmt::print(
          stderr,
          "error: --journal {}: the machine has no power monitor ([power] monitor) to write a journal for\n",
          journal_dir_);
      return false;
    }
    return true;
  }
  void opened(const config::MachineProfile& machine, SessionObservers& out) override {
    if (!mains_off_) return;  // the stop after the injected power failure, measured
    power_ = std::make_shared<broaching::PowerFailRecorder>(
        control::coupling_config(machine.coupling), controller::machine_limits(machine),
        machine.servo_period_s, machine.coupling.radius_mm);
    out.emplace_back(power_, controller::ObserverOptions{machine.servo_period_s, true});
  }
  void tick(controller::Controller&, const controller::ControllerStatus& st,
            machine::SimMachine* sim) override {
    if (dull_s_ >= 0 && !dulled_ && sim != nullptr && st.servo.time_s >= dull_s_) {
      sim->set_tool_dull(dull_factor_);
      dulled_ = true;
    }
  }
  // The load guard held the feed (its note says at what load): the operator at the terminal
  // resumes (the cutter checked) or aborts; --unattended or no terminal aborts, since nothing
  // would resume.
  bool on_event(const controller::ControllerEvent& e, SessionOperator& op) override {
    using controller::ControllerEventKind;
    if (e.kind == ControllerEventKind::Servo && e.servo.kind == control::EventKind::LoadGuard)
      hold_ = e.servo.action == static_cast<std::uint32_t>(control::LoadAction::Hold);
    if (!(e.kind == ControllerEventKind::Note && e.code == "control.load" && hold_ && !aborted_)) return true;
    const std::optional<std::string> answer =
        op.ask("the load guard holds the feed: type resume and Enter to cut on; anything else aborts");
    if (answer && *answer == "resume" && op.must(Request::simple(CommandKind::Resume))) return true;
    fmt::print(stderr,
               "error: the load guard held the feed (the cutter's load passed its hold level); the run is "
               "aborted\n");
    op.submit(Request::simple(CommandKind::Abort));
    aborted_ = true;
    return false;
  }
  void finished(machine::SimMachine* sim) override {
    if (sim == nullptr) return;
    const std::span<const float> b = sim->broach_bore();
    bore_.assign(b.begin(), b.end());
  }
  bool report(nlohmann::json& j) override {
    if (power_) {
      fmt::print("{}", power_->report_text());
      j[power_->report_key()] = nlohmann::json::parse(power_->report_json());
    }
    if (journal_) j["journal"] = finish_run_journal(*journal_, journal_dir_, bore_);
    return true;
  }

 private:
  std::string journal_dir_;
  double dull_s_ = -1, dull_factor_ = 1;
  bool dulled_ = false, mains_off_ = false, hold_ = false, aborted_ = false;
  std::shared_ptr<broaching::PowerFailRecorder> power_;
  std::shared_ptr<recovery::BreakpointJournal> journal_;
  std::vector<float> bore_;
};

}  // namespace

std::unique_ptr<RunFeature> broaching_run() {
  return std::make_unique<BroachingRun>();
}

}  // namespace opencnc::cli
