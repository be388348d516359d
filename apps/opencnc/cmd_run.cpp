// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc run`: a program on the simulated machine, with a progress bar, a report, a trace.
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
#include "edm_report.hpp"
#include "electrode_change.hpp"
#include "gcode_summary.hpp"
#include "numeric_options.hpp"
#include "opencnc/broaching/power_fail_recorder.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/preflight.hpp"
#include "opencnc/controller/run_recorder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/edm/edm_recorder.hpp"
#include "opencnc/edm/electrode_setting.hpp"
#include "opencnc/process/process_log.hpp"
#include "opencnc/retrace/retrace.hpp"
#include "run_journal.hpp"
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
  std::string process_log;  ///< FILE.csv or FILE.sqlite: the process data at the profile's rate
  double max_time_s = kDefaultMaxTimeS;  ///< 0: no limit
  std::vector<std::string> inject;       ///< "mains-off@SECONDS", "tool-dull@SECONDS=FACTOR", "edm-short@SECONDS",
                                         ///< "analog:CH=VALUE@SECONDS[/RAMP_S]"
  std::vector<std::string> retraces;     ///< "AT_SECONDS:X,Y"
  std::string journal;                   ///< the breakpoint journal's folder ("" = none)
  std::vector<std::string> electrode_changes;  ///< "AT_SECONDS:X,Y,Z"
};

/// One scripted retrace: at `at_s` seconds into the run, pause, jog to (x, y), start.
struct RetraceAt {
  double at_s = 0, x = 0, y = 0;
};

/// "12.5:100,40" → {12.5, 100, 40}; nullopt if it is not that (finite numbers, time ≥ 0).
std::optional<RetraceAt> parse_retrace(const std::string& text) {
  RetraceAt r;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf:%lf,%lf%c", &r.at_s, &r.x, &r.y, &tail) != 3 || !std::isfinite(r.at_s) ||
      !std::isfinite(r.x) || !std::isfinite(r.y) || r.at_s < 0)
    return std::nullopt;
  return r;
}

/// The operator of `--retrace`: at each time, pause the cut (the retrace feature: hold, torch
/// out), jog X then Y to B, and start (to the nearest point C, re-light, cut on).
class RetraceScript {
 public:
  RetraceScript(std::vector<RetraceAt> steps, std::shared_ptr<recovery::RetraceFeature> feature)
      : steps_(std::move(steps)), feature_(std::move(feature)) {}

  void tick(control::Controller& c, const control::ControllerStatus& st) {
    using control::Request;
    if (t0_ < 0 && st.run_active && st.job == control::JobKind::Program) t0_ = st.servo.time_s;
    if (stage_ != Stage::Waiting && asked_ != 0 && !c.outcome(asked_)) return;  // not answered yet
    if (stage_ != Stage::Waiting && asked_ != 0) {
      const control::Outcome o = *c.outcome(asked_);
      asked_ = 0;
      if (!o.accepted) {
        fmt::print(stderr, "error: retrace at {:g} s: {}\n", steps_[next_].at_s, o.message);
        stage_ = Stage::Waiting;
        ++next_;
        return;
      }
    }
    const bool idle = st.servo.state == control::State::Idle && !st.run_active;
    switch (stage_) {
      case Stage::Waiting:
        if (next_ >= steps_.size() || t0_ < 0 || st.servo.time_s - t0_ < steps_[next_].at_s) return;
        if (!st.run_active || st.job != control::JobKind::Program) return;  // between jobs: at the next
        asked_ = c.submit(Request::feature("retrace", "pause"));
        stage_ = Stage::Pausing;
        return;
      case Stage::Pausing:
        if (feature_->phase() != recovery::RetracePhase::Paused || st.servo.mode != control::Mode::Manual ||
            !idle)
          return;
        asked_ = c.submit(Request::jog_by(Axis::X, steps_[next_].x - st.servo.commanded[0], kJogSpeed));
        stage_ = Stage::JogX;
        return;
      case Stage::JogX:
        if (!idle) return;
        asked_ = c.submit(Request::jog_by(Axis::Y, steps_[next_].y - st.servo.commanded[1], kJogSpeed));
        stage_ = Stage::JogY;
        return;
      case Stage::JogY:
        if (!idle) return;
        asked_ = c.submit(Request::feature("retrace", "start"));
        stage_ = Stage::Starting;
        return;
      case Stage::Starting:
        times_.push_back(steps_[next_].at_s);
        stage_ = Stage::Waiting;
        ++next_;
        return;
    }
  }
  /// The program's job ended: the session goes on while a retrace is under way.
  bool goes_on(const control::ControllerEvent& e) const {
    return e.end == control::JobEnd::Aborted && stage_ != Stage::Waiting;
  }
  /// The times of the retraces that started, in order.
  const std::vector<double>& times() const { return times_; }

 private:
  enum class Stage : std::uint8_t { Waiting, Pausing, JogX, JogY, Starting };
  static constexpr double kJogSpeed = 50;  ///< mm/s: a hand on the jog buttons
  std::vector<RetraceAt> steps_;
  std::shared_ptr<recovery::RetraceFeature> feature_;
  std::size_t next_ = 0;
  Stage stage_ = Stage::Waiting;
  std::uint64_t asked_ = 0;
  double t0_ = -1;
  std::vector<double> times_;
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

/// The faults --inject schedules, in servo time from the run's start.
struct Injections {
  double mains_off_s = -1;
  double tool_dull_s = -1, tool_dull_factor = 1;
  double edm_short_s = -1;
};

/// "mains-off@12.5", "tool-dull@4=2.5" or "edm-short@3" into `out`; false with the reason printed.
bool parse_injection(const std::string& text, Injections& out) {
  const auto number = [](const char* from, char stop, const char*& end) {
    char* e = nullptr;
    const double v = std::strtod(from, &e);
    end = e;
    return e != from && *e == stop && std::isfinite(v) ? v : -1.0;
  };
  const char* end = nullptr;
  if (text.rfind("mains-off@", 0) == 0) {
    out.mains_off_s = number(text.c_str() + 10, '\0', end);
    if (out.mains_off_s >= 0) return true;
  } else if (text.rfind("edm-short@", 0) == 0) {
    out.edm_short_s = number(text.c_str() + 10, '\0', end);
    if (out.edm_short_s >= 0) return true;
  } else if (text.rfind("tool-dull@", 0) == 0) {
    out.tool_dull_s = number(text.c_str() + 10, '=', end);
    const double f = out.tool_dull_s >= 0 ? number(end + 1, '\0', end) : -1;
    if (f > 0 && f <= 100) {
      out.tool_dull_factor = f;
      return true;
    }
  }
  fmt::print(
      stderr,
      "error: --inject {}: expected mains-off@SECONDS, tool-dull@SECONDS=FACTOR or edm-short@SECONDS (servo "
      "time from the run's start, >= 0; the cutter's force grows by FACTOR, 0 < FACTOR <= 100, 1 = sharp)\n",
      text);
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
  void show(const control::ControllerStatus& st, double run_start_s, double done_mm) {
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
class TraceObserver final : public control::ControllerObserver {
 public:
  explicit TraceObserver(control::TraceCsvWriter& w) : w_(w) {}
  void on_trace(const control::TraceSample& s, const control::TraceContext&) override {
    if (s.activity == control::Activity::Program) w_.add(s);
  }

 private:
  control::TraceCsvWriter& w_;
};

std::string axis_name(int i) {
  return std::string(1, kAxisLetters[static_cast<std::size_t>(i)]);
}

void print_report(const control::RunReport& r, const config::MachineProfile& profile, const SessionEnd& end) {
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

nlohmann::json power_fail_json(const control::PowerFailReport& p) {
  nlohmann::json j;
  j["happened"] = p.happened;
  j["coupled"] = p.coupled;
  j["signal_s"] = p.signal_s;
  j["stop_time_s"] = p.stop_time_s;
  j["stop_distance_mm"] = p.stop_distance_mm;
  j["coupled_error_um"] = p.coupled_error_um;
  j["coupled_command_error_um"] = p.coupled_command_error_um;
  j["independent_error_um"] = p.independent_error_um;
  j["dc_link_min_v"] = p.happened ? nlohmann::json(p.dc_link_min_v) : nlohmann::json(nullptr);
  j["energy_at_signal_j"] = p.energy_at_signal_j;
  j["energy_at_rest_j"] = p.energy_at_rest_j;
  j["decel_scale"] = p.decel_scale;
  return j;
}

void print_power_fail(const control::PowerFailReport& p) {
  if (!p.happened) {
    fmt::print("power fail          none (the run ended before the injected time)\n");
    return;
  }
  fmt::print("power fail at       {:.3f} s: stopped in {:.3f} s over {:.3f} mm, DC link down to {:.0f} V\n",
             p.signal_s, p.stop_time_s, p.stop_distance_mm, p.dc_link_min_v);
  if (p.energy_at_signal_j > 0 || p.decel_scale > 1)
    fmt::print(
        "DC link energy      {:.2f} J at the signal, {:.2f} J at rest; braked at {:.3f}x the planned "
        "deceleration\n",
        p.energy_at_signal_j, p.energy_at_rest_j, p.decel_scale);
  if (p.coupled)
    fmt::print(
        "helix error         {:.3f} um coupled ({:.6f} um commanded), {:.1f} um if each axis stopped alone\n",
        p.coupled_error_um, p.coupled_command_error_um, p.independent_error_um);
}

nlohmann::json retraces_json(const std::vector<recovery::RetraceRecord>& records,
                             const std::vector<double>& times) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < records.size(); ++i) {
    const recovery::RetraceRecord& r = records[i];
    nlohmann::json j;
    j["at_s"] = i < times.size() ? nlohmann::json(times[i]) : nlohmann::json(nullptr);
    j["a"] = r.a_known ? nlohmann::json({r.a[0], r.a[1], r.a[2]}) : nlohmann::json(nullptr);
    j["b"] = {r.b[0], r.b[1], r.b[2]};
    j["c"] = {r.c[0], r.c[1], r.c[2]};
    j["segment"] = r.segment;
    j["line"] = r.line;
    j["distance_mm"] = r.distance_mm;
    j["candidates"] = r.candidates;
    list.push_back(j);
  }
  return list;
}

nlohmann::json report_json(const control::RunReport& r, const RunOptions& o, const SessionEnd& end,
                           const std::optional<control::PowerFailReport>& power_fail) {
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
  if (power_fail) j["power_fail"] = power_fail_json(*power_fail);
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

int run(const RunOptions& o) {
  // Every output is checked (and created) before anything runs.
  const std::optional<config::MachineProfile> profile = quiet_profile(o.session);
  const std::vector<NamedPath> inputs = session_inputs(o.session, profile ? &*profile : nullptr);
  const NamedPath outputs[] = {{"--trace", o.trace}, {"--report", o.report}, {"--process-log", o.process_log}};
  if (!check_inputs(inputs)) return kExitUsage;
  const std::optional<process::LogFormat> log_format =
      o.process_log.empty() ? std::nullopt : process::log_format(o.process_log);
  if (!o.process_log.empty() && !log_format) {
    fmt::print(stderr, "error: --process-log {}: the name must end in .csv, .sqlite, .sqlite3 or .db\n", o.process_log);
    return kExitUsage;
  }
  const auto files = open_outputs(inputs, outputs);
  if (files.empty()) return kExitUsage;
  OutputFile* const trace_file = files[0].get();
  OutputFile* const report_file = files[1].get();
  OutputFile* const log_file = files[2].get();
  std::shared_ptr<process::ProcessLog> process_log;
  std::shared_ptr<control::RunRecorder> recorder;
  std::shared_ptr<control::PowerFailRecorder> power_recorder;
  std::shared_ptr<control::EdmRecorder> edm_recorder;
  SessionOptions session = o.session;
  session.reports = true;
  if (!o.inject.empty()) {
    Injections at;
    for (const std::string& text : o.inject) {
      if (text.rfind("analog:", 0) == 0) {
        if (session.analog) {
          fmt::print(stderr, "error: --inject {}: one analog injection per run\n", text);
          return kExitUsage;
        }
        session.analog = analog_injection(text, profile ? profile->io.analog_inputs : 0);
        if (!session.analog) return kExitUsage;
      } else if (!parse_injection(text, at)) {
        return kExitUsage;
      }
    }
    if (o.session.realtime || o.session.hal) {
      fmt::print(stderr, "error: --inject works in virtual time only (not with --realtime or --hal)\n");
      return kExitUsage;
    }
    if (at.tool_dull_s >= 0 && profile && !profile->broaching.sim.present) {
      fmt::print(stderr,
                 "error: --inject tool-dull needs a simulated broach ([process.broaching.sim] in {})\n",
                 o.session.machine);
      return kExitUsage;
    }
    session.mains_off_s = at.mains_off_s;
    session.tool_dull_s = at.tool_dull_s;
    session.tool_dull_factor = at.tool_dull_factor;
    if (at.edm_short_s >= 0 && profile && !profile->edm.sim.present) {
      fmt::print(stderr, "error: --inject edm-short needs a simulated spark gap ([edm.sim] in {})\n",
                 o.session.machine);
      return kExitUsage;
    }
    session.edm_short_s = at.edm_short_s;
  }
  if (!o.electrode_changes.empty()) {
    if (o.session.realtime || o.session.hal) {
      fmt::print(stderr,
                 "error: --electrode-change works in virtual time only (not with --realtime or --hal)\n");
      return kExitUsage;
    }
    if (profile && !(profile->probe.reference_sphere.present && profile->probe.reference_sphere.sim)) {
      fmt::print(
          stderr,
          "error: --electrode-change needs a simulated reference sphere ([probe.reference_sphere.sim] in "
          "{})\n",
          o.session.machine);
      return kExitUsage;
    }
    session.tool_table_in_memory = true;  // the simulated electrodes' offsets stay out of the table file
  }
  std::optional<control::TraceCsvWriter> csv;
  std::optional<ProgressBar> bar;
  const bool tty = ::isatty(STDOUT_FILENO) != 0;
  double run_start_s = -1;
  SessionHooks hooks;
  // The machining time against --max-time: once the preflight has passed (an endless program is
  // refused there, in seconds, not estimated first).
  hooks.may_start = [&](const config::MachineProfile& machine, const control::OpenProgram&) {
    return within_max_time(o, machine);
  };
  hooks.opened = [&](const config::MachineProfile& machine, const control::OpenProgram& program) {
    std::vector<std::pair<std::shared_ptr<control::ControllerObserver>, control::ObserverOptions>> out;
    const plan::MachineLimits axes = control::axis_limits(machine);  // the drives' commands: the axes' own
    recorder = std::make_shared<control::RunRecorder>(control::machine_limits(machine),
                                                      machine.servo_period_s, &axes);
    out.emplace_back(recorder, control::ObserverOptions{0, true});
    if (session.mains_off_s >= 0) {
      power_recorder = std::make_shared<control::PowerFailRecorder>(
          control::coupling_config(machine.coupling), control::machine_limits(machine),
          machine.servo_period_s, machine.coupling.radius_mm);
      out.emplace_back(power_recorder, control::ObserverOptions{machine.servo_period_s, true});
    }
    if (trace_file != nullptr) {
      csv.emplace(*trace_file, machine.axis_mask(), machine.servo_period_s);
      out.emplace_back(std::make_shared<TraceObserver>(*csv), control::ObserverOptions{0, true});
    }
    if (log_file != nullptr) {
      process::ProcessLogSetup setup{machine.axis_mask(), machine.broaching.present ? machine.broaching.log_rate_hz : 100.0,
                                     machine.servo_period_s, machine.coupling.present ? machine.coupling.radius_mm : 0.0,
                                     o.session.file, machine.name};
      process_log = std::make_shared<process::ProcessLog>(setup, *log_format, *log_file);
      out.emplace_back(process_log, control::ObserverOptions{0, true});
    }
    if (tty) bar.emplace(program.preflight.summary.path_length_mm);
    return out;
  };
  hooks.progress = [&](const control::ControllerStatus& st, double) {
    if (run_start_s < 0) run_start_s = st.servo.time_s;
    if (bar) bar->show(st, run_start_s, recorder->report().path_length_mm);
  };
  // --retrace: the scripted operator of the retrace feature (flame/plasma machines).
  std::vector<RetraceAt> steps;
  for (const std::string& text : o.retraces) steps.push_back(*parse_retrace(text));  // checked by the option
  std::shared_ptr<recovery::RetraceFeature> feature;
  std::optional<RetraceScript> script;
  // --journal: the breakpoint journal's writer (docs/broaching.md), set up with the features.
  std::shared_ptr<recovery::BreakpointJournal> journal;
  if (!o.journal.empty()) session.settings["journal"] = o.journal;
  // --electrode-change: the scripted operator of the electrode feature on the program's tool table.
  std::vector<ElectrodeChangeAt> changes;
  for (const std::string& text : o.electrode_changes) changes.push_back(*parse_electrode_change(text));
  std::optional<ElectrodeChangeScript> changer;
  hooks.set_up = [&](control::MachineSetup& machine) {
    const config::MachineProfile& p = machine.profile();
    for (const auto& [observer, options] : machine.observers())  // the EDM's report section
      if (auto e = std::dynamic_pointer_cast<control::EdmRecorder>(observer)) edm_recorder = e;
    if (!o.journal.empty()) {
      journal = std::dynamic_pointer_cast<recovery::BreakpointJournal>(machine.feature("journal"));
      if (!journal) {
        fmt::print(stderr,
                   "error: --journal {}: {} has no power monitor ([power] monitor) to write a journal for\n",
                   o.journal, o.session.machine);
        return false;
      }
    }
    if (!changes.empty()) {
      auto electrode = std::dynamic_pointer_cast<control::ElectrodeSetting>(machine.feature("electrode"));
      if (!electrode) {
        fmt::print(stderr, "error: --electrode-change: {} has no tool table for the electrodes\n",
                   o.session.machine);
        return false;
      }
      const Axis axis = p.edm.present ? static_cast<Axis>(p.edm.config.tool_axis) : Axis::Z;
      const config::AxisProfile* a = p.find(axis);
      const double lift = p.edm.present ? 10.0 * p.edm.config.lift_direction : 10.0;
      changer.emplace(changes, electrode, axis, lift, a != nullptr ? a->min_limit : -1e9,
                      a != nullptr ? a->max_limit : 1e9);
    }
    if (!steps.empty()) {
      feature = std::dynamic_pointer_cast<recovery::RetraceFeature>(machine.feature("retrace"));
      if (!feature) {
        fmt::print(stderr, "error: --retrace: {} has no torch to retrace with ([process.cutting])\n",
                   o.session.machine);
        return false;
      }
      script.emplace(steps, feature);
    }
    return true;
  };
  if (!steps.empty() || !changes.empty()) {
    hooks.tick = [&](control::Controller& c, const control::ControllerStatus& st, machine::SimMachine* sim) {
      if (script) script->tick(c, st);
      if (changer) changer->tick(c, st, sim);
    };
    hooks.goes_on = [&](const control::ControllerEvent& e) {
      return (script && script->goes_on(e)) || (changer && changer->goes_on(e));
    };
  }
  const StopSignals signals;  // Ctrl-C: a controlled stop, and the report says so
  session.stop = &StopSignals::requested();
  session.stops = &StopSignals::count();
  session.max_time_s = o.max_time_s;
  const SessionEnd end = run_session(session, hooks);
  if (bar) bar->finish();
  if (!recorder) return end.exit_code;  // nothing ran; the outputs are left as they were
  int rc = end.exit_code;
  if (trace_file != nullptr && !commit_trace(*trace_file)) rc = kExitUsage;
  if (process_log) {
    std::string error;
    if (!process_log->finish(&error) || !log_file->commit(&error)) {
      fmt::print(stderr, "error: --process-log {}: {}\n", o.process_log, error);
      rc = kExitUsage;
    }
  }
  const control::RunReport r = recorder->report();
  print_report(r, end.profile, end);
  std::optional<control::PowerFailReport> power_fail;
  if (power_recorder) {
    power_fail = power_recorder->report();
    print_power_fail(*power_fail);
  }
  nlohmann::json j = report_json(r, o, end, power_fail);
  if (edm_recorder) {
    const control::EdmReport e = edm_recorder->report();
    print_edm(e, end.sim_edm);
    j["edm"] = edm_json(e, end.sim_edm);
  }
  if (feature) {
    const std::vector<recovery::RetraceRecord> records = feature->records();
    for (const recovery::RetraceRecord& x : records) {
      fmt::print("retrace             B ({:.3f}, {:.3f}) -> C ({:.4f}, {:.4f}) {:.3f} mm, segment {}, {}\n",
                 x.b[0], x.b[1], x.c[0], x.c[1], x.distance_mm, x.segment, x.line);
    }
    j["retraces"] = retraces_json(records, script->times());
  }
  if (changer) {
    for (const ElectrodeChangeRecord& x : changer->records()) {
      const control::ElectrodeResult& m = x.measured;
      fmt::print(
          "electrode change    at {:.3f} s, tool {}, segment {}: measured X{:.4f} Y{:.4f} Z{:.4f} (was "
          "X{:.4f} Y{:.4f} Z{:.4f}), {}\n",
          x.at_s, x.tool, x.segment, m.offset[0], m.offset[1], m.offset[2], m.previous[0], m.previous[1],
          m.previous[2], x.resumed ? "resumed" : "not resumed");
    }
    j["electrode_changes"] = changer->json();
  }
  if (journal) j["journal"] = finish_run_journal(*journal, o.journal, end.sim_bore);
  if (report_file != nullptr && !write_and_commit(*report_file, j.dump(2) + "\n")) rc = kExitUsage;
  return rc;
}

}  // namespace

void add_run_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<RunOptions>();
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
  cmd->add_option("--process-log", opts->process_log,
                  "Write the process data (load, positions, feed, helix error) at the profile's rate "
                  "([process.broaching] log_rate_hz, else 100 Hz) to FILE.csv or FILE.sqlite (docs/broaching.md)");
  cmd->add_option("--inject", opts->inject,
                  "Fault injection in virtual time (repeatable): mains-off@SECONDS (the mains fail then; the "
                  "report gains power_fail), tool-dull@SECONDS=FACTOR (the broach's cutter wears: its force "
                  "grows by FACTOR, 1 = sharp), edm-short@SECONDS (a short in the simulated EDM gap), "
                  "analog:CHANNEL=VALUE@SECONDS[/RAMP_SECONDS] (a process input goes to VALUE, drifting over the "
                  "ramp: the profile's alarms act on it)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--journal", opts->journal,
                  "Write the breakpoint journal in this folder when the mains fail (two checksummed slots; "
                  "`opencnc recover` reads it; the report gains `journal`)");
  cmd->add_option(
         "--max-time", opts->max_time_s,
         "Refuse a program that needs more machining time than this, in seconds (default 86400, a day; "
         "0: no limit)")
      ->check(finite_range(0, 1e12));
  cmd->add_option(
         "--retrace", opts->retraces,
         "Script the operator of a flame/plasma retrace: at AT_SECONDS into the run hold the cut (torch "
         "out), jog to X,Y and start from the nearest point of the path (repeatable; the report lists "
         "them as `retraces`)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::Validator(
          [](const std::string& s) {
            return parse_retrace(s) ? std::string()
                                    : "expected AT_SECONDS:X,Y (seconds into the run, mm), e.g. 12.5:100,40";
          },
          "AT_SECONDS:X,Y"));
  cmd->add_option(
         "--electrode-change", opts->electrode_changes,
         "Script the EDM operator who replaces a worn electrode (virtual time, a simulated reference "
         "sphere): at AT_SECONDS into the run feed hold and abort, lift the electrode 10 mm along the "
         "tool axis, put in a new one whose true offsets are X,Y,Z (mm), measure it on the sphere, store "
         "it (in a copy of the tool table) and resume where the job stopped (repeatable; the report "
         "lists them as `electrode_changes`; docs/edm.md)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->excludes("--retrace")
      ->check(CLI::Validator(
          [](const std::string& s) {
            return parse_electrode_change(s) ? std::string()
                                             : "expected AT_SECONDS:X,Y,Z (seconds into the run, mm), e.g. "
                                               "20:0.02,-0.01,0.05";
          },
          "AT_SECONDS:X,Y,Z"));
  cmd->callback([opts, &registry] { registry.set_result(run(*opts)); });
}

}  // namespace opencnc::cli
