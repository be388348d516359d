// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc plot`: the toolpath (XY, XZ, YZ, isometric) and the velocity, acceleration and
// following-error profiles of a run, as SVG — from a program (run in virtual time) or a trace CSV;
// a homing trace (`opencnc calibrate --trace`) shows each axis' homing phases and sensor level.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "opencnc/control/homing.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/viz/svg_chart.hpp"
#include "run_session.hpp"

namespace opencnc::cli {

namespace {

struct PlotOptions {
  SessionOptions session;
  std::string trace;
  std::string out;
};

/// What a plot needs of one servo period.
struct Sample {
  double t = 0;
  bool rapid = false;
  double path_velocity = 0;
  Pose cmd{};
  Pose ferr{};
  Pose act{};
  Pose level{};  ///< the home sensor's level
  std::array<control::HomingPhase, kAxisCount> phase{};
};

/// The phase a trace names ("search", …); Idle for anything else.
control::HomingPhase phase_named(const std::string& name) {
  for (int p = 0; p <= static_cast<int>(control::HomingPhase::Failed); ++p) {
    const auto phase = static_cast<control::HomingPhase>(p);
    if (name == control::to_string(phase)) return phase;
  }
  return control::HomingPhase::Idle;
}

struct Trace {
  AxisMask axes;
  double period_s = 1e-3;
  std::vector<Sample> samples;
};

// --- reading a trace CSV (the columns TraceCsvWriter writes) ---------------------------------

/// Largest magnitude a trace value may have (mm, degrees, s, mm/s): beyond it a chart's scale
/// overflows, and no machine travels a million kilometres.
constexpr double kMaxTraceValue = 1e9;

/// The columns a plot reads, by index in the header (-1: absent).
struct TraceColumns {
  int t = -1, rapid = -1, v = -1;
  std::array<int, kAxisCount> cmd{}, ferr{}, act{}, phase{}, level{};
};

TraceColumns find_columns(const std::vector<std::string>& head, AxisMask& axes) {
  TraceColumns c;
  for (auto* col : {&c.cmd, &c.ferr, &c.act, &c.phase, &c.level}) col->fill(-1);
  for (int k = 0; k < static_cast<int>(head.size()); ++k) {
    const std::string& h = head[static_cast<std::size_t>(k)];
    if (h == "time_s") c.t = k;
    if (h == "rapid") c.rapid = k;
    if (h == "path_velocity") c.v = k;
    for (int i = 0; i < kAxisCount; ++i) {
      const std::string a(1, kAxisLetters[static_cast<std::size_t>(i)]);
      if (h == "cmd_" + a) c.cmd[static_cast<std::size_t>(i)] = k, axes.set(static_cast<Axis>(i));
      if (h == "ferr_" + a) c.ferr[static_cast<std::size_t>(i)] = k;
      if (h == "act_" + a) c.act[static_cast<std::size_t>(i)] = k;
      if (h == "phase_" + a) c.phase[static_cast<std::size_t>(i)] = k;
      if (h == "level_" + a) c.level[static_cast<std::size_t>(i)] = k;
    }
  }
  return c;
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> out;
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    out.push_back(
        line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) return out;
    start = comma + 1;
  }
}

/// Field `k` of a row as a number a chart can take; `error` says file:row:col otherwise.
bool number_field(const std::vector<std::string_view>& fields, std::string_view line, int k,
                  const std::string& where, double& out, std::string& error) {
  const std::string_view f = fields[static_cast<std::size_t>(k)];
  const auto col = static_cast<std::size_t>(f.data() - line.data()) + 1;
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), out);
  if (ec == std::errc() && end == f.data() + f.size() && std::isfinite(out) &&
      std::fabs(out) <= kMaxTraceValue)
    return true;
  if (ec == std::errc::invalid_argument || end != f.data() + f.size())
    error = fmt::format("{}:{}: '{}' is not a number", where, col, f);
  else
    error = fmt::format("{}:{}: {} is out of range (a plot takes finite values up to {:g} in magnitude)",
                        where, col, f, kMaxTraceValue);
  return false;
}

bool read_trace(const std::string& path, Trace& trace, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = fmt::format("cannot read the trace {}: {}", path, std::strerror(errno));
    return false;
  }
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  for (const std::string_view h : split_fields(line)) head.emplace_back(h);
  const TraceColumns c = find_columns(head, trace.axes);
  if (c.t < 0 || trace.axes.count() == 0) {
    error = path + " is not an opencnc trace (no time_s or cmd_ columns)";
    return false;
  }
  std::size_t row = 1;
  while (std::getline(in, line)) {
    ++row;
    const std::vector<std::string_view> v = split_fields(line);
    const std::string where = fmt::format("{}:{}", path, row);
    if (v.size() != head.size()) {
      error = fmt::format("{}: {} fields, the header has {}", where, v.size(), head.size());
      return false;
    }
    Sample s;
    double rapid = 0;
    auto field = [&](int k, double& out) { return k < 0 || number_field(v, line, k, where, out, error); };
    bool ok = field(c.t, s.t) && field(c.rapid, rapid) && field(c.v, s.path_velocity);
    for (int i = 0; ok && i < kAxisCount; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      ok = field(c.cmd[ui], s.cmd[i]) && field(c.ferr[ui], s.ferr[i]) && field(c.level[ui], s.level[i]);
      s.act[i] = s.cmd[i];
      ok = ok && field(c.act[ui], s.act[i]);
      if (c.phase[ui] >= 0) s.phase[ui] = phase_named(std::string(v[static_cast<std::size_t>(c.phase[ui])]));
    }
    if (!ok) return false;
    s.rapid = rapid != 0;
    trace.samples.push_back(s);
  }
  if (trace.samples.size() > 1) trace.period_s = trace.samples[1].t - trace.samples[0].t;
  return true;
}

// --- panels ----------------------------------------------------------------------------------

constexpr const char* kFeedColor = "#1f77b4";
constexpr const char* kRapidColor = "#e8590c";
constexpr const char* kAxisColors[] = {"#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
                                       "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

/// A toolpath view: one polyline per stretch of feed or rapid moves, rapids in their own colour.
template <typename Project>
viz::Panel toolpath(const Trace& tr, std::string title, std::string x_label, std::string y_label,
                    Project project) {
  viz::Panel p;
  p.title = std::move(title);
  p.x_label = std::move(x_label);
  p.y_label = std::move(y_label);
  p.equal_scale = true;
  bool have_feed = false, have_rapid = false;
  for (std::size_t i = 0; i < tr.samples.size(); ++i) {
    const Sample& s = tr.samples[i];
    if (p.series.empty() || (i > 0 && s.rapid != tr.samples[i - 1].rapid)) {
      viz::Series series;
      series.color = s.rapid ? kRapidColor : kFeedColor;
      series.width = s.rapid ? 0.8 : 1.2;
      bool& labelled = s.rapid ? have_rapid : have_feed;
      if (!labelled) series.label = s.rapid ? "rapid (G0)" : "feed";
      labelled = true;
      if (i > 0) {  // join the stretches
        const auto [x0, y0] = project(tr.samples[i - 1].cmd);
        series.x.push_back(x0);
        series.y.push_back(y0);
      }
      p.series.push_back(std::move(series));
    }
    const auto [x, y] = project(s.cmd);
    p.series.back().x.push_back(x);
    p.series.back().y.push_back(y);
  }
  return p;
}

/// Columns a time plot has room for.
constexpr std::size_t kColumns = 1200;
/// Long runs: more than this many periods per column are drawn as peaks (see envelope()), over
/// wider columns so that motions that come and go (raster steps) read as a level, not a comb.
constexpr std::size_t kPeaksFrom = 16;
constexpr std::size_t kPeakColumns = 300;

/// Periods per column of a time plot, and whether it shows peaks.
std::pair<std::size_t, bool> columns(const Trace& tr) {
  const std::size_t n = tr.samples.size();
  if (n / kColumns <= kPeaksFrom) return {std::max<std::size_t>(1, n / kColumns), false};
  return {n / kPeakColumns, true};
}

/// `value(i)` over time in about kColumns columns. Short runs: the smallest and largest value of
/// each column, in order (the signed curve). Long runs, where that would be a solid band: the
/// largest |value| of each column, which keeps the peaks and the trend readable.
template <typename Value>
viz::Series envelope(const Trace& tr, std::string label, const char* color, Value value) {
  viz::Series s;
  s.label = std::move(label);
  s.color = color;
  s.width = 1.0;
  const std::size_t n = tr.samples.size();
  const auto [per, peaks] = columns(tr);
  for (std::size_t b = 0; b < n; b += per) {
    double lo = 1e300, hi = -1e300;
    std::size_t at_lo = b, at_hi = b;
    for (std::size_t i = b; i < std::min(n, b + per); ++i) {
      const double v = peaks ? std::fabs(value(i)) : value(i);
      if (v < lo) lo = v, at_lo = i;
      if (v > hi) hi = v, at_hi = i;
    }
    if (peaks) {
      s.x.push_back(tr.samples[b].t);
      s.y.push_back(hi);
      continue;
    }
    for (std::size_t i : {std::min(at_lo, at_hi), std::max(at_lo, at_hi)}) {
      s.x.push_back(tr.samples[i].t);
      s.y.push_back(i == at_lo ? lo : hi);
    }
  }
  return s;
}

/// " (largest |value| per 0.24 s)" when envelope() draws peaks.
std::string peaks_note(const Trace& tr) {
  const auto [per, peaks] = columns(tr);
  if (!peaks) return "";
  return fmt::format(" — largest |value| per {:.2g} s", static_cast<double>(per) * tr.period_s);
}

viz::Panel velocities(const Trace& tr) {
  viz::Panel p;
  p.title = "velocity" + peaks_note(tr);
  p.x_label = "time (s)";
  p.y_label = "velocity (mm/s, deg/s)";
  p.series.push_back(
      envelope(tr, "path", "#000000", [&](std::size_t i) { return tr.samples[i].path_velocity; }));
  for (int a = 0; a < kAxisCount; ++a) {
    if (!tr.axes.has(static_cast<Axis>(a))) continue;
    p.series.push_back(envelope(
        tr, std::string(1, kAxisLetters[static_cast<std::size_t>(a)]), kAxisColors[a], [&](std::size_t i) {
          return i == 0 ? 0.0 : (tr.samples[i].cmd[a] - tr.samples[i - 1].cmd[a]) / tr.period_s;
        }));
  }
  return p;
}

viz::Panel accelerations(const Trace& tr) {
  viz::Panel p;
  p.title = "acceleration (commanded)" + peaks_note(tr);
  p.x_label = "time (s)";
  p.y_label = "acceleration (mm/s², deg/s²)";
  const double t2 = tr.period_s * tr.period_s;
  for (int a = 0; a < kAxisCount; ++a) {
    if (!tr.axes.has(static_cast<Axis>(a))) continue;
    p.series.push_back(envelope(tr, std::string(1, kAxisLetters[static_cast<std::size_t>(a)]), kAxisColors[a],
                                [&](std::size_t i) {
                                  if (i < 2) return 0.0;
                                  const auto& x = tr.samples;
                                  return (x[i].cmd[a] - 2 * x[i - 1].cmd[a] + x[i - 2].cmd[a]) / t2;
                                }));
  }
  return p;
}

viz::Panel following_errors(const Trace& tr) {
  viz::Panel p;
  p.title = "following error" + peaks_note(tr);
  p.x_label = "time (s)";
  p.y_label = "following error (µm, mdeg)";
  for (int a = 0; a < kAxisCount; ++a) {
    if (!tr.axes.has(static_cast<Axis>(a))) continue;
    p.series.push_back(envelope(tr, std::string(1, kAxisLetters[static_cast<std::size_t>(a)]), kAxisColors[a],
                                [&](std::size_t i) { return 1000.0 * tr.samples[i].ferr[a]; }));
  }
  return p;
}

// --- homing traces ----------------------------------------------------------------------------

constexpr const char* kPhaseColors[] = {"#999999", "#8c564b", "#1f77b4", "#17becf", "#9467bd",
                                        "#bcbd22", "#e8590c", "#2ca02c", "#d62728", "#e377c2",
                                        "#7f7f7f", "#000000", "#ff0000"};

bool homes(const Trace& tr, int a) {
  for (const Sample& s : tr.samples) {
    const control::HomingPhase p = s.phase[static_cast<std::size_t>(a)];
    if (p != control::HomingPhase::Idle && p != control::HomingPhase::Done) return true;
  }
  return false;
}

/// The axis' position over time, one colour per homing phase.
viz::Panel homing_phases(const Trace& tr, int a) {
  viz::Panel p;
  const char axis = kAxisLetters[static_cast<std::size_t>(a)];
  p.title = fmt::format("homing {}: position by phase", axis);
  p.x_label = "time (s)";
  p.y_label = fmt::format("{} (mm)", axis);
  std::array<bool, std::size(kPhaseColors)> labelled{};
  for (std::size_t i = 0; i < tr.samples.size(); ++i) {
    const auto phase = tr.samples[i].phase[static_cast<std::size_t>(a)];
    if (p.series.empty() || phase != tr.samples[i - 1].phase[static_cast<std::size_t>(a)]) {
      const auto k = std::min<std::size_t>(static_cast<std::size_t>(phase), std::size(kPhaseColors) - 1);
      viz::Series s;
      s.color = kPhaseColors[k];
      if (!labelled[k]) s.label = control::to_string(phase);
      labelled[k] = true;
      if (i > 0) {
        s.x.push_back(tr.samples[i - 1].t);
        s.y.push_back(tr.samples[i - 1].act[a]);
      }
      p.series.push_back(std::move(s));
    }
    p.series.back().x.push_back(tr.samples[i].t);
    p.series.back().y.push_back(tr.samples[i].act[a]);
  }
  return p;
}

/// The home sensor's level against the position while the edges are measured (the ramps whose
/// threshold crossings homing interpolates).
viz::Panel sensor_level(const Trace& tr, int a) {
  viz::Panel p;
  const char axis = kAxisLetters[static_cast<std::size_t>(a)];
  p.title = fmt::format("homing {}: sensor level while returning and measuring", axis);
  p.x_label = fmt::format("{} (mm, before the origin was set)", axis);
  p.y_label = "level (0 … 1)";
  viz::Series s;
  s.label = "level";
  s.color = kAxisColors[a];
  for (const Sample& x : tr.samples) {
    const auto phase = x.phase[static_cast<std::size_t>(a)];
    if (phase != control::HomingPhase::Return && phase != control::HomingPhase::Measure) continue;
    s.x.push_back(x.act[a]);
    s.y.push_back(x.level[a]);
  }
  p.series.push_back(std::move(s));
  return p;
}

/// A homing trace: per homing axis, its position by phase and the sensor's level.
std::string draw_homing(const Trace& tr, const std::string& title) {
  viz::SvgChart chart(title, 2, 640, 430);
  for (int a = 0; a < kAxisCount; ++a) {
    if (!tr.axes.has(static_cast<Axis>(a)) || !homes(tr, a)) continue;
    chart.add_panel(homing_phases(tr, a));
    chart.add_panel(sensor_level(tr, a));
  }
  return chart.render();
}

/// The whole page as an SVG document (a homing trace gets the homing charts).
std::string draw(const Trace& tr, const std::string& title) {
  for (int a = 0; a < kAxisCount; ++a) {
    if (tr.axes.has(static_cast<Axis>(a)) && homes(tr, a)) return draw_homing(tr, title);
  }
  viz::SvgChart chart(title, 2, 640, 430);
  const auto xy = [](int a, int b) { return [a, b](const Pose& q) { return std::pair{q[a], q[b]}; }; };
  chart.add_panel(toolpath(tr, "toolpath XY (top)", "X (mm)", "Y (mm)", xy(0, 1)));
  chart.add_panel(toolpath(tr, "toolpath XZ (front)", "X (mm)", "Z (mm)", xy(0, 2)));
  chart.add_panel(toolpath(tr, "toolpath YZ (side)", "Y (mm)", "Z (mm)", xy(1, 2)));
  const double c30 = std::sqrt(3.0) / 2, s30 = 0.5;
  chart.add_panel(toolpath(tr, "toolpath isometric", "(X − Y)·cos 30° (mm)", "(X + Y)·sin 30° + Z (mm)",
                           [&](const Pose& q) {
                             return std::pair{(q[0] - q[1]) * c30, (q[0] + q[1]) * s30 + q[2]};
                           }));
  chart.add_panel(velocities(tr));
  chart.add_panel(accelerations(tr));
  chart.add_panel(following_errors(tr));
  return chart.render();
}

/// A plot draws a trace or runs a program; given both it could only guess which was meant.
bool check_sources(const PlotOptions& o) {
  const bool program = !o.session.file.empty() || !o.session.machine.empty() || !o.session.sets.empty();
  if (!o.trace.empty() && program) {
    fmt::print(stderr, "error: plot draws a trace (--trace) or runs a program (with --machine), not both\n");
    return false;
  }
  if (o.trace.empty() && (o.session.file.empty() || o.session.machine.empty())) {
    fmt::print(stderr, "error: plot wants a program and --machine, or --trace\n");
    return false;
  }
  return true;
}

/// The program run's samples, as the plot draws them.
class PlotRecorder final : public controller::ControllerObserver {
 public:
  explicit PlotRecorder(Trace& tr) : tr_(tr) {}
  void on_trace(const control::TraceSample& s, const controller::TraceContext&) override {
    if (s.activity != control::Activity::Program) return;
    tr_.samples.push_back(Sample{static_cast<double>(s.tick) * tr_.period_s, s.rapid, s.path_velocity,
                                 s.commanded, s.following_error, s.actual, s.home_level, s.homing_phase});
  }

 private:
  Trace& tr_;
};

int plot(const PlotOptions& o) {
  if (!check_sources(o)) return kExitUsage;
  const std::optional<config::MachineProfile> profile =
      o.trace.empty() ? quiet_profile(o.session) : std::nullopt;
  const std::vector<NamedPath> inputs = o.trace.empty()
                                            ? session_inputs(o.session, profile ? &*profile : nullptr)
                                            : std::vector<NamedPath>{{"the trace", o.trace}};
  const NamedPath outputs[] = {{"-o", o.out}};
  if (!check_inputs(inputs)) return kExitUsage;
  const auto files = open_outputs(inputs, outputs);
  if (files.empty()) return kExitUsage;
  Trace tr;
  std::string error, title;
  if (!o.trace.empty()) {
    if (!read_trace(o.trace, tr, error)) {  // (check_inputs said it can be read: its data is bad)
      fmt::print(stderr, "error: {}\n", error);
      return kExitProgram;
    }
    title = "opencnc trace " + o.trace;
  } else {
    SessionHooks hooks;
    hooks.opened = [&](const config::MachineProfile& p, const controller::OpenProgram&) {
      tr.axes = p.axis_mask();
      tr.period_s = p.servo_period_s;
      std::vector<std::pair<std::shared_ptr<controller::ControllerObserver>, controller::ObserverOptions>>
          out;
      out.emplace_back(std::make_shared<PlotRecorder>(tr), controller::ObserverOptions{0, true});
      return out;
    };
    SessionOptions session = o.session;
    session.unattended = true;  // a drawing: program stops and tool changes go on by themselves
    const SessionEnd end = run_session(session, hooks);
    if (tr.samples.empty()) return end.exit_code == kExitOk ? kExitProgram : end.exit_code;
    title = fmt::format("opencnc {} on {}", o.session.file, end.profile.name);
  }
  if (tr.samples.empty()) {
    fmt::print(stderr, "error: nothing to plot\n");
    return kExitProgram;
  }
  return write_and_commit(*files[0], draw(tr, title)) ? kExitOk : kExitUsage;
}

}  // namespace

void add_plot_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<PlotOptions>();
  CLI::App* cmd = app.add_subcommand(
      "plot", "Draw a run's toolpath and velocity profile as SVG (from a program or a trace)");
  cmd->add_option("file", opts->session.file, "G-code program to run in virtual time");
  cmd->add_option("--trace", opts->trace, "Trace CSV written by `opencnc run --trace`");
  cmd->add_option("--machine,-m", opts->session.machine, "Machine profile (with a program)");
  cmd->add_option("--set", opts->session.sets, "Override a profile key (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("-o,--output", opts->out, "SVG file to write")->required();
  cmd->callback([opts, &registry] { registry.set_result(plot(*opts)); });
}

}  // namespace opencnc::cli
