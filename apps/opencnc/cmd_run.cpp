// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc run`: a program on the simulated machine, with a progress bar, a report, a trace, and
// each machine feature's part of them (its options, injected faults, operator, lines of the report:
// run_feature.hpp): a loop over the features.
#include <fmt/format.h>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "gcode_summary.hpp"
#include "numeric_options.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/preflight.hpp"
#include "opencnc/controller/run_recorder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "run_feature.hpp"
#include "run_features_parts.hpp"
#include "run_session.hpp"
#include "stop_signals.hpp"

namespace opencnc::cli {

namespace {

/// Default of --max-time: a day of machining. Longer programs exist (moulds), and say so.
constexpr double kDefaultMaxTimeS = 86400;

struct RunOptions {
  SessionOptions session;
  std::string trace;
  std::string report;
  double max_time_s = kDefaultMaxTimeS;  ///< 0: no limit
  std::vector<std::string> inject;  ///< "mains-off@SECONDS", "analog:CH=VALUE@SECONDS[/RAMP_S]", a feature's
};

/// "analog:1=45@3/2" → input 1 goes to 45 from servo time 3 s over 2 s; nullopt with the reason
/// printed (a channel the profile does not have, numbers that are not finite or negative times).
std::optional<SessionOptions::AnalogInjection> analog_injection(const std::string& inject,
                                                                int analog_inputs) {
  SessionOptions::AnalogInjection a;
  const char* p = inject.c_str() + 7;  // after "analog:"
  char* end = nullptr;
  const long channel = std::strtol(p, &end, 10);
  bool ok = end != p && *end == '=';
  if (ok) a.value = std::strtod(p = end + 1, &end);
  ok = ok && end != p && *end == '@' && std::isfinite(a.value);
  if (ok) a.at_s = std::strtod(p = end + 1, &end);
  ok = ok && end != p && std::isfinite(a.at_s) && a.at_s >= 0;
  if (ok && *end == '/') {
    a.ramp_s = std::strtod(p = end + 1, &end);
    ok = end != p && std::isfinite(a.ramp_s) && a.ramp_s >= 0;
  }
  ok = ok && *end == '\0';
  if (!ok) {
    fmt::print(stderr, "error: --inject {}: expected analog:CHANNEL=VALUE@SECONDS[/RAMP_SECONDS]\n", inject);
    return std::nullopt;
  }
  if (channel < 0 || channel >= analog_inputs) {
    fmt::print(stderr, "error: --inject {}: the machine has no analog input {} ([io] analog_inputs = {})\n",
               inject, channel, analog_inputs);
    return std::nullopt;
  }
  a.channel = static_cast<int>(channel);
  return a;
}

/// "mains-off@12.5" into `mains_off_s`, or a feature's fault; false with the reason printed (the
/// forms every feature knows).
bool parse_injection(const std::string& text, double& mains_off_s,
                     const std::vector<std::unique_ptr<RunFeature>>& features) {
  if (text.rfind("mains-off@", 0) == 0) {
    const char* end = nullptr;
    mains_off_s = injection_number(text.c_str() + 10, '\0', end);
    if (mains_off_s >= 0) return true;
  } else {
    for (const auto& f : features) {
      bool ok = false;
      if (f->parse_injection(text, ok)) {
        if (ok) return true;
        break;
      }
    }
  }
  std::vector<std::string> forms = {"mains-off@SECONDS"};
  std::string notes;
  for (const auto& f : features) {
    for (const InjectionForm& i : f->injections()) {
      forms.push_back(i.form);
      if (!i.note.empty()) notes += "; " + i.note;
    }
  }
  std::string list;
  for (std::size_t k = 0; k < forms.size(); ++k)
    list += (k == 0 ? "" : k + 1 == forms.size() ? " or " : ", ") + forms[k];
  fmt::print(stderr, "error: --inject {}: expected {} (servo time from the run's start, >= 0{})\n", text,
             list, notes);
  return false;
}

/// "3.2 h", "19.0 years": a duration a person reads at a glance.
std::string human_duration(double s) {
  if (s < 120) return fmt::format("{:.1f} s", s);
  if (s < 7200) return fmt::format("{:.1f} min", s / 60);
  if (s < 2 * 86400) return fmt::format("{:.1f} h", s / 3600);
  if (s < 2 * 365.25 * 86400) return fmt::format("{:.1f} days", s / 86400);
  return fmt::format("{:.3g} years", s / (365.25 * 86400));
}

/// Refuses (with the reason, and the slowest move) a program that needs more machining time than
/// --max-time before it runs: F0.000001 would otherwise run for years. A program the scan cannot
/// finish is left to the run, which reports its errors.
bool within_max_time(const RunOptions& o, const config::MachineProfile& profile) {
  if (o.max_time_s <= 0) return true;
  const TimeEstimate e = estimate_machining_time(o.session.file, profile);
  if (!e.complete || e.total_s() <= o.max_time_s) return true;
  fmt::print(
      stderr,
      "error: {} needs at least {} of machining (feed {:.6g} s, rapid {:.6g} s, dwell {:.6g} s), more than "
      "--max-time {:g} s ({}){}; raise --max-time (0: no limit) if that is meant\n",
      o.session.file, human_duration(e.total_s()), e.feed_s, e.rapid_s, e.dwell_s, o.max_time_s,
      human_duration(o.max_time_s),
      e.slowest_move_at.empty() ? std::string()
                                : fmt::format("; the slowest move, {}, takes {}", e.slowest_move_at,
                                              human_duration(e.slowest_move_s)));
  return false;
}

/// "[#########...........]  42.1 %  line 123  12.3 s  ~17.0 s left" on one terminal line: the
/// path run so far against the preflight's length of the whole program.
class ProgressBar {
 public:
  explicit ProgressBar(double total_mm) : total_mm_(total_mm) {}
  void show(const controller::ControllerStatus& st, double run_start_s, double done_mm) {
    const double done = total_mm_ > 0 ? std::min(1.0, done_mm / total_mm_) : st.progress;
    const double elapsed = st.servo.time_s - run_start_s;
    const int width = 30, filled = static_cast<int>(done * width + 0.5);
    const std::string left = done > 0.01 ? fmt::format("~{:.1f} s left", elapsed * (1 - done) / done) : "";
    fmt::print("\r[{}{}] {:5.1f} %  line {:<6}  {:.1f} s  {:<16}",
               std::string(static_cast<std::size_t>(filled), '#'),
               std::string(static_cast<std::size_t>(width - filled), '.'), 100 * done, st.servo.line, elapsed,
               left);
    std::fflush(stdout);
  }
  void finish() { fmt::print("\n"); }

 private:
  double total_mm_;
};

/// The trace CSV, one row per period of the program run.
class TraceObserver final : public controller::ControllerObserver {
 public:
  explicit TraceObserver(controller::TraceCsvWriter& w) : w_(w) {}
  void on_trace(const control::TraceSample& s, const controller::TraceContext&) override {
    if (s.activity == control::Activity::Program) w_.add(s);
  }

 private:
  controller::TraceCsvWriter& w_;
};

std::string axis_name(int i) {
  return std::string(1, kAxisLetters[static_cast<std::size_t>(i)]);
}

void print_report(const controller::RunReport& r, const config::MachineProfile& profile,
                  const SessionEnd& end) {
  fmt::print("machining time      {:.3f} s (motion {:.3f} s)\n", r.machining_time_s, r.motion_time_s);
  fmt::print("path length         {:.3f} mm\n", r.path_length_mm);
  fmt::print("max following error {:.4f} mm{}\n", r.max_following_error_mm,
             r.max_following_error_axis >= 0 ? " (" + axis_name(r.max_following_error_axis) + ")" : "");
  fmt::print("max contour error   {:.4f} mm actual, {:.4f} mm commanded\n", r.max_contour_error_mm,
             r.max_command_contour_error_mm);
  fmt::print("axis  max velocity  max acceleration  max jerk\n");
  for (const config::AxisProfile& a : profile.axes) {
    const analysis::AxisStats& s = r.axes[static_cast<std::size_t>(index(a.axis))];
    if (a.manual()) {
      fmt::print("  {}   moved by hand\n", letter(a.axis));
      continue;
    }
    fmt::print("  {}   {:10.3f}    {:12.1f}    {:12.0f}\n", letter(a.axis), s.max_velocity,
               s.max_acceleration, s.max_jerk);
  }
  fmt::print("limit violations    {}{}\n", r.limit_violations,
             end.limit_touched ? " (and a limit stopped the run)" : "");
  if (end.wall_s > 0) {
    fmt::print("wall time           {:.3f} s ({:.0f}x real time)\n", end.wall_s,
               r.machining_time_s / end.wall_s);
  }
}

nlohmann::json report_json(const controller::RunReport& r, const RunOptions& o, const SessionEnd& end) {
  nlohmann::json j;
  j["program"] = o.session.file;
  j["machine"] = end.profile.name;
  j["realtime"] = o.session.realtime || o.session.hal;
  j["hal"] = o.session.hal ? nlohmann::json(o.session.hal_shm) : nlohmann::json(nullptr);
  j["finished"] = end.finished;
  j["fault"] = end.fault.empty() ? nlohmann::json(nullptr) : nlohmann::json(end.fault);
  j["stopped_by"] =
      end.stopped_by != 0 ? nlohmann::json(signal_name(end.stopped_by)) : nlohmann::json(nullptr);
  j["machining_time_s"] = r.machining_time_s;
  j["motion_time_s"] = r.motion_time_s;
  j["path_length_mm"] = r.path_length_mm;
  j["max_following_error_mm"] = r.max_following_error_mm;
  j["max_contour_error_mm"] = r.max_contour_error_mm;
  j["max_command_contour_error_mm"] = r.max_command_contour_error_mm;
  nlohmann::json v, a, k;
  for (const config::AxisProfile& ax : end.profile.axes) {
    const analysis::AxisStats& s = r.axes[static_cast<std::size_t>(index(ax.axis))];
    const std::string name = axis_name(index(ax.axis));
    v[name] = s.max_velocity;
    a[name] = s.max_acceleration;
    k[name] = s.max_jerk;
  }
  j["max_velocity"] = v;
  j["max_acceleration"] = a;
  j["max_jerk"] = k;
  j["limit_violations"] = r.limit_violations;
  j["limit_touched"] = r.limit_violations > 0 || end.limit_touched;
  j["samples"] = r.samples;
  j["wall_time_s"] = end.wall_s;
  return j;
}

/// Commits the trace; a failure names the reason and how much of the trace is whole.
bool commit_trace(OutputFile& trace) {
  std::string error;
  if (trace.commit(&error)) return true;
  const std::uint64_t rows = trace.records() > 0 ? trace.records() - 1 : 0;
  fmt::print(stderr, "error: {}; {}\n", error,
             trace.records() > 0 ? fmt::format("the trace keeps its first {} whole rows", rows)
                                 : std::string("the trace was not written"));
  return false;
}

int run(const RunOptions& o, const std::vector<std::unique_ptr<RunFeature>>& features) {
  // Every output is checked (and created) before anything runs.
  const std::optional<config::MachineProfile> profile = quiet_profile(o.session);
  const std::vector<NamedPath> inputs = session_inputs(o.session, profile ? &*profile : nullptr);
  std::vector<NamedPath> outputs = {{"--trace", o.trace}, {"--report", o.report}};
  for (const auto& f : features) {
    const std::vector<NamedPath> mine = f->outputs();
    outputs.insert(outputs.end(), mine.begin(), mine.end());
  }
  if (!check_inputs(inputs)) return kExitUsage;
  for (const auto& f : features)
    if (!f->check_options()) return kExitUsage;
  const auto files = open_outputs(inputs, outputs);
  if (files.empty()) return kExitUsage;
  OutputFile* const trace_file = files[0].get();
  OutputFile* const report_file = files[1].get();
  for (std::size_t i = 2; const auto& f : features) {
    std::vector<OutputFile*> mine;
    for (std::size_t k = 0; k < f->outputs().size(); ++k) mine.push_back(files[i++].get());
    f->take_outputs(mine);
  }
  std::shared_ptr<controller::RunRecorder> recorder;
  SessionOptions session = o.session;
  session.reports = true;
  if (!o.inject.empty()) {
    for (const std::string& text : o.inject) {
      if (text.rfind("analog:", 0) == 0) {
        if (session.analog) {
          fmt::print(stderr, "error: --inject {}: one analog injection per run\n", text);
          return kExitUsage;
        }
        session.analog = analog_injection(text, profile ? profile->io.analog_inputs : 0);
        if (!session.analog) return kExitUsage;
      } else if (!parse_injection(text, session.mains_off_s, features)) {
        return kExitUsage;
      }
    }
    if (o.session.realtime || o.session.hal) {
      fmt::print(stderr, "error: --inject works in virtual time only (not with --realtime or --hal)\n");
      return kExitUsage;
    }
  }
  for (const auto& f : features)
    if (!f->check(profile ? &*profile : nullptr, session)) return kExitUsage;
  std::optional<controller::TraceCsvWriter> csv;
  std::optional<ProgressBar> bar;
  const bool tty = ::isatty(STDOUT_FILENO) != 0;
  double run_start_s = -1;
  SessionHooks hooks;
  hooks.set_up = [&](controller::MachineSetup& machine) {
    for (const auto& f : features)
      if (!f->set_up(machine)) return false;
    return true;
  };
  // The machining time against --max-time: once the preflight has passed (an endless program is
  // refused there, in seconds, not estimated first).
  hooks.may_start = [&](const config::MachineProfile& machine, const controller::OpenProgram&) {
    return within_max_time(o, machine);
  };
  hooks.opened = [&](const config::MachineProfile& machine, const controller::OpenProgram& program) {
    SessionObservers out;
    const plan::MachineLimits axes = controller::axis_limits(machine);  // the drives' commands: the axes' own
    recorder = std::make_shared<controller::RunRecorder>(controller::machine_limits(machine),
                                                         machine.servo_period_s, &axes);
    out.emplace_back(recorder, controller::ObserverOptions{0, true});
    for (const auto& f : features) f->opened(machine, out);
    if (trace_file != nullptr) {
      csv.emplace(*trace_file, machine.axis_mask(), machine.servo_period_s);
      out.emplace_back(std::make_shared<TraceObserver>(*csv), controller::ObserverOptions{0, true});
    }
    if (tty) bar.emplace(program.preflight.summary.path_length_mm);
    return out;
  };
  hooks.progress = [&](const controller::ControllerStatus& st, double) {
    if (run_start_s < 0) run_start_s = st.servo.time_s;
    if (bar) bar->show(st, run_start_s, recorder->report().path_length_mm);
  };
  hooks.tick = [&](controller::Controller& c, const controller::ControllerStatus& st,
                   machine::SimMachine* sim) {
    for (const auto& f : features) f->tick(c, st, sim);
  };
  hooks.goes_on = [&](const controller::ControllerEvent& e) {
    return std::any_of(features.begin(), features.end(), [&](const auto& f) { return f->goes_on(e); });
  };
  hooks.on_event = [&](const controller::ControllerEvent& e, SessionOperator& op) {
    for (const auto& f : features) f->on_event(e, op);
  };
  hooks.finished = [&](machine::SimMachine* sim) {
    for (const auto& f : features) f->finished(sim);
  };
  const StopSignals signals;  // Ctrl-C: a controlled stop, and the report says so
  session.stop = &StopSignals::requested();
  session.stops = &StopSignals::count();
  session.max_time_s = o.max_time_s;
  const SessionEnd end = run_session(session, hooks);
  if (bar) bar->finish();
  if (!recorder) return end.exit_code;  // nothing ran; the outputs are left as they were
  int rc = end.exit_code;
  if (trace_file != nullptr && !commit_trace(*trace_file)) rc = kExitUsage;
  const controller::RunReport r = recorder->report();
  print_report(r, end.profile, end);
  nlohmann::json j = report_json(r, o, end);
  for (const auto& f : features)  // each feature's lines and part of the report
    if (!f->report(j)) rc = kExitUsage;
  if (report_file != nullptr && !write_and_commit(*report_file, j.dump(2) + "\n")) rc = kExitUsage;
  return rc;
}

}  // namespace

void add_run_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<RunOptions>();
  auto features = std::make_shared<std::vector<std::unique_ptr<RunFeature>>>(run_features());
  CLI::App* cmd = app.add_subcommand("run", "Run a G-code program on the simulated machine and report on it");
  cmd->add_option("file", opts->session.file, "G-code program")->required();
  cmd->add_option("--machine,-m", opts->session.machine, "Machine profile, e.g. configs/mill-3axis.toml")
      ->required();
  cmd->add_option("--set", opts->session.sets,
                  "Override a profile key: --set axis.x.max_velocity=200 (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--realtime", opts->session.realtime,
                "Tick in a real-time periodic thread instead of virtual time");
  CLI::Option* hal = cmd->add_flag("--hal", opts->session.hal,
                                   "Drive the machine through LinuxCNC's HAL: the tick runs in the component "
                                   "opencnc_rt.so, this process attaches to its shared memory (docs/hal.md)");
  hal->excludes("--realtime");
  cmd->add_option("--hal-shm", opts->session.hal_shm,
                  "The component's shared memory (its shm= parameter), default /opencnc")
      ->needs(hal);
  cmd->add_flag("--unattended", opts->session.unattended,
                "Go on by itself at program stops (M0, M1) and manual tool changes instead of asking the "
                "operator on the terminal");
  cmd->add_option("--trace", opts->trace, "Write one CSV row per servo period (docs/controller.md)");
  cmd->add_option("--report", opts->report, "Write the report as JSON");
  std::string faults;
  for (const auto& f : *features)
    for (const InjectionForm& i : f->injections()) faults += fmt::format("{} ({}), ", i.form, i.help);
  cmd->add_option(
         "--inject", opts->inject,
         "Fault injection in virtual time (repeatable): mains-off@SECONDS (the mains fail then; the "
         "report gains power_fail), " +
             faults +
             "analog:CHANNEL=VALUE@SECONDS[/RAMP_SECONDS] (a process input goes to VALUE, drifting over "
             "the ramp: the profile's alarms act on it)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option(
         "--max-time", opts->max_time_s,
         "Refuse a program that needs more machining time than this, in seconds (default 86400, a day; "
         "0: no limit)")
      ->check(finite_range(0, 1e12));
  for (const auto& f : *features) f->add_options(*cmd);  // each feature's own options
  cmd->callback([opts, features, &registry] { registry.set_result(run(*opts, *features)); });
}

}  // namespace opencnc::cli
