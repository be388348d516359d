// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc latency`: wake-up jitter histogram of the periodic servo thread (like LinuxCNC's latency test).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "cli_files.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "opencnc/control/clock.hpp"
#include "opencnc/viz/svg_chart.hpp"

namespace opencnc::cli {

namespace {

struct LatencyOptions {
  double seconds = 10;
  double period_us = 1000;
  int priority = 80;
  int cpu = -1;
  std::string csv, svg;
  bool json = false;
};

// The measured thread does nothing but wake up: what is measured is the platform's scheduling
// latency, the budget a servo tick must leave room for.
struct IdleTick final : control::Tickable {
  bool tick() noexcept override { return true; }
};

// The terminal view groups the 1 µs bins into widening buckets: a person wants the shape and the
// tail at a glance; the CSV and SVG keep every bin.
void print_histogram(const control::LatencyHistogram& h) {
  static constexpr int kEdges[] = {0, 5, 10, 20, 30, 40, 50, 75, 100, 150, 200, 300, 500, 1000};
  constexpr int kBuckets = static_cast<int>(std::size(kEdges));
  const auto counts = h.counts();
  std::uint64_t bucket[kBuckets] = {};
  for (int i = 0; i <= control::LatencyHistogram::kBins; ++i) {
    int b = kBuckets - 1;
    while (b > 0 && kEdges[b] > i) --b;
    bucket[b] += counts[static_cast<std::size_t>(i)];
  }
  int first = 0, last = kBuckets - 1;
  while (first < last && bucket[first] == 0) ++first;
  while (last > first && bucket[last] == 0) --last;
  const std::uint64_t peak = *std::max_element(std::begin(bucket), std::end(bucket));
  std::puts("  latency (us)      count  share");
  for (int b = first; b <= last; ++b) {
    const double share =
        h.samples() == 0 ? 0 : static_cast<double>(bucket[b]) / static_cast<double>(h.samples());
    const int bar =
        peak == 0 ? 0
                  : static_cast<int>(40.0 * static_cast<double>(bucket[b]) / static_cast<double>(peak) + 0.5);
    const std::string label = b + 1 < kBuckets ? fmt::format("{:4d} - {:<4d}", kEdges[b], kEdges[b + 1])
                                               : fmt::format(">= {:<8d}", kEdges[b]);
    fmt::print("  {} {:9d}  {:6.2f}%  {}\n", label, bucket[b], 100.0 * share,
               std::string(static_cast<std::size_t>(bucket[b] > 0 ? std::max(bar, 1) : 0), '#'));
  }
}

std::string histogram_csv(const control::LatencyHistogram& h) {
  std::string out = "bin_start_us,bin_end_us,count\n";
  const auto counts = h.counts();
  for (int i = 0; i <= control::LatencyHistogram::kBins; ++i) {
    out += i == control::LatencyHistogram::kBins
               ? fmt::format("{},inf,{}\n", i, counts[static_cast<std::size_t>(i)])
               : fmt::format("{},{},{}\n", i, i + 1, counts[static_cast<std::size_t>(i)]);
  }
  return out;
}

std::string histogram_svg(const control::RealtimeClock& clock, double period_us) {
  const auto& h = clock.latency();
  const auto counts = h.counts();
  viz::Panel p;
  p.title = fmt::format("wake-up latency, {} samples, max {:.1f} us, {} overruns", h.samples(),
                        static_cast<double>(h.max_ns()) / 1000.0, clock.overruns());
  p.x_label = "latency after deadline (us)";
  p.y_label = "count (log)";
  p.log_y = true;
  viz::Series s;
  s.bars = true;
  s.color = "#1f77b4";
  int last = 1;
  for (int i = 0; i < control::LatencyHistogram::kBins; ++i) {
    if (counts[static_cast<std::size_t>(i)] > 0) last = i;
  }
  for (int i = 0; i <= last; ++i) {
    s.x.push_back(i + 0.5);
    s.y.push_back(static_cast<double>(counts[static_cast<std::size_t>(i)]));
  }
  p.series.push_back(std::move(s));
  viz::SvgChart chart(fmt::format("opencnc latency — period {:.0f} us, {}", period_us,
                                  clock.realtime() ? "SCHED_FIFO" : "normal thread (not real-time)"));
  chart.add_panel(std::move(p));
  return chart.render();
}

int run_latency(const LatencyOptions& o) {
  // Outputs are checked (and created) before the measurement, not after it.
  const NamedPath outputs[] = {{"--csv", o.csv}, {"--svg", o.svg}};
  const auto files = open_outputs({}, outputs);
  if (files.empty()) return kExitUsage;
  control::RealtimeClock::Options co;
  co.period_ns = static_cast<std::int64_t>(o.period_us * 1000.0);
  co.priority = o.priority;
  co.cpu = o.cpu;
  control::RealtimeClock clock(co);
  IdleTick tick;
  if (!clock.start(tick)) {
    fmt::print(stderr, "error: cannot start the periodic thread\n");
    return kExitProgram;
  }
  for (const auto& w : clock.warnings()) fmt::print(stderr, "warning: {}\n", w);
  if (!o.json)
    fmt::print("measuring {:.0f} us periods for {:.1f} s ({})...\n", o.period_us, o.seconds,
               clock.realtime() ? "SCHED_FIFO" : "normal thread");
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds));
  clock.stop();

  const auto& h = clock.latency();
  if (o.json) {
    // One object on one line: scripts (latency-under-load.sh) embed it as it is.
    fmt::print(
        "{{\"period_us\": {:.0f}, \"seconds\": {:.1f}, \"sched_fifo\": {}, \"samples\": {}, \"overruns\": "
        "{}, "
        "\"min_us\": {:.1f}, \"mean_us\": {:.1f}, \"stddev_us\": {:.1f}, \"p99_us\": {:.0f}, \"p999_us\": "
        "{:.0f}, "
        "\"max_us\": {:.1f}}}\n",
        o.period_us, o.seconds, clock.realtime(), h.samples(), clock.overruns(),
        static_cast<double>(h.min_ns()) / 1000.0, h.mean_ns() / 1000.0, h.stddev_ns() / 1000.0,
        static_cast<double>(h.percentile_ns(0.99)) / 1000.0,
        static_cast<double>(h.percentile_ns(0.999)) / 1000.0, static_cast<double>(h.max_ns()) / 1000.0);
  } else {
    fmt::print(
        "samples {}  overruns {}  min {:.1f} us  mean {:.1f} us  stddev {:.1f} us  p99 {:.0f} us  "
        "p99.9 {:.0f} us  max {:.1f} us\n",
        h.samples(), clock.overruns(), static_cast<double>(h.min_ns()) / 1000.0, h.mean_ns() / 1000.0,
        h.stddev_ns() / 1000.0, static_cast<double>(h.percentile_ns(0.99)) / 1000.0,
        static_cast<double>(h.percentile_ns(0.999)) / 1000.0, static_cast<double>(h.max_ns()) / 1000.0);
    print_histogram(h);
  }
  int rc = kExitOk;
  if (files[0] && !write_and_commit(*files[0], histogram_csv(h))) rc = kExitUsage;
  if (files[1] && !write_and_commit(*files[1], histogram_svg(clock, o.period_us))) rc = kExitUsage;
  return rc;
}

}  // namespace

void add_latency_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<LatencyOptions>();
  CLI::App* cmd = app.add_subcommand("latency", "Measure the wake-up jitter of the periodic servo thread");
  cmd->add_option("--seconds", opts->seconds, "How long to measure")->check(finite_range(0.1, 86400.0));
  cmd->add_option("--period-us", opts->period_us, "Thread period in microseconds")
      ->check(finite_range(50.0, 100000.0));
  cmd->add_option("--priority", opts->priority, "SCHED_FIFO priority")->check(CLI::Range(1, 99));
  cmd->add_option("--cpu", opts->cpu, "Pin the thread to this CPU")->check(CLI::Range(0, 1023));
  cmd->add_option("--csv", opts->csv, "Write the histogram as CSV");
  cmd->add_option("--svg", opts->svg, "Draw the histogram as SVG");
  cmd->add_flag("--json", opts->json, "Print the figures as one JSON object (no histogram)");
  cmd->callback([opts, &registry] { registry.set_result(run_latency(*opts)); });
}

}  // namespace opencnc::cli
