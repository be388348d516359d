// SPDX-License-Identifier: GPL-3.0-or-later
// Feed steps per second of PulseDistributor for 3, 5, 6 and 9 axes, both methods, one feed step
// at a time (a step generator) and a servo period at a time (advance_to_fraction).
#include <benchmark/benchmark.h>

#include <array>
#include <bit>
#include <span>

#include "opencnc/motion/pulse_distributor.hpp"

namespace {

using opencnc::motion::PulseDistributor;
using opencnc::motion::PulseMethod;
using opencnc::motion::StepCount;

// Unequal lengths and mixed signs, all axes moving; a move is cut to the first N.
constexpr std::array<StepCount, 9> kMove{1'000'003, -737'111, 512'345,    -98'765, 1'234'567,
                                         -3'001,    777'777,  -1'500'001, 42'421};

std::span<const StepCount> move_of(const benchmark::State& state) {
  return std::span<const StepCount>(kMove).first(static_cast<std::size_t>(state.range(0)));
}

// One feed step per call, as a step-pulse generator uses it.
template <PulseMethod kMethod>
void BM_Step(benchmark::State& state) {
  PulseDistributor d(kMethod);
  d.start(move_of(state));
  std::int64_t pulses = 0;
  for (auto _ : state) {
    if (d.done()) d.start(move_of(state));
    const auto out = d.step();
    pulses += std::popcount(out.step_mask);
    benchmark::DoNotOptimize(out);
  }
  state.SetItemsProcessed(state.iterations());  // feed steps
  state.counters["axis_steps/s"] =
      benchmark::Counter(static_cast<double>(pulses), benchmark::Counter::kIsRate);
}

// One servo period per call: the move spread over 1000 periods, each advance_to_fraction() call
// taking about a thousandth of it.
template <PulseMethod kMethod>
void BM_ServoPeriod(benchmark::State& state) {
  constexpr StepCount kPeriods = 1000;
  PulseDistributor d(kMethod);
  d.start(move_of(state));
  StepCount period = 0;
  StepCount feed_steps = 0;
  for (auto _ : state) {
    if (period == kPeriods) {
      d.start(move_of(state));
      period = 0;
    }
    feed_steps += d.advance_to_fraction(++period, kPeriods);
    benchmark::DoNotOptimize(d.position(0));
  }
  state.SetItemsProcessed(state.iterations());  // servo periods
  state.counters["feed_steps/s"] =
      benchmark::Counter(static_cast<double>(feed_steps), benchmark::Counter::kIsRate);
}

BENCHMARK(BM_Step<PulseMethod::Vector>)->Arg(3)->Arg(5)->Arg(6)->Arg(9);
BENCHMARK(BM_Step<PulseMethod::Dda>)->Arg(3)->Arg(5)->Arg(6)->Arg(9);
BENCHMARK(BM_ServoPeriod<PulseMethod::Vector>)->Arg(3)->Arg(5)->Arg(6)->Arg(9);
BENCHMARK(BM_ServoPeriod<PulseMethod::Dda>)->Arg(3)->Arg(5)->Arg(6)->Arg(9);

}  // namespace
