// SPDX-License-Identifier: GPL-3.0-or-later
// Summary of a scanned program: counts, lengths, bounding boxes, time, tools and offsets.
#include "gcode_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <set>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/canon/tee_sink.hpp"
#include "opencnc/gcode/interpreter.hpp"

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

// Axis indices (first, second, normal) of an arc plane among X, Y, Z.
void plane_axes(canon::Plane p, int& a, int& b, int& n) {
  switch (p) {
    case canon::Plane::YZ: a = 1, b = 2, n = 0; return;
    case canon::Plane::XZ: a = 2, b = 0, n = 1; return;
    default: a = 0, b = 1, n = 2; return;
  }
}

// Swept angle (radians, signed: + counterclockwise) from angle `a0` to `a1` with LinuxCNC's
// turn count (|turns| - 1 extra full circles).
double swept(double a0, double a1, int turns) {
  const double two_pi = 2 * std::numbers::pi;
  if (turns > 0) {
    double d = a1 - a0;
    while (d <= 0) d += two_pi;
    return d + (turns - 1) * two_pi;
  }
  double d = a1 - a0;
  while (d >= 0) d -= two_pi;
  return d + (turns + 1) * two_pi;
}

// Adds an arc (in XYZ of the plane axes) to `box`; returns its length.
double arc_extent(const double start[3], const double end[3], const double center[3], canon::Plane plane, int turns,
                  Box& box) {
  int a, b, n;
  plane_axes(plane, a, b, n);
  // An arc whose end is off its start circle runs as a spiral between the two radii: the
  // larger one bounds its extremes.
  const double r = std::max(std::hypot(start[a] - center[a], start[b] - center[b]),
                            std::hypot(end[a] - center[a], end[b] - center[b]));
  const double a0 = std::atan2(start[b] - center[b], start[a] - center[a]);
  const double a1 = std::atan2(end[b] - center[b], end[a] - center[a]);
  const double sweep = swept(a0, a1, turns);
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
  bool untimed = false;   // per-revolution feeds: no time without a spindle model
  Box box;
};

// Counts, lengths, machine extents and feed time of a program's moves, taken as they are
// appended (while they are still in the cache) instead of in a second pass over a program
// of maybe a million moves. Moves are measured in order, one at a time.
class MoveMeter {
 public:
  explicit MoveMeter(const canon::Program& prog) : prog_(prog) {}
  /// Measures the moves appended since the last call.
  void catch_up() {
    for (; next_ < prog_.size(); ++next_) measure(next_);
  }
  const Totals& totals() const { return t_; }

 private:
  void measure(canon::SegmentId id) {
    if (id == 0) {
      const Pose& start = prog_.start();
      for (int i = 0; i < 3; ++i) last_[i] = start[i];
      t_.box.add(last_[0], last_[1], last_[2]);
    }
    const double* s = last_;
    const canon::Move& m = prog_.move(id);
    const double e[3] = {prog_.end_coord(id, Axis::X), prog_.end_coord(id, Axis::Y), prog_.end_coord(id, Axis::Z)};
    double len;
    if (m.kind == canon::MoveKind::Arc) {
      const canon::ArcGeometry& g = prog_.arc(id);
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
    const double f = prog_.feed(id);
    if (m.flags & canon::kInverseTime) t_.feed_time_min += f > 0 ? 1.0 / f : 0;
    else if (m.flags & canon::kPerRevolution) t_.untimed = true;
    else if (f > 0) t_.feed_time_min += len / f;
  }

  const canon::Program& prog_;
  canon::SegmentId next_ = 0;
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
    int a, b, n;
    plane_axes(arc.plane, a, b, n);
    double s[3] = {pos_[0], pos_[1], pos_[2]}, e[3] = {arc.end[0], arc.end[1], arc.end[2]}, c[3];
    c[a] = arc.first_center;
    c[b] = arc.second_center;
    c[n] = s[n];
    arc_extent(s, e, c, arc.plane, arc.rotation, box_);
    for (int i = 0; i < 3; ++i) pos_[i] = arc.end[i];
    meter_.catch_up();
  }
  void change_tool(int index) override { tool_changes.insert(index); }
  void change_tool_number(int index) override { tool_changes.insert(index); }
  void select_tool(int tool) override { tools_selected.insert(tool); }
  void set_g5x_offset(int index, const Pose&) override { systems.insert(index); }
  void use_tool_length_offset(const Pose&) override { ++tool_offsets; }

  const Box& box() const { return box_; }
  std::set<int> tool_changes, tools_selected, systems;
  int tool_offsets = 0;

 private:
  void move(const Pose& end) {
    box_.add(end[0], end[1], end[2]);
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

}  // namespace

int run_scan(const std::string& file, const gcode::Options& options, bool json, double rapid_rate_mm_min) {
  gcode::Interpreter interp(options);
  if (!interp.open(file)) {
    for (const auto& d : interp.diagnostics().items()) std::fprintf(stderr, "%s [%s]\n", d.format().c_str(), d.code.c_str());
    return kExitUsage;
  }
  canon::ProgramBuilder builder(options.axes);
  builder.program().set_sources(interp.sources());
  const canon::Program& prog = builder.program();
  MoveMeter meter(prog);
  WorkWatcher watch(meter);
  canon::TeeSink tee(builder, watch);   // the builder first: the watcher's meter reads its moves
  const gcode::RunStatus status = interp.run(tee);
  meter.catch_up();   // moves of calls the watcher does not follow (probes, taps, splines)
  const Totals& t = meter.totals();
  const gcode::InterpState st = interp.state();
  const double rapid_min = rapid_rate_mm_min > 0 ? t.rapid_length / rapid_rate_mm_min : 0.0;
  const auto& diags = interp.diagnostics();
  if (json) {
    nlohmann::json j;
    j["file"] = file;
    j["ok"] = status != gcode::RunStatus::Error;
    j["blocks"] = st.blocks_executed;
    j["segments"] = {{"feed", t.feeds}, {"rapid", t.rapids}, {"arcs", t.arcs}};
    j["length_mm"] = {{"feed", t.feed_length}, {"rapid", t.rapid_length}};
    j["bounding_box"] = {{"machine_mm", box_json(t.box)}, {"work", box_json(watch.box())}};
    j["time_s"] = {{"feed", t.feed_time_min * 60.0}, {"rapid", rapid_rate_mm_min > 0 ? nlohmann::json(rapid_min * 60.0) : nullptr},
                   {"per_revolution_untimed", t.untimed}};
    j["tools"] = {{"selected", watch.tools_selected}, {"changed_index", watch.tool_changes}};
    j["coordinate_systems"] = watch.systems;
    j["tool_length_offsets"] = watch.tool_offsets;
    j["program_memory_bytes"] = prog.memory_bytes();
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
                t.untimed ? " (feed-per-revolution moves not timed)" : "");
    if (rapid_rate_mm_min > 0) std::printf(" + %.1f s rapid", rapid_min * 60.0);
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
  return status == gcode::RunStatus::Error ? kExitProgram : kExitOk;
}

}  // namespace opencnc::cli
