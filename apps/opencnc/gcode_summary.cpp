// SPDX-License-Identifier: GPL-3.0-or-later
// Summary of a scanned program: counts, lengths, bounding boxes, time, tools and offsets.
#include "gcode_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <set>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/canon/tee_sink.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "progress.hpp"

namespace opencnc::cli {

namespace {

struct Box {
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                  -std::numeric_limits<double>::infinity()};
  void add(double x, double y, double z) {   // (written out: it runs twice per move)
    lo[0] = std::min(lo[0], x), hi[0] = std::max(hi[0], x);
    lo[1] = std::min(lo[1], y), hi[1] = std::max(hi[1], y);
    lo[2] = std::min(lo[2], z), hi[2] = std::max(hi[2], z);
  }
  bool empty() const { return !(lo[0] <= hi[0]); }
};

// Adds an arc (in XYZ of the plane axes) to `box`; returns its length.
double arc_extent(const double start[3], const double end[3], const Vec3& center, canon::Plane plane,
                  int turns, Box& box) {
  // The plane's axes within its triple (the centre is given in it).
  const canon::PlaneAxes axes = canon::plane_axes(plane);
  const int base = canon::plane_base(plane);
  const int a = axes.first - base, b = axes.second - base, n = axes.normal - base;
  // An arc whose end is off its start circle runs as a spiral between the two radii: the
  // larger one bounds its extremes.
  const double r = std::max(std::hypot(start[a] - center[a], start[b] - center[b]),
                            std::hypot(end[a] - center[a], end[b] - center[b]));
  const double a0 = std::atan2(start[b] - center[b], start[a] - center[a]);
  const double a1 = std::atan2(end[b] - center[b], end[a] - center[a]);
  const double sweep = canon::arc_sweep(std::remainder(a1 - a0, 2 * std::numbers::pi), turns);
  box.add(start[0], start[1], start[2]);
  box.add(end[0], end[1], end[2]);
  for (int q = 0; q < 4; ++q) {   // the four axis extremes of the circle, if swept
    const double ang = q * std::numbers::pi / 2;
    double rel = sweep > 0 ? ang - a0 : a0 - ang;
    rel = std::fmod(rel, 2 * std::numbers::pi);
    if (rel < 0) rel += 2 * std::numbers::pi;
    if (rel <= std::fabs(sweep)) {
      const double frac = rel / std::fabs(sweep);
      double p[3];
      p[a] = center[a] + r * std::cos(ang);
      p[b] = center[b] + r * std::sin(ang);
      p[n] = start[n] + frac * (end[n] - start[n]);
      box.add(p[0], p[1], p[2]);
    }
  }
  return std::hypot(r * sweep, end[n] - start[n]);
}

struct Totals {
  std::size_t feeds = 0, rapids = 0, arcs = 0;
  double feed_length = 0, rapid_length = 0;
  double feed_time_min = 0;
  bool untimed = false;    // per-revolution moves without a spindle speed (or under G96): not timed
  double slowest_min = 0;  // the feed move that takes longest, and where it is
  std::uint32_t slowest_file = 0, slowest_line = 0;
  Box box;
  std::optional<Diagnostic> out_of_reach;  // the first move no machine could make
};

/// Farthest a move may end from the machine origin (mm): beyond it lengths and times stop
/// meaning anything (10**300 overflows them to inf) and no machine travels that far.
constexpr double kMaxReachMm = 1e9;

bool within_reach(const double p[3]) {
  return std::fabs(p[0]) <= kMaxReachMm && std::fabs(p[1]) <= kMaxReachMm && std::fabs(p[2]) <= kMaxReachMm;
}

/// Moves the builder keeps before the meter has it start over: the summary needs each move
/// once, so a program of any length (a loop that never ends) scans in bounded memory.
constexpr std::size_t kKeptMoves = std::size_t{1} << 16;

// Counts, lengths, machine extents and feed time of a program's moves, taken as they are
// appended (while they are still in the cache) instead of in a second pass. Moves are measured
// in order, one at a time; every kKeptMoves the builder drops the moves measured.
class MoveMeter {
 public:
  explicit MoveMeter(canon::ProgramBuilder& builder) : builder_(builder) {}
  /// Measures the moves appended since the last call.
  void catch_up() {
    const canon::Program& prog = builder_.program();
    for (; next_ < prog.size(); ++next_) {
      spindle_before(prog, next_);
      measure(prog, next_);
    }
    if (next_ >= kKeptMoves) {
      spindle_before(prog, next_);
      builder_.restart();
      next_ = 0;
      next_action_ = 0;
    }
  }
  const Totals& totals() const { return t_; }

 private:
  // The spindle's speed and a synchronised run's pitch as they stand before move `id`: a move per
  // revolution (G95, G33, G76, G33.1) takes its length over (distance per turn × turns per minute).
  void spindle_before(const canon::Program& prog, canon::SegmentId id) {
    for (; next_action_ < prog.action_count() && prog.action(next_action_).before_move <= id;
         ++next_action_) {
      const canon::Action& a = prog.action(next_action_);
      if (a.kind == canon::ActionKind::SpindleSpeed) rpm_ = a.index2 == 0 ? a.value : 0;  // G96: varies
      if (a.kind == canon::ActionKind::SpeedFeedSyncStart) per_turn_mm_ = a.value;
      if (a.kind == canon::ActionKind::SpeedFeedSyncStop) per_turn_mm_ = 0;
    }
  }
  /// Minutes of a move of `len` mm at `per_turn` mm per spindle turn; 0 (and untimed) when the
  /// speed is not known.
  double per_turn_minutes(double len, double per_turn) {
    if (rpm_ > 0 && per_turn > 0) return len / (per_turn * rpm_);
    t_.untimed = true;
    return 0;
  }

  void measure(const canon::Program& prog, canon::SegmentId id) {
    if (id == 0) {  // (after a restart the start is where the last move measured ended)
      const Pose& start = prog.start();
      for (int i = 0; i < 3; ++i) last_[i] = start[i];
      t_.box.add(last_[0], last_[1], last_[2]);
    }
    const double* s = last_;
    const canon::Move& m = prog.move(id);
    const double e[3] = {prog.end_coord(id, Axis::X), prog.end_coord(id, Axis::Y),
                         prog.end_coord(id, Axis::Z)};
    if (!within_reach(e)) {
      out_of_reach(prog, id, e);
      return;
    }
    double len;
    if (m.kind == canon::MoveKind::Arc) {
      const canon::ArcGeometry& g = prog.arc(id);
      len = arc_extent(s, e, g.center, g.plane, g.turns, t_.box);
      ++t_.arcs;
    } else {
      len = std::sqrt((e[0] - s[0]) * (e[0] - s[0]) + (e[1] - s[1]) * (e[1] - s[1]) + (e[2] - s[2]) * (e[2] - s[2]));
      t_.box.add(e[0], e[1], e[2]);
    }
    for (int i = 0; i < 3; ++i) last_[i] = e[i];   // (X, Y, Z only: a whole pose copied costs more)
    if (m.kind == canon::MoveKind::Traverse) {
      ++t_.rapids;
      t_.rapid_length += len;
      return;
    }
    ++t_.feeds;
    t_.feed_length += len;
    const double f = prog.feed(id);
    double minutes = 0;
    if (m.flags & canon::kInverseTime)
      minutes = f > 0 ? 1.0 / f : 0;
    else if (m.flags & canon::kSpindleSynced)
      minutes = per_turn_minutes(len, per_turn_mm_);
    else if (m.flags & canon::kPerRevolution)
      minutes = per_turn_minutes(len, f);
    else if (f > 0)
      minutes = len / f;
    t_.feed_time_min += minutes;
    if (minutes > t_.slowest_min) {
      t_.slowest_min = minutes;
      t_.slowest_file = prog.file_of(id);
      t_.slowest_line = m.line;
    }
  }

  // A move beyond any machine's reach is left out of the totals and reported (the first one).
  void out_of_reach(const canon::Program& prog, canon::SegmentId id, const double e[3]) {
    if (t_.out_of_reach) return;
    const int axis = !(std::fabs(e[0]) <= kMaxReachMm) ? 0 : !(std::fabs(e[1]) <= kMaxReachMm) ? 1 : 2;
    const std::uint32_t file = prog.file_of(id);
    t_.out_of_reach =
        Diagnostic{Severity::Error,
                   file < prog.sources().file_count() ? prog.sources().file(file) : std::string(),
                   prog.move(id).line,
                   0,
                   fmt::format("this move ends at {} {:g} mm, beyond any machine's reach (more than "
                               "{:g} mm from the origin): lengths and times would mean nothing",
                               kAxisLetters[static_cast<std::size_t>(axis)], e[axis], kMaxReachMm),
                   "scan.out-of-reach"};
  }

  canon::ProgramBuilder& builder_;
  canon::SegmentId next_ = 0;
  std::size_t next_action_ = 0;  // the first action not yet seen
  double rpm_ = 0;               // the spindle speed in force (0: none, or G96)
  double per_turn_mm_ = 0;       // the pitch of the synchronised run in force (0: none)
  double last_[3] = {0, 0, 0};   // X, Y, Z where the last move measured ended
  Totals t_;
};

// Watches the canonical stream in work coordinates (extents, tools, coordinate systems); after
// each motion, which the builder ahead of it in the tee has just appended, it has `meter`
// measure the new moves.
class WorkWatcher final : public canon::Sink {
 public:
  explicit WorkWatcher(MoveMeter& meter) : meter_(meter) {}
  void straight_traverse(canon::SegmentId, const Pose& end) override { move(end); }
  void straight_feed(canon::SegmentId, const Pose& end) override { move(end); }
  void arc_feed(canon::SegmentId, const canon::ArcFeed& arc) override {
    const canon::PlaneAxes axes = canon::plane_axes(arc.plane);
    const int base = canon::plane_base(arc.plane);
    double s[3] = {pos_[0], pos_[1], pos_[2]}, e[3] = {arc.end[0], arc.end[1], arc.end[2]};
    Vec3 c;
    c[axes.first - base] = arc.first_center;
    c[axes.second - base] = arc.second_center;
    c[axes.normal - base] = s[axes.normal - base];
    if (within_reach(s) && within_reach(e) && within_reach(c.v.data()))
      arc_extent(s, e, c, arc.plane, arc.rotation, box_);
    for (int i = 0; i < 3; ++i) pos_[i] = arc.end[i];
    meter_.catch_up();
  }
  void change_tool(int index) override { tool_changes.insert(index); }
  void change_tool_number(int index) override { tool_changes.insert(index); }
  void select_tool(int tool) override { tools_selected.insert(tool); }
  void set_g5x_offset(int index, const Pose&) override { systems.insert(index); }
  void use_tool_length_offset(const Pose&) override { ++tool_offsets; }
  void dwell(double seconds) override { dwell_s += seconds; }

  const Box& box() const { return box_; }
  std::set<int> tool_changes, tools_selected, systems;
  int tool_offsets = 0;
  double dwell_s = 0;

 private:
  void move(const Pose& end) {
    // (a move beyond any machine's reach is reported by the meter, and would swamp the box)
    if (within_reach(end.v.data())) box_.add(end[0], end[1], end[2]);
    for (int i = 0; i < 3; ++i) pos_[i] = end[i];
    meter_.catch_up();
  }
  MoveMeter& meter_;
  double pos_[3] = {0, 0, 0};   // X, Y, Z of the last motion's end (work coordinates)
  Box box_;
};

nlohmann::json box_json(const Box& b) {
  if (b.empty()) return nullptr;
  return {{"min", {b.lo[0], b.lo[1], b.lo[2]}}, {"max", {b.hi[0], b.hi[1], b.hi[2]}}};
}

void print_box(const char* name, const Box& b) {
  if (b.empty()) {
    std::printf("%-22s (no motion)\n", name);
    return;
  }
  // (+ 0.0 turns a negative zero into zero: "-0.0000" would puzzle the reader)
  std::printf("%-22s X %.4f .. %.4f  Y %.4f .. %.4f  Z %.4f .. %.4f\n", name, b.lo[0] + 0.0, b.hi[0] + 0.0,
              b.lo[1] + 0.0, b.hi[1] + 0.0, b.lo[2] + 0.0, b.hi[2] + 0.0);
}

/// One scan of a program: the interpreter into the builder (which drops what the meter has
/// measured) and the watcher, through a tee.
class ProgramScan {
 public:
  explicit ProgramScan(const gcode::Options& options)
      : interp_(options), builder_(options.axes), meter_(builder_), watch_(meter_), tee_(builder_, watch_) {}
  /// False (with the diagnostic in the interpreter's) if the file cannot be opened.
  bool open(const std::string& file) {
    if (!interp_.open(file)) return false;
    builder_.program().set_sources(interp_.sources());
    return true;
  }
  gcode::RunStatus run(InterpreterProgress& progress) {
    const gcode::RunStatus status = progress.run(interp_, tee_);
    meter_.catch_up();  // moves of calls the watcher does not follow (probes, taps, splines)
    return status;
  }
  const Totals& totals() const { return meter_.totals(); }
  const WorkWatcher& watcher() const { return watch_; }
  const gcode::Interpreter& interpreter() const { return interp_; }
  /// "file:line" of a move.
  std::string where(std::uint32_t file, std::uint32_t line) const {
    const canon::SourceMap& sources = *interp_.sources();
    return fmt::format("{}:{}", file < sources.file_count() ? sources.file(file) : std::string("?"), line);
  }

 private:
  gcode::Interpreter interp_;
  canon::ProgramBuilder builder_;
  MoveMeter meter_;
  WorkWatcher watch_;
  canon::TeeSink tee_;  // the builder first: the watcher's meter reads its moves
};

}  // namespace

int run_scan(const std::string& file, const gcode::Options& options, const ScanOutput& out) {
  ProgramScan scan(options);
  if (!scan.open(file)) {
    for (const auto& d : scan.interpreter().diagnostics().items())
      std::fprintf(stderr, "%s [%s]\n", d.format().c_str(), d.code.c_str());
    return kExitUsage;
  }
  InterpreterProgress progress("scan " + file, out.progress);
  const gcode::RunStatus status = scan.run(progress);
  const WorkWatcher& watch = scan.watcher();
  const Totals& t = scan.totals();
  const gcode::InterpState st = scan.interpreter().state();
  const double rapid_rate_mm_min = out.rapid_rate_mm_min;
  const double rapid_min = rapid_rate_mm_min > 0 ? t.rapid_length / rapid_rate_mm_min : 0.0;
  Diagnostics diags = scan.interpreter().diagnostics();
  if (t.out_of_reach) diags.add(*t.out_of_reach);
  const bool ok = status != gcode::RunStatus::Error && !t.out_of_reach;
  if (out.json) {
    nlohmann::json j;
    j["file"] = file;
    j["ok"] = ok;
    j["blocks"] = st.blocks_executed;
    j["segments"] = {{"feed", t.feeds}, {"rapid", t.rapids}, {"arcs", t.arcs}};
    j["length_mm"] = {{"feed", t.feed_length}, {"rapid", t.rapid_length}};
    j["bounding_box"] = {{"machine_mm", box_json(t.box)}, {"work", box_json(watch.box())}};
    j["time_s"] = {{"feed", t.feed_time_min * 60.0},
                   {"rapid", rapid_rate_mm_min > 0 ? nlohmann::json(rapid_min * 60.0) : nullptr},
                   {"dwell", watch.dwell_s},
                   {"per_revolution_untimed", t.untimed}};
    j["tools"] = {{"selected", watch.tools_selected}, {"changed_index", watch.tool_changes}};
    j["coordinate_systems"] = watch.systems;
    j["tool_length_offsets"] = watch.tool_offsets;
    nlohmann::json d = nlohmann::json::array();
    for (const auto& x : diags.items()) d.push_back({{"text", x.format()}, {"code", x.code}});
    j["diagnostics"] = d;
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("%-22s %s\n", "file", file.c_str());
    std::printf("%-22s %llu\n", "blocks executed", static_cast<unsigned long long>(st.blocks_executed));
    std::printf("%-22s %zu feed (%zu arcs), %zu rapid\n", "segments", t.feeds, t.arcs, t.rapids);
    std::printf("%-22s feed %.3f mm, rapid %.3f mm\n", "path length", t.feed_length, t.rapid_length);
    print_box("extent (machine, mm)", t.box);
    print_box("extent (work)", watch.box());
    std::printf("%-22s %.1f s at programmed feeds%s", "time", t.feed_time_min * 60.0,
                t.untimed ? " (some moves per spindle turn without a known speed not timed)" : "");
    if (rapid_rate_mm_min > 0) std::printf(" + %.1f s rapid", rapid_min * 60.0);
    if (watch.dwell_s > 0) std::printf(" + %.1f s dwell", watch.dwell_s);
    std::printf("\n");
    std::printf("%-22s", "tools selected");
    for (int x : watch.tools_selected) std::printf(" T%d", x);
    std::printf("\n%-22s", "coordinate systems");
    for (int x : watch.systems) {
      if (x <= 6) std::printf(" G%d", 53 + x);
      else std::printf(" G59.%d", x - 6);
    }
    std::printf("\n%-22s %d\n", "tool length offsets", watch.tool_offsets);
    for (const auto& x : diags.items()) std::printf("%s [%s]\n", x.format().c_str(), x.code.c_str());
  }
  return ok ? kExitOk : kExitProgram;
}

TimeEstimate estimate_machining_time(const std::string& file, const config::MachineProfile& profile) {
  TimeEstimate e;
  // The options the run's own source gives this file (dialect comment, modules, tool table).
  Diagnostics diags;
  const std::unique_ptr<controller::MachineSetup> machine = features::machine_setup(profile, diags);
  if (!machine) return e;
  const auto& source = machine->source();
  ProgramScan scan(source->options_for(file, {}));
  if (!scan.open(file)) return e;
  InterpreterProgress progress("checking the machining time of " + file, false);
  e.complete = scan.run(progress) != gcode::RunStatus::Error && !scan.totals().out_of_reach;
  double rapid_mm_s = 0;
  for (const config::AxisProfile& a : profile.axes) {
    if (a.axis == Axis::X || a.axis == Axis::Y || a.axis == Axis::Z)
      rapid_mm_s += a.max_velocity * a.max_velocity;
  }
  rapid_mm_s = std::sqrt(rapid_mm_s);
  const Totals& t = scan.totals();
  e.feed_s = 60 * t.feed_time_min;
  e.rapid_s = rapid_mm_s > 0 ? t.rapid_length / rapid_mm_s : 0;
  e.dwell_s = scan.watcher().dwell_s;
  e.slowest_move_s = 60 * t.slowest_min;
  if (t.slowest_min > 0) e.slowest_move_at = scan.where(t.slowest_file, t.slowest_line);
  return e;
}

}  // namespace opencnc::cli
