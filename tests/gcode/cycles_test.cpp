// SPDX-License-Identifier: GPL-3.0-or-later
// Canned cycles, threading and probing: geometric properties on seeded random programs,
// behaviour rs274 cannot show (UVW planes, execute-mode probing), replay and the program
// builder's view of the moves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gcode_test_util.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/gcode/canned_cycles.hpp"
#include "opencnc/gcode/probing.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "opencnc/gcode/threading.hpp"

using namespace opencnc;
using namespace opencnc::gcode;

namespace {

// Every canonical call that matters here, in order.
struct Event {
  char kind;         // 't' traverse, 'f' feed, 'p' probe, 'r' rigid tap, 's' sync start, 'x' sync stop,
                     // 'd' dwell, 'm' motion-control mode, 'c' spindle cw, 'w' ccw, 'o' stop, 'h' program stop,
                     // 'v'/'e' feed override off/on, 'V'/'E' spindle override off/on
  Pose end{};
  double value = 0;
};

class Events : public canon::Sink {
 public:
  void straight_traverse(canon::SegmentId, const Pose& end) override { add('t', end); }
  void straight_feed(canon::SegmentId, const Pose& end) override { add('f', end); }
  void straight_probe(canon::SegmentId, const Pose& end) override { add('p', end); }
  void rigid_tap(canon::SegmentId, const Pose& end, double scale) override { add('r', end, scale); }
  void start_speed_feed_synch(int, double pitch, bool) override { add('s', {}, pitch); }
  void stop_speed_feed_synch() override { add('x', {}); }
  void dwell(double s) override { add('d', {}, s); }
  void set_motion_control_mode(canon::MotionControl m, double) override { add('m', {}, static_cast<double>(m)); }
  void start_spindle_clockwise(int) override { add('c', {}); }
  void start_spindle_counterclockwise(int) override { add('w', {}); }
  void stop_spindle_turning(int) override { add('o', {}); }
  void program_stop() override { add('h', {}); }
  void disable_feed_override() override { add('v', {}); }
  void enable_feed_override() override { add('e', {}); }
  void disable_speed_override(int) override { add('V', {}); }
  void enable_speed_override(int) override { add('E', {}); }

  std::vector<Event> events;
  std::vector<Event> moves() const {
    std::vector<Event> out;
    std::copy_if(events.begin(), events.end(), std::back_inserter(out), [](const Event& e) { return e.kind == 't' || e.kind == 'f'; });
    return out;
  }

 private:
  void add(char k, const Pose& p, double v = 0) { events.push_back({k, p, v}); }
};

Options with_modules(Mode mode = Mode::Scan) {
  Options o;
  o.mode = mode;
  o.extensions = standard_extensions(Dialect::LinuxCnc);
  return o;
}

struct Outcome {
  RunStatus status;
  Events sink;
  InterpState state;
  std::string error;   // code of the first error
};

Outcome run(const std::string& program, Options options = with_modules()) {
  Outcome r;
  Interpreter interp(options);
  interp.open_text("cycles.ngc", program);
  r.status = interp.run(r.sink);
  r.state = interp.state();
  for (const auto& d : interp.diagnostics().items()) {
    if (d.severity == Severity::Error && r.error.empty()) r.error = d.code;
  }
  return r;
}

std::string num(double v) { return fmt::format("{:.4f}", v); }

// --- canned cycles: properties of random drilling blocks --------------------------------------

struct Plane {
  const char* code;
  int a, b, c;           // in-plane axes and drilling axis (Pose indices)
  char la, lb, lc;
};
constexpr Plane kPlanes[] = {{"G17", 0, 1, 2, 'X', 'Y', 'Z'}, {"G18", 2, 0, 1, 'Z', 'X', 'Y'}, {"G19", 1, 2, 0, 'Y', 'Z', 'X'}};

TEST(CannedCycles, RandomDrillingBlocksStayOnTheHoleAxisAndReachTheBottom) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> coord(-50, 50), up(0.5, 20), depth(0.5, 15), peck(0.3, 4);
  const int cycles[] = {73, 81, 82, 83, 85, 86, 89};
  for (int trial = 0; trial < 300; ++trial) {
    const Plane& pl = kPlanes[rng() % 3];
    const int code = cycles[rng() % 7];
    const bool incremental = rng() % 2;
    const bool old_z = rng() % 2;
    const int repeats = 1 + static_cast<int>(rng() % 4);
    // Values with four decimals, as the program states them.
    auto four = [](double v) { return std::stod(num(v)); };
    const double start_c = four(coord(rng)), r_abs = four(start_c + (rng() % 3 == 0 ? up(rng) : -depth(rng) / 2));
    const double bottom_abs = four(r_abs - depth(rng)), q = four(peck(rng));
    const double ha = four(coord(rng)), hb = four(coord(rng));
    SCOPED_TRACE(fmt::format("trial {}: {} G{} {} {} L{}", trial, pl.code, code, incremental ? "G91" : "G90",
                             old_z ? "G98" : "G99", repeats));
    std::string prog = fmt::format("G21 {} G90 F300 S800 M3\nG0 {}0 {}0 {}{}\n", pl.code, pl.la, pl.lb, pl.lc, num(start_c));
    prog += fmt::format("{} {} G{}", old_z ? "G98" : "G99", incremental ? "G91" : "G90", code);
    // G91: X/Y step from the current point, R from the initial level, the bottom from R.
    const double r_word = four(incremental ? r_abs - start_c : r_abs);
    const double bottom_word = four(incremental ? bottom_abs - r_abs : bottom_abs);
    prog += fmt::format(" {}{} {}{} {}{} R{} L{}", pl.la, num(ha), pl.lb, num(hb), pl.lc, num(bottom_word), num(r_word), repeats);
    if (code == 73 || code == 83) prog += " Q" + num(q);
    if (code == 82 || code == 86 || code == 89) prog += " P0.5";
    prog += "\nG80\nM2\n";
    const Outcome r = run(prog);
    ASSERT_EQ(r.status, RunStatus::Finished) << r.error << "\n" << prog;
    // R and the bottom as the interpreter computes them.
    const double R = incremental ? r_word + start_c : r_word;
    const double bottom = incremental ? R + bottom_word : bottom_word;
    const double clear = old_z ? std::max(start_c, R) : R;
    const auto moves = r.sink.moves();
    std::vector<std::pair<double, double>> bottoms;
    double c_prev = start_c, a_prev = 0, b_prev = 0;
    for (std::size_t i = 1; i < moves.size(); ++i) {   // [0] is the G0 to the start
      const Pose& e = moves[i].end;
      const bool lateral = e[pl.a] != a_prev || e[pl.b] != b_prev;
      // Never below the bottom; never sideways below the R plane.
      EXPECT_GE(e[pl.c], bottom - 1e-12);
      if (lateral) {
        EXPECT_GE(std::min(e[pl.c], c_prev), R - 1e-12) << "lateral move below R at move " << i;
      }
      if (moves[i].kind == 'f') {
        EXPECT_FALSE(lateral) << "feed off the hole axis at move " << i;
        if (e[pl.c] == bottom) bottoms.emplace_back(e[pl.a], e[pl.b]);
        if (code == 73 || code == 83) {
          const double delta = 0.254;   // mm: back-off of each peck
          EXPECT_LE(std::fabs(e[pl.c] - c_prev), q + delta + 1e-9);
        }
      }
      c_prev = e[pl.c], a_prev = e[pl.a], b_prev = e[pl.b];
    }
    // One hole per repeat, stepped in G91, all at the same place in G90.
    ASSERT_EQ(bottoms.size(), static_cast<std::size_t>(repeats));
    for (int k = 0; k < repeats; ++k) {
      const double ea = incremental ? ha * (k + 1) : ha;
      const double eb = incremental ? hb * (k + 1) : hb;
      EXPECT_NEAR(bottoms[static_cast<std::size_t>(k)].first, ea, 1e-9);
      EXPECT_NEAR(bottoms[static_cast<std::size_t>(k)].second, eb, 1e-9);
    }
    // The block ends above the last hole at the retract height.
    EXPECT_NEAR(r.state.position.current[pl.c], clear, 1e-12);
    EXPECT_NEAR(r.state.position.current[pl.a], bottoms.back().first, 1e-12);
  }
}

TEST(CannedCycles, WordsCarryOverWhileTheSameCycleStaysActive) {
  const Outcome r = run("G21 F100\nG0 Z10\nG83 X1 Y1 Z-6 R2 Q2.5\nX4\nG82 X5 Z-1 R1 P0.3\nY3\nM2\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error;
  EXPECT_EQ(r.state.cycle.q, 2.5);
  EXPECT_EQ(r.state.cycle.p, 0.3);
  EXPECT_EQ(r.state.cycle.r, 1);
  EXPECT_EQ(r.state.cycle.bottom, -1);
  EXPECT_TRUE(r.state.cycle.initial_level_valid);
  EXPECT_EQ(r.state.cycle.initial_level, 10);
  EXPECT_EQ(r.state.position.current[Axis::Z], 1);   // G99: at R
  // A motion of another kind ends the run of cycles (and its initial level).
  const Outcome g0 = run("G21 F100\nG0 Z10\nG81 X1 Y1 Z-6 R2\nG0 X3\nM2\n");
  EXPECT_FALSE(g0.state.cycle.initial_level_valid);
  // A new cycle needs its R again; the same one does not.
  EXPECT_EQ(run("G21 F100\nG0 Z10\nG81 X1 Y1 Z-6 R2\nG82 X4 P1\nM2\n").error, "gcode.cycle-r-missing");
  EXPECT_EQ(run("G21 F100\nG0 Z10\nG81 X1 Y1 Z-6 R2\nG80\nG81 X4 Z-3\nM2\n").error, "gcode.cycle-r-missing");
}

TEST(CannedCycles, TappingReversesTheSpindleAndRestoresTheOverridesItFound) {
  const Outcome r = run("G21 F200 S300 M3\nG0 Z10\nG84 X1 Y1 Z-5 R2 P0.5\nM2\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error;
  auto sequence = [](const Outcome& o) {
    std::string seq;
    for (const Event& e : o.sink.events) seq += e.kind;
    return seq;
  };
  // Spindle on, rapid down, exact path, over the hole, to R, overrides off, feed in, stop,
  // reverse, dwell, feed out, stop, forward again, overrides on, path mode back; M2 stops.
  EXPECT_EQ(sequence(r), "ctmttvVfowdfoceEmo");
  // With the overrides off (M49) before the cycle, they stay off after it.
  const Outcome off = run("G21 F200 S300 M3 M49\nG0 Z10\nG84 X1 Y1 Z-5 R2 P0.5\nM2\n");
  EXPECT_EQ(sequence(off), "cvVtmttvVfowdfocmeEo");   // M2 turns them back on
}

// In G18 and G19 LinuxCNC 2.9 hands the tapping feeds' coordinates to its plane mapping
// rotated by one place; rs274 prints them so and its motion runs them. opencnc gives the same
// points (issue 6), while the rapids and the position after the block are the hole's.
TEST(CannedCycles, TappingInG18AndG19FeedsToThePointsLinuxCncGives) {
  const auto feeds = [](const Outcome& o) {
    std::vector<Pose> f;
    for (const Event& e : o.sink.moves()) {
      if (e.kind == 'f') f.push_back(e.end);
    }
    return f;
  };
  // G18: hole at Z3 X1, bottom Y-2, R2 (LinuxCNC starts in G99: back to R).
  const Outcome xz = run("G21 F200 S300 M3\nG18 G0 X5 Y6 Z7\nG84 X1 Y-2 Z3 R2\nM2\n");
  ASSERT_EQ(xz.status, RunStatus::Finished) << xz.error;
  const std::vector<Pose> f18 = feeds(xz);
  ASSERT_EQ(f18.size(), 2u);
  EXPECT_EQ(f18[0][Axis::X], -2);
  EXPECT_EQ(f18[0][Axis::Y], 3);
  EXPECT_EQ(f18[0][Axis::Z], 1);
  EXPECT_EQ(f18[1][Axis::X], 2);
  EXPECT_EQ(f18[1][Axis::Y], 3);
  EXPECT_EQ(f18[1][Axis::Z], 1);
  // G19 with G74: hole at Y1 Z3, bottom X-2, R2 (G99: back to R).
  const Outcome yz = run("G21 F200 S300 M4\nG19 G0 X5 Y6 Z7\nG99 G74 Y1 Z3 X-2 R2\nM2\n");
  ASSERT_EQ(yz.status, RunStatus::Finished) << yz.error;
  const std::vector<Pose> f19 = feeds(yz);
  ASSERT_EQ(f19.size(), 2u);
  EXPECT_EQ(f19[0][Axis::X], 3);
  EXPECT_EQ(f19[0][Axis::Y], -2);
  EXPECT_EQ(f19[0][Axis::Z], 1);
  EXPECT_EQ(f19[1][Axis::X], 3);
  EXPECT_EQ(f19[1][Axis::Y], 2);
  EXPECT_EQ(f19[1][Axis::Z], 1);
  // The interpreter takes the tool to be over the hole at the retract height afterwards.
  EXPECT_EQ(yz.state.position.current[Axis::X], 2);
  EXPECT_EQ(yz.state.position.current[Axis::Y], 1);
  EXPECT_EQ(yz.state.position.current[Axis::Z], 3);
  // G17 is unchanged: along Z at the hole.
  const Outcome xy = run("G21 F200 S300 M3\nG0 Z10\nG84 X1 Y2 Z-5 R2\nM2\n");
  const std::vector<Pose> f17 = feeds(xy);
  ASSERT_EQ(f17.size(), 2u);
  EXPECT_EQ(f17[0][Axis::X], 1);
  EXPECT_EQ(f17[0][Axis::Y], 2);
  EXPECT_EQ(f17[0][Axis::Z], -5);
}

TEST(CannedCycles, RunInTheUvwPlanesOnMachinesWithThoseAxes) {
  Options o = with_modules();
  o.axes = AxisMask::all();
  const Outcome r = run("G21 F100\nG0 W10\nG17.1 G81 U1 V2 W-3 R2\nG19.1 G83 V4 W5 U-6 R1 Q2.5\nM2\n", o);
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error;
  const auto moves = r.sink.moves();
  ASSERT_GE(moves.size(), 6u);
  // G17.1: over (U1, V2) at W10, down to R, feed to W-3, back to R.
  EXPECT_EQ(moves[1].end[Axis::U], 1);
  EXPECT_EQ(moves[1].end[Axis::V], 2);
  EXPECT_EQ(moves[1].end[Axis::W], 10);
  EXPECT_EQ(moves[3].kind, 'f');
  EXPECT_EQ(moves[3].end[Axis::W], -3);
  for (const Event& e : moves) EXPECT_EQ(e.end[Axis::X], 0);   // XYZ never move
  // G19.1 drills along U.
  EXPECT_EQ(r.state.position.current[Axis::U], 1);
  EXPECT_EQ(r.state.position.current[Axis::V], 4);
  // The other axis set cannot appear in the block; G84 cannot tap in these planes.
  EXPECT_EQ(run("G21 F100\nG17.1 G81 U1 V2 W-3 R2 X1\nM2\n", o).error, "gcode.cycle-rotary-axis");
  EXPECT_EQ(run("G21 F100 S100 M3\nG17.1 G84 U1 V2 W-3 R2\nM2\n", o).error, "gcode.cycle-tapping-plane");
}

TEST(CannedCycles, ReportTheirProblemsWithStableCodes) {
  const std::pair<const char*, const char*> cases[] = {
      {"G0 Z5\nG81 X1 Z-1\n", "gcode.cycle-r-missing"},
      {"G0 Z5\nG81 X1 R2\n", "gcode.cycle-bottom-missing"},
      {"G0 Z5\nG81 X1 Z3 R2\n", "gcode.cycle-r-below-bottom"},
      {"G0 Z5\nG81 X1 Z-1 R2 L0\n", "gcode.cycle-repeat-zero"},
      {"G0 Z5\nG83 X1 Z-1 R2\n", "gcode.cycle-q-missing"},
      {"G0 Z5\nG83 X1 Z-1 R2 Q-2\n", "gcode.cycle-q-not-positive"},
      {"G0 Z5\nG86 X1 Z-1 R2\n", "gcode.cycle-dwell-missing"},
      {"G0 Z5\nM3\nG87 X1 Z-1 R2 I1 K1\n", "gcode.cycle-g87-word-missing"},
      {"G0 Z5\nG86 X1 Z-1 R2 P1\n", "gcode.spindle-stopped"},
      {"G0 Z5\nM4\nG84 X1 Z-1 R2\n", "gcode.spindle-wrong-direction"},
      {"G0 Z5\nG81 X1 Z-1 R2 B3\n", "gcode.cycle-rotary-axis"},
      {"G0 Z5\nG93\nG81 X1 Z-1 R2\n", "gcode.cycle-inverse-time"},
      {"G0 Z5\nG74 X1 Z-1 R2 L2\n", "gcode.unused-word"},
  };
  for (const auto& [body, code] : cases) {
    EXPECT_EQ(run(std::string("G21 F100\n") + body + "M2\n").error, code) << body;
  }
}

// --- threading --------------------------------------------------------------------------------

TEST(Threading, RandomG76CyclesCutDeeperEachPassToTheFullDepth) {
  std::mt19937 rng(7611);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const bool internal = rng() % 2;
    const double i = (internal ? 1 : -1) * (0.5 + 2 * u(rng));
    const double j = 0.05 + 0.3 * u(rng);
    const double k = j + 0.2 + 1.5 * u(rng);
    const double r = 1 + 2 * u(rng);
    const double q = 30 * u(rng);
    const int h = static_cast<int>(rng() % 3);
    const double p = 0.5 + 2 * u(rng);
    const double z_end = -5 - 30 * u(rng);
    const std::string block = fmt::format("G76 P{} Z{} I{} J{} K{} R{} Q{} H{}", num(p), num(z_end), num(i), num(j),
                                          num(k), num(r), num(q), h);
    SCOPED_TRACE(block);
    const Outcome run76 = run("G21 G18 S300 M3\nG0 X20 Z2\n" + block + "\nM2\n");
    ASSERT_EQ(run76.status, RunStatus::Finished) << run76.error;
    const double I = std::stod(num(i)), J = std::stod(num(j)), K = std::stod(num(k)), R = std::stod(num(r));
    const double tan_q = std::tan(std::stod(num(q)) * 3.14159265358979323846 / 180);
    // The depth of pass n below the drive line is |I| + J n^(1/R) until |I| + K.
    std::vector<double> depths;
    for (int n = 1;; ++n) {
      const double d = std::fabs(I) + J * std::pow(n, 1.0 / R);
      if (d >= std::fabs(I) + K) break;
      depths.push_back(d);
    }
    for (int s = 0; s <= h; ++s) depths.push_back(std::fabs(I) + K);
    // Every feed is synchronised at the pitch and ends at the thread's end (shifted back by
    // the compound infeed).
    bool synced = false;
    std::vector<double> cut_x;
    for (const Event& e : run76.sink.events) {
      if (e.kind == 's') {
        synced = true;
        EXPECT_NEAR(e.value, std::stod(num(p)), 1e-12);
      }
      if (e.kind == 'x') synced = false;
      if (e.kind == 'f') {
        EXPECT_TRUE(synced);
        cut_x.push_back(e.end[Axis::X]);
      }
    }
    ASSERT_EQ(cut_x.size(), depths.size());
    for (std::size_t n = 0; n < depths.size(); ++n) {
      const double x = internal ? 20 + depths[n] : 20 - depths[n];
      EXPECT_NEAR(cut_x[n], x, 1e-9) << "pass " << n;
    }
    // The cuts never go past the full depth, and each is at least as deep as the last.
    for (std::size_t n = 1; n < cut_x.size(); ++n) EXPECT_GE(std::fabs(cut_x[n] - 20), std::fabs(cut_x[n - 1] - 20) - 1e-12);
    // The infeed of pass n starts tan(Q) * (depth - |I|) further back in Z.
    const auto moves = run76.sink.moves();
    std::size_t pass = 0;
    for (std::size_t m = 1; m + 1 < moves.size() && pass < depths.size(); ++m) {
      if (moves[m].kind == 't' && moves[m + 1].kind == 't' && moves[m].end[Axis::Z] == moves[m + 1].end[Axis::Z] &&
          moves[m].end[Axis::X] != moves[m + 1].end[Axis::X] && m + 2 < moves.size() && moves[m + 2].kind == 'f') {
        EXPECT_NEAR(moves[m].end[Axis::Z], 2 - (depths[pass] - std::fabs(I)) * tan_q, 1e-9) << "pass " << pass;
        ++pass;
      }
    }
    EXPECT_EQ(pass, depths.size());
    // The cycle ends at the programmed end, at the start X.
    EXPECT_EQ(run76.state.position.current[Axis::X], 20);
    EXPECT_EQ(run76.state.position.current[Axis::Z], std::stod(num(z_end)));
  }
}

TEST(Threading, RigidTapReturnsToItsStartAndG33IsSynchronised) {
  const Outcome r = run("G21 S200 M3\nG0 X1 Y2 Z3\nG33.1 Z-7 K1.25 I1.5\nG33 Z-4 K2\nM2\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error;
  std::string seq;
  for (const Event& e : r.sink.events) seq += e.kind;
  EXPECT_EQ(seq, "ctsrxsfxo");   // o: M2 stops the spindle
  EXPECT_EQ(r.sink.events[3].value, 1.5);           // the retract speed factor
  EXPECT_EQ(r.sink.events[3].end[Axis::Z], -7);
  EXPECT_EQ(r.sink.events[6].end[Axis::Z], -4);    // G33 starts where the tap started
  EXPECT_EQ(r.state.position.current[Axis::Z], -4);
}

// --- probing ----------------------------------------------------------------------------------

TEST(Probing, ScanModeBacksOffTowardsTheStartAsRs274Does) {
  std::mt19937 rng(38);
  std::uniform_real_distribution<double> c(-40, 40);
  for (int trial = 0; trial < 200; ++trial) {
    const bool inch = rng() % 2;
    Pose start{}, end{};
    for (int a = 0; a < 3; ++a) start[a] = std::stod(num(c(rng))), end[a] = std::stod(num(c(rng)));
    const std::string prog = fmt::format("{} F50\nG0 X{} Y{} Z{}\nG38.{} X{} Y{} Z{}\nM2\n", inch ? "G20" : "G21", num(start[0]),
                                         num(start[1]), num(start[2]), 2 + rng() % 4, num(end[0]), num(end[1]), num(end[2]));
    SCOPED_TRACE(prog);
    const Outcome r = run(prog);
    ASSERT_EQ(r.status, RunStatus::Finished) << r.error;
    const Pose& at = r.state.position.current;
    double dist_end = 0, dist_start = 0, along = 0;
    for (int a = 0; a < 3; ++a) {
      dist_end += (at[a] - end[a]) * (at[a] - end[a]);
      dist_start += (start[a] - end[a]) * (start[a] - end[a]);
      along += (at[a] - end[a]) * (start[a] - end[a]);
    }
    const double backoff = probe_backoff(inch ? canon::Units::Inch : canon::Units::Mm);
    EXPECT_NEAR(std::sqrt(dist_end), backoff, 1e-9);
    EXPECT_NEAR(along, backoff * std::sqrt(dist_start), 1e-9);   // on the line back to the start
    for (int a = 0; a < 3; ++a) EXPECT_EQ(r.state.parameters[static_cast<std::size_t>(5061 + a)], end[a]);
    EXPECT_EQ(r.state.parameters[5070], 0.0);
    EXPECT_EQ(r.state.position.canon_position, at);
  }
}

TEST(Probing, ExecuteModeWaitsForTheProbeResult) {
  Interpreter interp(with_modules(Mode::Execute));
  interp.open_text("probe.ngc", "G21 F100\nG0 X1 Z10\nG38.2 Z-5\nG0 Z#5063\nG91 G1 X1\nM2\n");
  Events sink;
  ASSERT_EQ(interp.run(sink), RunStatus::NeedSync);
  EXPECT_EQ(interp.pending_sync(), SyncKind::Probe);
  ASSERT_EQ(sink.events.back().kind, 'p');
  EXPECT_EQ(sink.events.back().end[Axis::Z], -5);
  // Still waiting: nothing runs until the result comes.
  EXPECT_EQ(interp.run(sink), RunStatus::NeedSync);
  SyncValues v;
  v.kind = SyncKind::Probe;
  v.probe_position[Axis::X] = 1;
  v.probe_position[Axis::Z] = -2.375;
  v.probe_tripped = true;
  v.position = v.probe_position;
  v.position[Axis::Z] = -2.3;   // the machine stopped a little past the trip point... and backed up
  interp.sync(v);
  ASSERT_EQ(interp.run(sink), RunStatus::Finished);
  const InterpState st = interp.state();
  EXPECT_EQ(st.parameters[5063], -2.375);
  EXPECT_EQ(st.parameters[5070], 1.0);
  const auto moves = sink.moves();
  EXPECT_EQ(moves[moves.size() - 2].end[Axis::Z], -2.375);   // G0 Z#5063
  EXPECT_EQ(moves.back().end[Axis::X], 2);                   // G91 from the synced position
}

TEST(Probing, AMoveThatMustMakeContactAndDoesNotEndsTheRun) {
  for (const char* code : {"G38.2", "G38.3", "G38.4", "G38.5"}) {
    SCOPED_TRACE(code);
    Interpreter interp(with_modules(Mode::Execute));
    interp.open_text("probe.ngc", fmt::format("G21 F100\nG0 Z10\n{} Z-5\nG0 Z20\nM2\n", code));
    Events sink;
    ASSERT_EQ(interp.run(sink), RunStatus::NeedSync);
    SyncValues v;
    v.kind = SyncKind::Probe;
    v.probe_position[Axis::Z] = -5;
    v.position = v.probe_position;
    interp.sync(v);
    const bool must = code == std::string("G38.2") || code == std::string("G38.4");
    EXPECT_EQ(interp.run(sink), must ? RunStatus::Error : RunStatus::Finished);
    if (must) {
      ASSERT_FALSE(interp.diagnostics().items().empty());
      const Diagnostic& d = interp.diagnostics().items().back();
      EXPECT_EQ(d.code, "gcode.probe-no-contact");
      EXPECT_EQ(d.line, 3u);
    } else {
      EXPECT_EQ(interp.state().parameters[5070], 0.0);
    }
  }
}

// --- replay and the program builder -----------------------------------------------------------

class StateAtMotion : public canon::Sink {
 public:
  StateAtMotion(const Interpreter& interp, std::vector<InterpState>& states) : interp_(interp), states_(states) {}
  void straight_traverse(canon::SegmentId id, const Pose&) override { capture(id); }
  void straight_feed(canon::SegmentId id, const Pose&) override { capture(id); }
  void straight_probe(canon::SegmentId id, const Pose&) override { capture(id); }
  void rigid_tap(canon::SegmentId id, const Pose&, double) override { capture(id); }

 private:
  void capture(canon::SegmentId id) {
    if (states_.size() <= id) states_.resize(id + 1);
    states_[id] = interp_.state();
  }
  const Interpreter& interp_;
  std::vector<InterpState>& states_;
};

std::vector<InterpState> states_at_motions(const std::string& program, canon::SegmentId quiet) {
  Options o = with_modules();
  o.quiet_until_segment = quiet;
  Interpreter interp(o);
  interp.open_text("replay.ngc", program);
  std::vector<InterpState> states;
  StateAtMotion sink(interp, states);
  EXPECT_EQ(interp.run(sink), RunStatus::Finished);
  return states;
}

TEST(CyclesReplay, StateAtAnySegmentInsideACycleEqualsTheFullRunsState) {
  const std::string program =
      "G21 F200 S500 M3\nG0 Z10\nG98 G83 X1 Y1 Z-6 R2 Q1.5 L2 G91\nG90 G38.3 Z-20\nG87 X5 Y5 Z-8 R1 I1 J0 K-2\n"
      "G18 G76 P1.5 Z-20 I-1 J0.2 K1 H1\nG17 G33.1 Z-5 K1\nG0 X0\nM2\n";
  const auto full = states_at_motions(program, 0);
  ASSERT_GT(full.size(), 40u);
  for (canon::SegmentId k = 1; k < full.size(); k += 3) {
    SCOPED_TRACE("replay to segment " + std::to_string(k));
    const auto part = states_at_motions(program, k);
    ASSERT_EQ(part.size(), full.size());
    EXPECT_EQ(part[k], full[k]);
    EXPECT_EQ(part[k].digest(), full[k].digest());
  }
}

TEST(CyclesProgram, TheBuilderSeesProbeTapAndSynchronisedMoves) {
  Interpreter interp(with_modules());
  canon::ProgramBuilder builder(kXyzabc);
  interp.open_text("p.ngc", "G21 F100 S300 M3\nG38.2 Z-5\nG33.1 Z-8 K1\nG33 Z-10 K1.5\nG1 X1\nM2\n");
  ASSERT_EQ(interp.run(builder), RunStatus::Finished);
  const canon::Program& p = builder.program();
  ASSERT_EQ(p.size(), 5u);  // the tap is two moves: in, and back out
  EXPECT_EQ(p.move(0).kind, canon::MoveKind::Probe);
  EXPECT_EQ(p.move(1).kind, canon::MoveKind::RigidTap);
  EXPECT_NE(p.move(1).flags & canon::kSpindleSynced, 0);
  EXPECT_EQ(p.move(2).kind, canon::MoveKind::RigidTap);
  EXPECT_NE(p.move(2).flags & canon::kTapReturn, 0);
  EXPECT_EQ(p.move(3).kind, canon::MoveKind::Feed);
  EXPECT_NE(p.move(3).flags & canon::kSpindleSynced, 0);
  EXPECT_EQ(p.move(4).flags & canon::kSpindleSynced, 0);
}

}  // namespace
