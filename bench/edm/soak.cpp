// SPDX-License-Identifier: GPL-3.0-or-later
// soak — the five-axis sinker EDM machining for hours in virtual time: one channel after another
// (roughing with jumps, semi-finishing with a circle orbit, finishing with a square orbit and jumps
// along the path, four electrode changes per channel, B tilted both ways), a fresh workpiece per
// channel. Measures what a days-long job needs: resident memory flat after the first hour (and
// the resident set and the heap in use at the end of every hour), the
// servo tick's cost (p99) unchanged from the first hour to the last, and no drift of the rest
// position: every channel ends where the first one did (which is within half a step of the
// program: the axes home on switches).
//
//   soak [--hours H] [--json] [--profile FILE]
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <malloc.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

using namespace opencnc;
using namespace opencnc::control;
using namespace opencnc::controller;

namespace {

constexpr const char* kChannel = R"(G21 G90 G94
T1 M6
G0 B-30 C0 X-0.8 Y0
G0 Z-19.97
M180 P1
G1 Z-20.03 C0.2 F60
M181
G0 Z5
T2 M6
G0 Z-20.0
M180 P2
G1 Z-20.035 F30
M180 P3
G1 Z-20.04 F20
M181
G0 Z5
T3 M6
G0 B30 C0 X0.8
G0 Z-19.97
M180 P1
G1 Z-20.03 C-0.2 F60
M181
G0 Z5
T4 M6
G0 Z-20.0
M180 P3
G1 Z-20.035 F20
M181
G0 Z5
G0 B0 C0 X0 Y0 Z0
M2
)";

/// Servo tick durations in 10 ns buckets up to 1 ms (the last bucket: longer).
struct Histogram {
  std::array<std::uint64_t, 100001> n{};
  std::uint64_t count = 0;
  void add(std::int64_t ns) {
    ++n[static_cast<std::size_t>(std::clamp<std::int64_t>(ns / 10, 0, 100000))];
    ++count;
  }
  double p99() const {
    const std::uint64_t want = count - count / 100;
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < n.size(); ++i)
      if ((seen += n[i]) >= want) return static_cast<double>(i) * 10.0;
    return 0;
  }
};

/// VmRSS (now) and VmHWM (peak) of this process, MiB.
std::pair<double, double> rss_mb() {
  std::ifstream f("/proc/self/status");
  std::string key;
  double rss = 0, hwm = 0, kb = 0;
  std::string unit;
  while (f >> key) {
    if (key == "VmRSS:" && f >> kb >> unit) rss = kb / 1024;
    if (key == "VmHWM:" && f >> kb >> unit) hwm = kb / 1024;
  }
  return {rss, hwm};
}

/// Bytes the allocator has handed out and not had back (MiB): unlike the resident set, it does not
/// count pages the allocator keeps after a free, so it tells a leak from fragmentation.
double heap_in_use_mb() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks + m.hblkhd) / (1024.0 * 1024.0);
}

[[noreturn]] void usage(int code) {
  std::fputs(
      "usage: soak [--hours H] [--json] [--profile FILE]\n"
      "  Machines turbine channels on the simulated five-axis EDM for H hours of virtual time (default 1)\n"
      "  and reports memory, the servo tick's p99 in the first and the last hour, and position drift.\n",
      code == 0 ? stdout : stderr);
  std::exit(code);
}

struct Options {
  double hours = 1;
  bool json = false;
  std::string profile = OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml";
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--help" || a == "-h") usage(0);
    if (a == "--json") {
      o.json = true;
    } else if (a == "--hours" && i + 1 < argc) {
      char* end = nullptr;
      o.hours = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(o.hours > 0) || o.hours > 1e4) usage(2);
    } else if (a == "--profile" && i + 1 < argc) {
      o.profile = argv[++i];
    } else {
      std::fprintf(stderr, "soak: unknown option %s\n", argv[i]);
      usage(2);
    }
  }
  return o;
}

struct Result {
  double wall_s = 0, rss_first = 0, rss_last = 0, hwm_first = 0, hwm_last = 0;
  double heap_first = 0, heap_last = 0;
  double p99_first = 0, p99_last = 0, drift_um = 0, drift_mdeg = 0;
  // The first channel's rest against the program: the axes home on switches whose edges fall
  // between two steps, so a homed stepper stands up to half a step from a programmed position.
  // The drift is how far any later rest is from that first one.
  double rest_um = 0, rest_mdeg = 0;
  Pose first_rest{};
  std::uint64_t channels = 0, ticks = 0, jumps = 0;
  std::vector<double> rss_hourly, heap_hourly;  // at the end of every hour of machining
};

bool accepted(SimRig& rig, Request r) {
  return rig.request(std::move(r), 200000).accepted;
}

/// Every axis homed on its switches (the profile's methods; at once where it homes immediately).
bool home_all(SimRig& rig) {
  if (!accepted(rig, Request::set_mode(Mode::Manual)) || !accepted(rig, Request::home())) return false;
  if (rig.run_until([&] { return rig.status().servo.state == State::Idle && rig.status().servo.all_homed; },
                    600000))
    return true;
  std::fprintf(stderr, "soak: homing did not finish\n");
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const config::ProfileLoad load = config::load_profile(o.profile);
  if (!load.ok()) {
    for (const auto& d : load.diagnostics.items()) std::fprintf(stderr, "%s\n", d.format().c_str());
    return 2;
  }
  const config::MachineProfile& profile = *load.profile;
  const auto dir = std::filesystem::temp_directory_path() / "opencnc-edm-soak";
  std::filesystem::create_directories(dir);
  const std::string program = (dir / "channel.ngc").string();
  std::ofstream(program) << kChannel;
  Diagnostics d;
  SimRig rig(profile, *features::machine_setup(profile, d));
  rig.step();
  if (!accepted(rig, Request::simple(CommandKind::MachineOn)) || !home_all(rig) ||
      !accepted(rig, Request::set_mode(Mode::Auto)))
    return 1;
  const auto hour_ticks = static_cast<std::uint64_t>(std::llround(3600.0 / profile.servo_period_s));
  const auto end_tick = static_cast<std::uint64_t>(std::llround(o.hours * 3600.0 / profile.servo_period_s));
  auto first = std::make_unique<Histogram>(), now = std::make_unique<Histogram>();
  Result r;
  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t tick = 0, hour_end = hour_ticks;
  while (tick < end_tick) {
    rig.machine().new_edm_workpiece();
    if (!accepted(rig, Request::open(program)) || !accepted(rig, Request::simple(CommandKind::CycleStart))) {
      std::fprintf(stderr, "soak: the channel program did not start\n");
      return 1;
    }
    for (;;) {
      rig.controller().service();
      timespec a{}, b{};
      clock_gettime(CLOCK_MONOTONIC, &a);
      rig.servo().tick();
      clock_gettime(CLOCK_MONOTONIC, &b);
      now->add((b.tv_sec - a.tv_sec) * 1'000'000'000LL + (b.tv_nsec - a.tv_nsec));
      if (++tick == hour_end) {
        r.rss_hourly.push_back(rss_mb().first);
        r.heap_hourly.push_back(heap_in_use_mb());
        if (hour_end == hour_ticks) {
          std::tie(r.rss_first, r.hwm_first) = rss_mb();
          r.heap_first = heap_in_use_mb();
          std::swap(first, now);
        }
        if (tick < end_tick) now = std::make_unique<Histogram>();  // the last hour's own
        hour_end += hour_ticks;
      }
      const ControllerStatus st = rig.status();
      if (!st.run_active && st.servo.state == State::Idle && st.servo.activity == Activity::None) break;
      if (st.servo.state == State::Faulted || st.servo.state == State::EStopped) {
        std::fprintf(stderr, "soak: the machine faulted at %.3f s\n", st.servo.time_s);
        return 1;
      }
    }
    const ServoStatus s = rig.status().servo;
    if (rig.status().runs_finished != r.channels + 1) {
      std::fprintf(stderr, "soak: channel %llu ended without finishing (%s) at %.3f s\n",
                   static_cast<unsigned long long>(r.channels + 1), rig.status().wait_text.c_str(), s.time_s);
      return 1;
    }
    ++r.channels;
    if (std::getenv("SOAK_VERBOSE") != nullptr)
      std::fprintf(stderr, "channel %llu ended at %.1f s, %u jumps, at X%.4f Z%.4f B%.3f, heap %.3f MiB, wait %s\n",
                   static_cast<unsigned long long>(r.channels), s.time_s, s.edm.jumps, s.actual[Axis::X],
                   s.actual[Axis::Z], s.actual[Axis::B], heap_in_use_mb(), rig.status().wait_text.c_str());
    r.jumps = s.edm.jumps;
    if (r.channels == 1) {
      r.first_rest = s.actual;
      for (Axis a : {Axis::X, Axis::Y, Axis::Z})
        r.rest_um = std::max(r.rest_um, 1000 * std::fabs(s.actual[a]));
      for (Axis a : {Axis::B, Axis::C}) r.rest_mdeg = std::max(r.rest_mdeg, 1000 * std::fabs(s.actual[a]));
    }
    for (Axis a : {Axis::X, Axis::Y, Axis::Z})
      r.drift_um = std::max(r.drift_um, 1000 * std::fabs(s.actual[a] - r.first_rest[a]));
    for (Axis a : {Axis::B, Axis::C})
      r.drift_mdeg = std::max(r.drift_mdeg, 1000 * std::fabs(s.actual[a] - r.first_rest[a]));
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::tie(r.rss_last, r.hwm_last) = rss_mb();
  r.heap_last = heap_in_use_mb();
  if (r.hwm_first == 0) {
    std::tie(r.rss_first, r.hwm_first) = std::pair{r.rss_last, r.hwm_last};
    r.heap_first = r.heap_last;
  }
  if (first->count == 0) std::swap(first, now);  // under an hour: one window
  r.p99_first = first->p99();
  r.p99_last = now->count > 0 ? now->p99() : r.p99_first;
  r.ticks = tick;
  const double hours = static_cast<double>(tick) * profile.servo_period_s / 3600.0;
  if (o.json) {
    fmt::print(
        "{{\"hours\": {:.4f}, \"wall_s\": {:.1f}, \"rss_mb_first_hour\": {:.1f}, \"rss_mb_last_hour\": "
        "{:.1f}, "
        "\"peak_rss_mb_first_hour\": {:.1f}, \"peak_rss_mb_last_hour\": {:.1f}, \"tick_ns_p99_first_hour\": "
        "{:.0f}, "
        "\"tick_ns_p99_last_hour\": {:.0f}, \"position_drift_um\": {:.3f}, \"position_drift_mdeg\": {:.3f}, "
        "\"rest_from_program_um\": {:.3f}, \"rest_from_program_mdeg\": {:.3f}, "
        "\"heap_mb_first_hour\": {:.3f}, \"heap_mb_last_hour\": {:.3f}, \"channels\": {}, \"jumps\": {}, "
        "\"rss_mb_hourly\": [{:.2f}], \"heap_mb_hourly\": [{:.3f}]}}\n",
        hours, r.wall_s, r.rss_first, r.rss_last, r.hwm_first, r.hwm_last, r.p99_first, r.p99_last,
        r.drift_um, r.drift_mdeg, r.rest_um, r.rest_mdeg, r.heap_first, r.heap_last, r.channels, r.jumps,
        fmt::join(r.rss_hourly, ", "), fmt::join(r.heap_hourly, ", "));
  } else {
    fmt::print("soak: {:.3f} h of machining ({} channels, {} jumps) in {:.1f} s\n", hours, r.channels,
               r.jumps, r.wall_s);
    fmt::print(
        "  resident memory  {:.1f} MiB after the first hour, {:.1f} MiB at the end (peak {:.1f} → {:.1f})\n",
        r.rss_first, r.rss_last, r.hwm_first, r.hwm_last);
    fmt::print("  heap in use      {:.3f} MiB after the first hour, {:.3f} MiB at the end\n", r.heap_first,
               r.heap_last);
    fmt::print("  servo tick p99   {:.0f} ns in the first hour, {:.0f} ns in the last\n", r.p99_first,
               r.p99_last);
    fmt::print(
        "  rest position    {:.3f} µm, {:.3f} millidegrees from the program (homed steppers: up to half a "
        "step); drift from the first channel's {:.3f} µm, {:.3f} millidegrees\n",
        r.rest_um, r.rest_mdeg, r.drift_um, r.drift_mdeg);
  }
  std::filesystem::remove_all(dir);
  return 0;
}
