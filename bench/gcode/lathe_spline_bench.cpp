// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of the lathe roughing engine (passes per profile) and of splitting NURBS into chords.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "opencnc/canon/nurbs.hpp"
#include "opencnc/gcode/lathe_roughing.hpp"

namespace {

using namespace opencnc;
using gcode::lathe::Point;

class Counter final : public gcode::lathe::PathSink {
 public:
  void rapid(Point) override { ++moves; }
  void feed(Point) override { ++moves; }
  void arc(Point, Point, bool) override { ++moves; }
  std::size_t moves = 0;
};

// A 40 mm long contour of 24 elements (steps, tapers and arcs) on a 30 mm bar.
gcode::lathe::Profile bar_profile() {
  using K = gcode::lathe::ProfileElement::Kind;
  gcode::lathe::Profile p;
  Point at(2, 16);
  auto to = [&](Point end) {
    p.push_back({K::Line, at, end, {}, false, 0});
    at = end;
  };
  to(Point(0, 4));
  for (int i = 0; i < 11; ++i) {
    const double z = -3.5 * i;
    to(Point(z - 2, at.imag()));
    const Point end(z - 3.5, at.imag() + 1);
    const Point mid = (at + end) / 2.0, chord = end - at;
    const Point centre = mid + 1.5 * Point(0, 1) * chord;   // a bump, centre below the chord
    p.push_back({K::Arc, at, end, centre, true, 0});
    at = end;
  }
  return p;
}

void BM_RoughG71(benchmark::State& state) {
  const auto profile = bar_profile();
  gcode::lathe::RoughingParams params;
  params.start = Point(2, 16);
  params.allowance = 0.3;
  params.depth = 1.0 / static_cast<double>(state.range(0));
  params.retract = 0.5;
  std::size_t moves = 0;
  for (auto _ : state) {
    Counter c;
    gcode::lathe::rough(profile, params, c);
    moves = c.moves;
    benchmark::DoNotOptimize(c.moves);
  }
  state.counters["moves"] = static_cast<double>(moves);
  state.counters["moves/s"] = benchmark::Counter(static_cast<double>(moves) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RoughG71)->Arg(1)->Arg(4)->Unit(benchmark::kMicrosecond);

void BM_TessellateNurbs(benchmark::State& state) {
  // A 10-point, order-4 curve spanning about 100 mm, split at 0.5 µm.
  std::vector<canon::NurbsPoint> pts;
  for (int i = 0; i < 10; ++i) pts.push_back({10.0 * i, 20.0 * std::sin(i * 0.9), 1.0 + 0.5 * (i % 3)});
  std::size_t chords = 0;
  for (auto _ : state) {
    auto out = canon::tessellate_nurbs(pts, 4, 0.0005);
    chords = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["chords"] = static_cast<double>(chords);
}
BENCHMARK(BM_TessellateNurbs)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
