// SPDX-License-Identifier: GPL-3.0-or-later
// path_index_bench — builds the retrace path index of a nest of parts on a 3000 × 1500 mm sheet
// (each part a wavy outline of short lines and arcs, as CAM output is, and a round hole; rapids
// between them) with a given number of feed segments, then times nearest-point queries from
// random points of the sheet against a scan of every segment, checking that both agree. Times
// are the thread's CPU time (the wall-clock p99 is printed beside: on a shared machine it
// counts the other processes).
//
//   path_index_bench [--segments N] [--queries N] [--linear-queries N] [--margin UM] [--seed S] [--json]
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/retrace/path_index.hpp"

using namespace opencnc;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kPerPart =
    200;  ///< feed segments per part: 180 outline lines, 18 outline arcs, a hole of 2 arcs

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// CPU time of this thread: on the shared build machine other processes take the cores for
/// milliseconds at a time, which the wall clock counts and the thread's CPU time does not.
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

/// One part at (x0, y0) in a cell of `cell` mm: its outline, then its hole.
void add_part(canon::ProgramBuilder& b, canon::SegmentId& id, double x0, double y0, double cell) {
  const double r = 0.4 * cell;
  const auto outline = [&](int k) {
    const double a = 2 * kPi * k / 198.0;
    const double rr = r * (1 + 0.05 * std::sin(7 * a));
    return Pose{x0 + rr * std::cos(a), y0 + rr * std::sin(a), 0};
  };
  b.straight_traverse(id++, outline(0));
  for (int k = 1; k <= 198; ++k) {
    const Pose p = outline(k);
    if (k % 11 == 0) {  // an arc about the part's centre from the last outline point, ending at p's angle
      const Pose s = outline(k - 1);
      const double rad = std::hypot(s[0] - x0, s[1] - y0), ang = std::atan2(p[1] - y0, p[0] - x0);
      canon::ArcFeed arc;
      arc.first_center = x0;
      arc.second_center = y0;
      arc.first_end = x0 + rad * std::cos(ang);
      arc.second_end = y0 + rad * std::sin(ang);
      arc.rotation = 1;
      arc.end = Pose{arc.first_end, arc.second_end, 0};
      b.arc_feed(id++, arc);
      continue;
    }
    b.straight_feed(id++, p);
  }
  const double h = 0.1 * cell;
  b.straight_traverse(id++, Pose{x0 + h, y0, 0});
  for (int half = 0; half < 2; ++half) {
    canon::ArcFeed arc;
    arc.first_end = x0 + (half == 0 ? -h : h);
    arc.second_end = y0;
    arc.first_center = x0;
    arc.second_center = y0;
    arc.rotation = 1;
    arc.end = Pose{arc.first_end, arc.second_end, 0};
    b.arc_feed(id++, arc);
  }
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

int usage(int code) {
  std::fputs(
      "usage: path_index_bench [--segments N] [--queries N] [--linear-queries N] [--margin UM] [--seed S] "
      "[--json]\n"
      "  Builds the retrace path index of a nest of parts with about N feed segments (default\n"
      "  1000000) and times nearest-point queries (candidates within UM micrometres of the\n"
      "  nearest, default 500) against a scan of every segment.\n",
      code == 0 ? stdout : stderr);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  long segments = 1000000, queries = 20000, linear_queries = 200, margin_um = 500;
  unsigned seed = 1;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> long {
      if (i + 1 >= argc) return -1;
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      return *end == '\0' && v > 0 ? v : -1;
    };
    if (a == "--help" || a == "-h") return usage(0);
    if (a == "--json") {
      json = true;
    } else if (a == "--segments") {
      segments = value();
    } else if (a == "--queries") {
      queries = value();
    } else if (a == "--linear-queries") {
      linear_queries = value();
    } else if (a == "--margin") {
      margin_um = value();
    } else if (a == "--seed") {
      seed = static_cast<unsigned>(value());
    } else {
      fmt::print(stderr, "path_index_bench: unknown option '{}'\n", a);
      return usage(2);
    }
    if (segments <= 0 || queries <= 0 || linear_queries <= 0 || margin_um <= 0) return usage(2);
  }

  // The nest, built as the interpreter's canonical calls would build it.
  const long parts = std::max(1L, segments / kPerPart);
  const int cols = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(parts) * 2))));
  const double cell = 3000.0 / cols;
  canon::ProgramBuilder b(AxisMask(0x7));  // X Y Z
  b.set_feed_rate(3000);
  canon::SegmentId id = 0;
  for (long p = 0; p < parts; ++p)
    add_part(b, id, (static_cast<double>(p % cols) + 0.5) * cell,
             (static_cast<double>(p / cols) + 0.5) * cell, cell);
  const canon::Program& program = b.program();

  const auto t0 = Clock::now();
  const double c0 = thread_cpu_s();
  recovery::PathIndex index;
  for (std::size_t m = 0; m < program.size(); ++m) index.add(program, m);
  index.finish();
  const double build_s = thread_cpu_s() - c0, build_wall_s = seconds_since(t0);

  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(0, 3000),
      uy(0, cell * std::ceil(static_cast<double>(parts) / cols));
  std::vector<Vec3> points(static_cast<std::size_t>(queries));
  for (auto& q : points) q = {ux(rng), uy(rng), 0};
  recovery::QueryOptions options;
  options.margin_mm = static_cast<double>(margin_um) / 1000;
  std::vector<double> tree_us, tree_wall_us, linear_us;
  tree_us.reserve(points.size());
  tree_wall_us.reserve(points.size());
  for (const auto& q : points) {
    const auto t = Clock::now();
    const double c = thread_cpu_s();
    const recovery::Nearest n = index.nearest(q, options);
    tree_us.push_back((thread_cpu_s() - c) * 1e6);
    tree_wall_us.push_back(seconds_since(t) * 1e6);
    if (!n.found) return 1;
  }
  long mismatches = 0;
  for (long i = 0; i < linear_queries; ++i) {
    const auto& q = points[static_cast<std::size_t>(i) % points.size()];
    const double c = thread_cpu_s();
    const recovery::Nearest l = index.nearest_linear(q, options);
    linear_us.push_back((thread_cpu_s() - c) * 1e6);
    const recovery::Nearest n = index.nearest(q, options);
    if (l.nearest.entry != n.nearest.entry || l.nearest.distance_mm != n.nearest.distance_mm) ++mismatches;
  }
  const double memory_mb = static_cast<double>(index.memory_bytes()) / 1e6;
  if (json) {
    fmt::print(
        "{{\"segments\": {}, \"build_s\": {:.4f}, \"build_wall_s\": {:.4f}, \"query_p50_us\": {:.2f}, "
        "\"query_p99_us\": {:.2f}, \"query_max_us\": {:.2f}, \"query_wall_p99_us\": {:.2f}, "
        "\"linear_p50_us\": {:.1f}, "
        "\"linear_p99_us\": {:.1f}, \"memory_mb\": {:.1f}, \"program_mb\": {:.1f}, \"peak_rss_mb\": {:.1f}, "
        "\"queries\": {}, \"linear_queries\": {}, \"mismatches\": {}}}\n",
        index.size(), build_s, build_wall_s, percentile(tree_us, 0.5), percentile(tree_us, 0.99),
        percentile(tree_us, 1.0), percentile(tree_wall_us, 0.99), percentile(linear_us, 0.5),
        percentile(linear_us, 0.99), memory_mb, static_cast<double>(program.memory_bytes()) / 1e6,
        peak_rss_mb(), queries, linear_queries, mismatches);
  } else {
    fmt::print("feed segments     {}\n", index.size());
    fmt::print("build             {:.3f} s CPU ({:.3f} s wall)\n", build_s, build_wall_s);
    fmt::print(
        "query (tree)      p50 {:.2f} us  p99 {:.2f} us  max {:.2f} us CPU; p99 {:.2f} us wall  ({} "
        "queries)\n",
        percentile(tree_us, 0.5), percentile(tree_us, 0.99), percentile(tree_us, 1.0),
        percentile(tree_wall_us, 0.99), queries);
    fmt::print("query (linear)    p50 {:.1f} us  p99 {:.1f} us CPU  ({} queries)\n",
               percentile(linear_us, 0.5), percentile(linear_us, 0.99), linear_queries);
    fmt::print("index memory      {:.1f} MB (the program itself {:.1f} MB; peak RSS {:.1f} MB)\n", memory_mb,
               static_cast<double>(program.memory_bytes()) / 1e6, peak_rss_mb());
    fmt::print("tree vs linear    {} mismatches\n", mismatches);
  }
  return mismatches == 0 ? 0 : 1;
}
