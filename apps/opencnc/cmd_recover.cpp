// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc recover`: after a power failure, the operator's choice for the breakpoint in a journal —
// resume, retract along the helix or discard — confirmed, then run on the simulated machine that
// powers up where the record says the axes rest (absolute encoders).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <numbers>

#include <nlohmann/json.hpp>

#include "cli_files.hpp"
#include "commands.hpp"
#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/broaching/recovery_wait.hpp"
#include "opencnc/broaching/sim_bore.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/run_recorder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/motion/coupling.hpp"

namespace opencnc::cli {

namespace {

struct RecoverOptions {
  std::string machine, journal, choice, direction = "back", trace, report;
  std::vector<std::string> sets;
  double distance_mm = 0, speed_mm_min = 600, tolerance_mm = 0.01, tolerance_deg = 0.01, run_in_mm = 2.0;
  bool yes = false;
};

/// The trace to a CSV and the recovery's largest helix error (feedback, coupled periods).
class RecoverTrace final : public controller::ControllerObserver {
 public:
  RecoverTrace(controller::TraceCsvWriter* csv, const recovery::BreakpointCoupling& c,
               const motion::CouplingConfig& config, double radius_mm)
      : csv_(csv), c_(c), radius_mm_(radius_mm) {
    const auto kind = static_cast<motion::CouplingKind>(c.kind);
    if (kind == motion::CouplingKind::ConstantPitch) law_ = motion::CouplingLaw::constant(c.pitch_mm);
    if (kind == motion::CouplingKind::LinearPitch)
      law_ = motion::CouplingLaw::linear(c.pitch_mm, c.pitch_rate);
    if ((kind == motion::CouplingKind::PitchTable || kind == motion::CouplingKind::Cam) && c.table >= 1 &&
        c.table <= motion::kMaxCouplingTables)
      law_ = motion::CouplingLaw::tabulated(kind, config.tables[static_cast<std::size_t>(c.table - 1)]);
  }
  // Only while the tick holds the breakpoint's law (its origin): later grooves have laws of their own.
  void on_status(const controller::ControllerStatus& s) override {
    const control::CouplingStatus& k = s.servo.coupling;
    same_law_ = static_cast<std::uint8_t>(k.kind) == c_.kind && k.master_origin == c_.master_origin &&
                k.slave_origin == c_.slave_origin;
  }
  void on_trace(const control::TraceSample& s, const controller::TraceContext&) override {
    if (s.activity != control::Activity::Program) return;
    if (csv_ != nullptr) csv_->add(s);
    // The law of the breakpoint holds while the recovery runs on the interrupted move's groove.
    if (s.coupled && same_law_ && law_.active() && c_.master_axis >= 0 && c_.slave_axis >= 0) {
      const double law = c_.slave_origin + law_.slave(s.actual[c_.master_axis] - c_.master_origin);
      const double e = std::fabs(std::remainder(s.actual[c_.slave_axis] - law, 360.0));
      worst_um = std::max(worst_um, e);
    }
  }
  double helix_error_um() const { return worst_um * std::numbers::pi / 180 * radius_mm_ * 1000; }

 private:
  controller::TraceCsvWriter* csv_;
  recovery::BreakpointCoupling c_;
  motion::CouplingLaw law_;
  double radius_mm_;
  double worst_um = 0;  ///< degrees until helix_error_um converts
  bool same_law_ = false;
};

/// The valid record in the journal, or nullopt after saying why.
std::optional<recovery::BreakpointRecord> read_record(const std::string& dir) {
  std::string error;
  auto j = recovery::Journal::open(dir, &error);
  if (!j) {
    fmt::print(stderr, "error: --journal {}: {}\n", dir, error);
    return std::nullopt;
  }
  const auto raw = j->read();
  if (!raw) {
    fmt::print(stderr, "error: the journal {} holds no breakpoint\n", dir);
    return std::nullopt;
  }
  auto r = recovery::decode(raw->payload, &error);
  if (!r) fmt::print(stderr, "error: the journal {}: {}\n", dir, error);
  if (r && !r->valid)
    fmt::print(stderr, "error: the breakpoint in {} was already dealt with (not valid)\n", dir);
  return r && r->valid ? r : std::nullopt;
}

/// The simulated workpiece as the run that wrote the record left it (`opencnc run --journal` keeps
/// it beside the journal): the machine powers up with the groove already cut. Without it (or one of
/// another breakpoint) the simulated bore is uncut, and the load guard meets the groove as a chip.
void restore_bore(controller::SimRig& rig, const std::string& dir, const recovery::BreakpointRecord& r) {
  if (rig.machine().broach_bore().empty()) return;  // no simulated broach
  std::string error;
  const std::optional<recovery::SimBore> b = recovery::load_sim_bore(dir, &error);
  if (b && b->program_hash == r.program_hash && b->signal_time_s == r.signal_time_s &&
      rig.machine().restore_broach_bore(b->cells)) {
    fmt::print("simulated bore      as the power failure left it ({})\n", recovery::kSimBoreFile);
    return;
  }
  const std::string why = !error.empty() ? error
                          : b            ? "it belongs to another breakpoint"
                                         : std::string("none beside the journal");
  fmt::print(stderr, "warning: simulated bore: {}: the workpiece powers up uncut (the load guard may hold)\n",
             why);
}

/// The operator's yes on the terminal (anything else, or no input, is no).
bool confirmed(const std::string& question) {
  fmt::print("{} [y/N] ", question);
  std::fflush(stdout);
  std::string answer;
  if (!std::getline(std::cin, answer)) return false;
  return answer == "y" || answer == "Y" || answer == "yes";
}

int recover(const RecoverOptions& o) {
  const std::optional<recovery::BreakpointRecord> r = read_record(o.journal);
  if (!r) return kExitProgram;
  // The simulated machine powers up where the axes rest; the operator's --set come after.
  std::vector<std::string> sets;
  {
    const config::ProfileLoad plain = config::load_profile(o.machine, o.sets);
    if (!plain.ok()) {
      for (const auto& d : plain.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
      return kExitUsage;
    }
    for (const config::AxisProfile& a : plain.profile->axes) {
      const char l = static_cast<char>(std::tolower(letter(a.axis)));
      const double at = r->actual[a.axis];
      sets.push_back(fmt::format("axis.{}.sim.start_position={:.17g}", l, at));
      sets.push_back(fmt::format("axis.{}.homing.position={:.17g}", l, at));
    }
  }
  sets.insert(sets.end(), o.sets.begin(), o.sets.end());
  const config::ProfileLoad load = config::load_profile(o.machine, sets);
  if (!load.ok()) {
    for (const auto& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
    return kExitUsage;
  }
  const config::MachineProfile& profile = *load.profile;
  const NamedPath inputs[] = {{"the profile", o.machine}, {"the program", r->program_path}};
  const NamedPath outputs[] = {{"--trace", o.trace}, {"--report", o.report}};
  const auto files = open_outputs(inputs, outputs);
  if (files.empty()) return kExitUsage;

  fmt::print("breakpoint          {}\n", recovery::describe(*r));
  const std::string question =
      o.choice == "resume"    ? fmt::format("Resume {} at line {}?", r->program_path, r->line)
      : o.choice == "retract" ? fmt::format("Retract {} mm {} along the helix at {} mm/min?", o.distance_mm,
                                            o.direction, o.speed_mm_min)
                              : std::string("Discard the breakpoint (the program cannot be resumed then)?");
  if (!o.yes && !confirmed(question)) {
    fmt::print(stderr, "error: not confirmed: nothing done, the breakpoint stays valid\n");
    return kExitProgram;
  }

  // The machine as every front end sets it up, the journal among its features.
  Diagnostics d;
  std::unique_ptr<controller::MachineSetup> machine =
      features::machine_setup(profile, d, controller::MachineSetup::Options::with("journal", o.journal));
  for (const Diagnostic& x : d.items()) {
    if (x.code == "setting.journal")
      fmt::print(stderr, "error: --journal {}: {}\n", o.journal, x.message);
    else
      fmt::print(stderr, "{}\n", x.format());
  }
  if (!machine) return kExitUsage;
  auto journal = std::dynamic_pointer_cast<recovery::BreakpointJournal>(machine->feature("journal"));
  if (!journal) {
    fmt::print(stderr, "error: --journal {}: {} has no power monitor ([power] monitor)\n", o.journal,
               o.machine);
    return kExitUsage;
  }
  controller::SimRig rig(profile, *machine);
  std::optional<controller::TraceCsvWriter> csv;
  if (files[0]) csv.emplace(*files[0], profile.axis_mask(), profile.servo_period_s);
  auto trace =
      std::make_shared<RecoverTrace>(csv ? &*csv : nullptr, r->coupling,
                                     control::coupling_config(profile.coupling), profile.coupling.radius_mm);
  rig.controller().attach(trace, controller::ObserverOptions{profile.servo_period_s, true});
  restore_bore(rig, o.journal, *r);
  rig.step();
  if (!rig.request(controller::Request::simple(control::CommandKind::MachineOn)).accepted ||
      !rig.request(controller::Request::set_mode(control::Mode::Auto)).accepted) {
    fmt::print(stderr, "error: the machine does not come on\n");
    return kExitProgram;
  }
  std::any args;
  if (o.choice == "resume")
    args = recovery::ResumeArgs{o.tolerance_mm, o.tolerance_deg, o.run_in_mm, o.speed_mm_min};
  if (o.choice == "retract")
    args = recovery::RetractArgs{o.distance_mm, o.direction == "onward", o.speed_mm_min};
  const controller::Outcome answer =
      rig.request(controller::Request::feature("journal", o.choice, args), 100000);
  bool done = false;
  std::string why = answer.message;
  if (answer.accepted) {
    why = recovery::run_recovery(rig, *journal);
    done = why.empty();
  }
  journal->flush();
  const auto after = journal->last_written();
  fmt::print("{}  {}\n", o.choice, done ? "completed" : "refused or failed: " + why);
  if (r->coupling.kind != 0)
    fmt::print("helix error         {:.3f} um (feedback, while the breakpoint's law held)\n",
               trace->helix_error_um());
  fmt::print("breakpoint valid    {}\n", after && after->valid ? "yes" : "no (cleared)");
  int rc = done ? kExitOk : kExitProgram;
  if (files[0] && !commit(*files[0])) rc = kExitUsage;
  if (files[1]) {
    nlohmann::json j;
    j["choice"] = o.choice;
    j["completed"] = done;
    j["message"] = why.empty() ? nlohmann::json(nullptr) : nlohmann::json(why);
    j["valid_after"] = after && after->valid;
    j["segment"] = r->segment;
    j["line"] = r->line;
    j["helix_error_um"] = trace->helix_error_um();
    j["machine_time_s"] = rig.status().servo.time_s;
    if (!write_and_commit(*files[1], j.dump(2) + "\n")) rc = kExitUsage;
  }
  return rc;
}

}  // namespace

void add_recover_command(CLI::App& app, Registry& registry) {
  auto o = std::make_shared<RecoverOptions>();
  CLI::App* cmd = app.add_subcommand(
      "recover",
      "After a power failure: resume, retract along the helix, or discard the journal's breakpoint");
  cmd->add_option("choice", o->choice, "resume | retract | discard")
      ->required()
      ->check(CLI::IsMember({"resume", "retract", "discard"}));
  cmd->add_option("--machine,-m", o->machine, "Machine profile, e.g. configs/broach-zc.toml")->required();
  cmd->add_option("--journal", o->journal, "The breakpoint journal's folder (opencnc run --journal)")
      ->required();
  cmd->add_option("--set", o->sets, "Override a profile key (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--distance", o->distance_mm, "retract: distance along the master (Z), mm")
      ->check(CLI::Range(0.0, 1e6));
  cmd->add_option("--direction", o->direction, "retract: onward (the cutting direction) or back (default)")
      ->check(CLI::IsMember({"onward", "back"}));
  cmd->add_option("--speed", o->speed_mm_min,
                  "retract and resume's run-in: speed of the master, mm/min (600)")
      ->check(CLI::Range(0.001, 1e6));
  cmd->add_option("--tolerance", o->tolerance_mm, "resume: linear axes within this of the rest, mm (0.01)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--tolerance-deg", o->tolerance_deg,
                  "resume: rotary axes within this of the rest, deg (0.01)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--run-in", o->run_in_mm,
                  "resume: back off this far along the move before cutting on, mm (2)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_flag("--yes", o->yes, "Confirmed: do not ask on the terminal");
  cmd->add_option("--trace", o->trace, "Write one CSV row per servo period of the recovery");
  cmd->add_option("--report", o->report, "Write the outcome as JSON");
  cmd->callback([o, &registry] {
    if (o->choice == "retract" && !(o->distance_mm > 0)) {
      fmt::print(stderr, "error: retract needs --distance above 0\n");
      registry.set_result(kExitUsage);
      return;
    }
    registry.set_result(recover(*o));
  });
}

}  // namespace opencnc::cli
