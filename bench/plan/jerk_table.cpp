// SPDX-License-Identifier: GPL-3.0-or-later
// jerk_table — per G-code program: LinuxCNC 2.9's motion time (from a file the harness wrote),
// opencnc's without a jerk limit, with J = 1e5 and J = 2e4 mm/s³ (or --jerks), the peak jerk the
// trace used, its contour error (both ways: the path from the programmed moves and the moves' end
// points from the path), its limit violations and how much faster than real time the
// planner and the tick ran (docs/performance.md, "Jerk-limited motion").
//
//   jerk_table [--lcnc TIMES.tsv] [--jerks 0,1e5,2e4] [--cpu-limit S] [--lookahead N]
//              [--tol P] [--tool-table FILE] [--no-check] [--trace CSV] FILES...
//
// The machine is configs/mill-3axis.toml's: X Y Z at 100 mm/s and 1000 mm/s², 1 ms, 200 moves of
// look-ahead; the jerk J on all three axes. Before each program the interpreter runs the MDI line
// `G64 P<tol>` (default 0.01), as the LinuxCNC harness does with its --tol: a program that sets no
// path mode of its own runs under that tolerance in both (G64 without P stays unbounded). Each program is
// interpreted once by opencnc's interpreter into a canon::Program, then planned and run in virtual time
// (analysis::simulate) twice per J: without the trace checker for the CPU time (planner + tick,
// one thread), then with it for the metrics. A run whose CPU time passes --cpu-limit (default 120 s)
// is aborted and reported as not finished, with the motion time it reached. --trace writes the
// first J's commanded trajectory of the (one) program, one line a period: "time,line,x,y,z,v"
// (the columns of the LinuxCNC harness's --trace, to compare the feed along the program).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "opencnc/analysis/simulate.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

using namespace opencnc;

namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string dir_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

/// LinuxCNC's times by path: lines "PATH<TAB>SECONDS" (FAIL or empty: not measured).
std::map<std::string, double> read_lcnc_times(const std::string& file) {
  std::map<std::string, double> times;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    const auto tab = line.find('\t');
    if (tab == std::string::npos) continue;
    char* end = nullptr;
    const std::string value = line.substr(tab + 1);
    const double t = std::strtod(value.c_str(), &end);
    if (end != value.c_str() && t > 0) times[line.substr(0, tab)] = t;
  }
  return times;
}

struct Args {
  std::string lcnc;
  std::vector<double> jerks{0, 1e5, 2e4};
  double cpu_limit_s = 120;
  std::size_t lookahead = 200;
  double tolerance = 0.01;
  std::string tool_table;
  bool check = true;
  std::string trace;        ///< CSV of the first J's trajectory
  double normal_share = 0;  ///< 0: the planner's default
  std::vector<std::string> files;
};

bool parse(int argc, char** argv, Args& a) {
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    const auto value = [&]() -> std::string { return i + 1 < argc ? argv[++i] : std::string(); };
    if (s == "--lcnc") {
      a.lcnc = value();
    } else if (s == "--jerks") {
      a.jerks.clear();
      std::stringstream list(value());
      std::string item;
      while (std::getline(list, item, ',')) a.jerks.push_back(std::strtod(item.c_str(), nullptr));
    } else if (s == "--cpu-limit") {
      a.cpu_limit_s = std::strtod(value().c_str(), nullptr);
    } else if (s == "--lookahead") {
      a.lookahead = static_cast<std::size_t>(std::strtoul(value().c_str(), nullptr, 10));
    } else if (s == "--tol") {
      a.tolerance = std::strtod(value().c_str(), nullptr);
    } else if (s == "--tool-table") {
      a.tool_table = value();
    } else if (s == "--normal-share") {
      a.normal_share = std::strtod(value().c_str(), nullptr);
    } else if (s == "--trace") {
      a.trace = value();
    } else if (s == "--no-check") {
      a.check = false;
    } else if (s == "-h" || s == "--help") {
      return false;
    } else {
      a.files.push_back(s);
    }
  }
  return !a.files.empty() && !a.jerks.empty();
}

/// The program as opencnc's interpreter reads it (LinuxCNC dialect, XYZABC, mm), or nothing.
std::optional<canon::Program> interpret(const std::string& path, const Args& args) {
  gcode::Options o;
  o.extensions = gcode::standard_extensions(o.dialect);
  o.subroutine_path = {dir_name(path)};
  if (!args.tool_table.empty()) {
    Diagnostics d;
    auto table = tools::ToolTable::load(args.tool_table, d);
    if (table) o.tool_table = std::make_shared<tools::ToolTable>(std::move(*table));
  }
  gcode::Interpreter interp(o);
  canon::ProgramBuilder builder(kXyzabc);
  builder.program().set_sources(interp.sources());  // diagnostics name the file and line
  // The harness's `--tol`: an MDI G64 P before the program (LinuxCNC's G64 P also sets Q = P).
  const std::string mdi = args.tolerance > 0 ? fmt::format("G64 P{:g}", args.tolerance) : std::string("G64");
  if (interp.execute_mdi(mdi, builder) == gcode::RunStatus::Error || !interp.open(path)) return std::nullopt;
  if (interp.run(builder) == gcode::RunStatus::Error) {
    for (const auto& d : interp.diagnostics().items()) {
      if (d.severity == Severity::Error) fmt::print(stderr, "{}\n", d.format());
    }
    return std::nullopt;
  }
  return builder.take();
}

/// Largest G64 P the program sets (mm); 0 when it sets none (no bound).
double largest_tolerance(const canon::Program& p) {
  double tol = 0;
  for (std::size_t i = 0; i < p.action_count(); ++i) {
    const canon::Action& a = p.action(i);
    if (a.kind == canon::ActionKind::MotionControl) tol = std::max(tol, a.value);
  }
  return tol;
}

struct Run {
  bool finished = false;
  double motion_s = 0;
  double cpu_s = 0;
  double peak_jerk_share = 0;  ///< largest axis jerk / its limit (0 without a limit)
  double contour_mm = 0;
  double corner_mm = 0;  ///< largest distance from a programmed end point to the path
  std::uint64_t violations = 0;
  std::uint64_t ticks = 0;  ///< virtual time simulated, in servo periods
  int state = 0;            ///< traj::RunState at the end
};

Run run(const canon::Program& program, double jerk, const Args& args) {
  const plan::MachineLimits limits =
      plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, jerk);
  analysis::SimulationOptions opt;
  opt.planner.lookahead_moves = args.lookahead;
  if (args.normal_share > 0) opt.planner.normal_accel_share = args.normal_share;
  opt.max_time_s = 48 * 3600;
  Run r;
  std::FILE* trace = nullptr;
  if (!args.trace.empty() && jerk == args.jerks.front()) trace = std::fopen(args.trace.c_str(), "w");
  if (trace != nullptr) {
    opt.observe = [trace](std::uint64_t n, const traj::TickOutput& o) {
      fmt::print(trace, "{:.3f},{},{:.6f},{:.6f},{:.6f},{:.4f}\n", 1e-3 * static_cast<double>(n), o.line,
                 o.position[0], o.position[1], o.position[2], o.path_velocity);
    };
  }
  for (int pass = 0; pass < (args.check ? 2 : 1); ++pass) {
    opt.check = pass == 1;
    const double c0 = cpu_seconds();
    // A run that plans slower than the limit allows is stopped (an abort on the path).
    opt.inputs = [&](std::uint64_t n, const traj::TickOutput&, traj::TickInput& in) {
      if (n % 4096 == 0 && cpu_seconds() - c0 > args.cpu_limit_s) in.abort = true;
    };
    const analysis::SimulationResult s = analysis::simulate(program, limits, opt);
    if (trace != nullptr) {
      std::fclose(trace);
      trace = nullptr;
      opt.observe = nullptr;
    }
    if (pass == 0) {
      r.cpu_s = cpu_seconds() - c0;
      r.finished = s.finished;
      r.motion_s = s.motion_time_s;
      r.ticks = s.ticks;
      r.state = static_cast<int>(s.state);
      if (!s.finished) return r;
      continue;
    }
    if (s.report.limit_violations > 0) fmt::print(stderr, "J {:g}: {}\n", jerk, s.report.summary());
    r.contour_mm = s.report.max_contour_error_mm;
    r.corner_mm = s.report.max_corner_miss_mm;
    r.violations = s.report.limit_violations;
    if (jerk > 0) {
      for (const analysis::AxisStats& a : s.report.axes)
        r.peak_jerk_share = std::max(r.peak_jerk_share, a.max_jerk / jerk);
    }
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parse(argc, argv, args)) {
    std::fprintf(stderr,
                 "usage: jerk_table [--lcnc TIMES.tsv] [--jerks 0,1e5,2e4] [--cpu-limit S] [--lookahead N] "
                 "[--tol P] [--tool-table FILE] [--no-check] [--trace CSV] FILES...\n");
    return 2;
  }
  const std::map<std::string, double> lcnc =
      args.lcnc.empty() ? std::map<std::string, double>{} : read_lcnc_times(args.lcnc);
  std::string head = "| program | moves | G64 P [mm] | LinuxCNC [s] |";
  std::string rule = "|---|---:|---:|---:|";
  for (double j : args.jerks) {
    const std::string name = j > 0 ? fmt::format("J {:g}", j) : std::string("no jerk");
    head += fmt::format(" {} [s] | {} ratio |", name, j > 0 ? name : std::string("vs LinuxCNC"));
    rule += "---:|---:|";
    if (j > 0) {
      head += fmt::format(" {} peak jerk |", name);
      rule += "---:|";
    }
  }
  head += " contour [mm] | corner miss [mm] | violations | × real time (slowest) |";
  rule += "---:|---:|---:|---:|";
  fmt::print("{}\n{}\n", head, rule);
  std::fflush(stdout);
  for (const std::string& file : args.files) {
    const std::optional<canon::Program> program = interpret(file, args);
    const std::string name = base_name(file);
    if (!program) {
      fmt::print("| {} | interpreter error |\n", name);
      continue;
    }
    const auto l = lcnc.find(file);  // by path: programs of the same name may differ
    std::string row =
        fmt::format("| {} | {} | {} | {} |", name, program->size(),
                    largest_tolerance(*program) > 0 ? fmt::format("{:g}", largest_tolerance(*program)) : "—",
                    l != lcnc.end() ? fmt::format("{:.3f}", l->second) : "—");
    double base = 0, contour = 0, corner = 0, slowest = 1e300;
    std::uint64_t violations = 0;
    for (double j : args.jerks) {
      const Run r = run(*program, j, args);
      if (!r.finished) {
        row += fmt::format(" DNF ({:.1f} s of motion, {:.1f} s simulated, state {}, {:.0f} s CPU) | — |",
                           r.motion_s, 1e-3 * static_cast<double>(r.ticks), r.state, r.cpu_s);
        if (j > 0) row += " — |";
        slowest = std::min(slowest, r.motion_s / r.cpu_s);
        continue;
      }
      if (j <= 0) base = r.motion_s;
      const double ratio =
          j > 0 ? (base > 0 ? r.motion_s / base : 0) : (l != lcnc.end() ? r.motion_s / l->second : 0);
      row += fmt::format(" {:.3f} | {} |", r.motion_s, ratio > 0 ? fmt::format("{:.3f}", ratio) : "—");
      if (j > 0) row += fmt::format(" {:.0f} % |", 100 * r.peak_jerk_share);
      contour = std::max(contour, r.contour_mm);
      corner = std::max(corner, r.corner_mm);
      violations += r.violations;
      slowest = std::min(slowest, r.motion_s / r.cpu_s);
    }
    row += fmt::format(" {:.4f} | {:.4f} | {} | {:.0f} |", contour, corner,
                       args.check ? fmt::format("{}", violations) : "—", slowest);
    fmt::print("{}\n", row);
    std::fflush(stdout);
  }
  return 0;
}
