// SPDX-License-Identifier: GPL-3.0-or-later
// plan_throughput — how much faster than the motion the planner runs on programs of 0.05 mm feed
// moves at 100 mm/s (2000 moves a second), zigzags included, with and without jerk limits (issue
// 23's throughput target: at least 20×, one core; docs/performance.md, "Jerk-limited motion").
//
//   plan_throughput [--moves N] [--jerks 0,1e5,2e4] [--tolerance P] [SHAPE...]
//
// The machine is configs/mill-3axis.toml's (X Y Z at 100 mm/s, 1000 mm/s², 1 ms) with the jerk J
// on all three axes, 200 moves of look-ahead. For each shape and J the program is planned twice on
// this thread: once alone (the blocks are popped from the queue as soon as they are published, so
// the CPU time is the planner's only), once with the interpolator ticking in virtual time
// (analysis::simulate without the trace checker: planner plus tick). Both are printed as
// motion time ÷ CPU time of the thread (CLOCK_THREAD_CPUTIME_ID: the machine is shared, so wall
// time says little about our cost). The planner's resident memory does not grow with the program
// (the window is bounded, docs/planner.md); the program itself is held whole here.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "opencnc/analysis/simulate.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/traj/block_queue.hpp"

using namespace opencnc;

namespace {

constexpr double kStep = 0.05;  // mm per move
constexpr double kFeed = 6000;  // mm/min = 100 mm/s: 2000 moves a second
constexpr double kPi = 3.14159265358979323846;

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Rounds to 0.1 µm, as a 4-decimal CAM file would.
double r4(double v) {
  return std::round(v * 1e4) * 1e-4;
}

struct Shape {
  const char* name;
  const char* what;
  /// The end point of move i (i ≥ 1); the program starts at the origin.
  std::function<void(int n, std::vector<Pose>& points)> make;
};

Pose xyz(double x, double y, double z) {
  Pose p;
  p[Axis::X] = r4(x);
  p[Axis::Y] = r4(y);
  p[Axis::Z] = r4(z);
  return p;
}

std::vector<Shape> shapes() {
  return {
      {"spiral", "Archimedean spiral from r = 50 mm, 0.5 mm per turn, 0.05 mm chords",
       [](int n, std::vector<Pose>& pts) {
         double th = 0;
         for (int i = 0; i < n; ++i) {
           const double r = 50 - 0.5 * th / (2 * kPi);
           pts.push_back(xyz(r * std::cos(th), r * std::sin(th), 0));
           th += kStep / r;
         }
       }},
      {"surface", "raster over a wavy surface: 20 mm rows of 0.05 mm moves, Z = 2 sin, 0.2 mm stepover",
       [](int n, std::vector<Pose>& pts) {
         const int per_row = static_cast<int>(20 / kStep);
         for (int i = 0; i < n; ++i) {
           const int row = i / per_row, k = i % per_row;
           const double x = (row % 2 == 0 ? k : per_row - 1 - k) * kStep;
           const double y = 0.2 * row;
           pts.push_back(xyz(x, y, 2 * std::sin(0.3 * x) * std::cos(0.2 * y)));
         }
       }},
      {"zigzag-180", "X back and forth by 0.05 mm, Y creeping 0.1 µm a move (bench/control/gen_dense.py)",
       [](int n, std::vector<Pose>& pts) {
         for (int i = 0; i < n; ++i) pts.push_back(xyz((i % 2) * kStep, i * 1e-4, 0));
       }},
      {"zigzag-90", "a staircase: 0.05 mm along X, then 0.05 mm along Y",
       [](int n, std::vector<Pose>& pts) {
         for (int i = 0; i < n; ++i) pts.push_back(xyz(((i + 1) / 2) * kStep, (i / 2) * kStep, 0));
       }},
      {"zigzag-30", "0.05 mm moves turning ±150° in turn (a zigzag of 30° teeth)",
       [](int n, std::vector<Pose>& pts) {
         const double a = 15 * kPi / 180;
         for (int i = 0; i < n; ++i) {
           const double x = (i + 1) * kStep * std::cos(a), y = (i % 2 == 0 ? 1 : 0) * kStep * std::sin(a);
           pts.push_back(xyz(x, y, 0));
         }
       }},
      {"random", "0.05 mm moves turning by a seeded random angle in ±90°",
       [](int n, std::vector<Pose>& pts) {
         std::mt19937 rng(23);
         std::uniform_real_distribution<double> turn(-kPi / 2, kPi / 2);
         double x = 0, y = 0, h = 0;
         for (int i = 0; i < n; ++i) {
           h += turn(rng);
           x += kStep * std::cos(h);
           y += kStep * std::sin(h);
           pts.push_back(xyz(x, y, 0));
         }
       }},
  };
}

canon::Program build(const Shape& s, int n, double tolerance) {
  std::vector<Pose> pts;
  pts.reserve(static_cast<std::size_t>(n));
  s.make(n, pts);
  canon::ProgramBuilder b(kXyzabc);
  b.set_motion_control_mode(canon::MotionControl::Continuous, tolerance);
  b.set_feed_rate(kFeed);
  canon::SegmentId id = 0;
  b.straight_feed(++id, pts.front());
  for (std::size_t i = 1; i < pts.size(); ++i) b.straight_feed(++id, pts[i]);
  return b.take();
}

analysis::SimulationOptions options() {
  analysis::SimulationOptions opt;
  opt.planner.lookahead_moves = 200;
  opt.check = false;
  opt.max_time_s = 48 * 3600;
  return opt;
}

/// CPU seconds of planning `program` alone: every published block is popped at once.
double plan_only(const canon::Program& program, const plan::MachineLimits& limits) {
  plan::Planner planner(limits, options().planner);
  auto queue = std::make_unique<traj::BlockQueue>();
  const double c0 = cpu_seconds();
  if (!planner.start(program)) return -1;
  for (;;) {
    const plan::PlanStatus st = planner.pump(*queue);
    queue->pop(queue->available());
    if (st != plan::PlanStatus::Working) break;
  }
  return cpu_seconds() - c0;
}

}  // namespace

int main(int argc, char** argv) {
  int moves = 20000;
  double tolerance = 0.01;
  std::vector<double> jerks{0, 1e5, 2e4};
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string { return i + 1 < argc ? argv[++i] : std::string(); };
    if (a == "--moves") {
      moves = std::max(2, std::atoi(value().c_str()));
    } else if (a == "--tolerance") {
      tolerance = std::strtod(value().c_str(), nullptr);
    } else if (a == "--jerks") {
      jerks.clear();
      std::stringstream list(value());
      std::string item;
      while (std::getline(list, item, ',')) jerks.push_back(std::strtod(item.c_str(), nullptr));
    } else if (a == "-h" || a == "--help") {
      std::fprintf(stderr,
                   "usage: plan_throughput [--moves N] [--jerks 0,1e5,2e4] [--tolerance P] [SHAPE...]\n");
      return 2;
    } else {
      only.push_back(a);
    }
  }
  fmt::print("{} moves of {} mm at F{:g}, G64 P{:g}, look-ahead 200\n\n", moves, kStep, kFeed, tolerance);
  fmt::print(
      "| shape | J [mm/s³] | motion [s] | planner CPU [s] | planner × real time | planner + tick CPU [s] | "
      "planner + tick × real time |\n|---|---:|---:|---:|---:|---:|---:|\n");
  double worst = 1e300;
  for (const Shape& s : shapes()) {
    if (!only.empty() && std::find(only.begin(), only.end(), s.name) == only.end()) continue;
    const canon::Program program = build(s, moves, tolerance);
    for (double j : jerks) {
      const plan::MachineLimits limits =
          plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, j);
      const double plan_cpu = plan_only(program, limits);
      const double c0 = cpu_seconds();
      const analysis::SimulationResult r = analysis::simulate(program, limits, options());
      const double all_cpu = cpu_seconds() - c0;
      if (!r.finished || plan_cpu < 0) {
        fmt::print("| {} | {:g} | did not finish |\n", s.name, j);
        worst = 0;
        continue;
      }
      worst = std::min(worst, r.motion_time_s / all_cpu);
      fmt::print("| {} | {:g} | {:.3f} | {:.3f} | {:.0f} | {:.3f} | {:.0f} |\n", s.name, j, r.motion_time_s,
                 plan_cpu, r.motion_time_s / plan_cpu, all_cpu, r.motion_time_s / all_cpu);
      std::fflush(stdout);
    }
  }
  fmt::print("\nslowest planner + tick: {:.0f}× real time\n", worst);
  return 0;
}
