// SPDX-License-Identifier: GPL-3.0-or-later
// fleet_mqtt_bench: N machines publish to one real mosquitto on loopback for M minutes of virtual
// time (their status sampled at --hz, run --speed times faster than real time); halfway the broker
// is killed (SIGKILL, no persistence) and started again after --down-s. A subscriber on the broker
// collects every sample's sequence number. Prints, over all machines: observations published,
// received once, twice, missing — and of the missing, those the publishers reported as a gap
// (their queue, bounded by --queue, overflowed while the broker was away), those the killed broker
// had acknowledged but not passed on (it keeps nothing: no persistence), and those lost after the
// restart (must be 0); and that every machine reconnected.
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "mqtt_rig.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/mqtt_publisher.hpp"

namespace {

using namespace opencnc;
using namespace std::chrono_literals;
using connect::test::eventually;

int usage() {
  std::fprintf(stderr,
               "usage: fleet_mqtt_bench [--machines 20] [--minutes 10] [--hz 10] [--speed 20] [--down-s 3]\n"
               "                        [--queue 2000] [--no-restart]\n");
  return 2;
}

struct Machine {
  std::unique_ptr<connect::Agent> agent;
  std::unique_ptr<connect::MqttPublisher> pub;
  std::uint64_t first = 0, at_kill = 0, at_restart = 0;
};

}  // namespace

int main(int argc, char** argv) {
  int machines = 20, hz = 10, speed = 20;
  double minutes = 10, down_s = 3;
  std::size_t queue = 2000;
  bool restart = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") return usage(), 0;
    if (a == "--no-restart") {
      restart = false;
      continue;
    }
    if (i + 1 >= argc) return usage();
    const char* v = argv[++i];
    if (a == "--machines")
      machines = std::atoi(v);
    else if (a == "--minutes")
      minutes = std::atof(v);
    else if (a == "--hz")
      hz = std::atoi(v);
    else if (a == "--speed")
      speed = std::atoi(v);
    else if (a == "--down-s")
      down_s = std::atof(v);
    else if (a == "--queue")
      queue = static_cast<std::size_t>(std::atol(v));
    else
      return usage();
  }
  if (machines < 1 || hz < 1 || speed < 1 || minutes <= 0 || queue < 1) return usage();
  const auto load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml");
  if (!load.ok()) return 1;

  connect::test::Broker broker;
  auto sub = std::make_unique<connect::test::Subscriber>(broker.port());
  if (!eventually([&] { return sub->subscribed(); }, 10s))
    return std::fprintf(stderr, "no subscription\n"), 1;
  std::vector<Machine> fleet(static_cast<std::size_t>(machines));
  for (int m = 0; m < machines; ++m) {
    Machine& x = fleet[static_cast<std::size_t>(m)];
    connect::AgentOptions ao;
    ao.device_name = fmt::format("mill-{:02}", m + 1);
    ao.buffer_size = 1 << 20;  // the publisher's own queue is the bound measured here, not the agent's
    x.agent = connect::Agent::for_profile(*load.profile, ao);
    connect::MqttOptions mo;
    mo.broker = connect::MqttAddress{"127.0.0.1", broker.port()};
    mo.queue_limit = queue;
    // The first retry after the kill comes after the broker is back and the subscriber in place
    // (a broker without persistence keeps nothing for a subscriber that is not there yet).
    mo.reconnect_min_ms = static_cast<int>(down_s * 1000) / 2;
    x.first = x.agent->next_sequence();
    x.pub = std::make_unique<connect::MqttPublisher>(*x.agent, mo);
    x.pub->start();
  }

  // Virtual time: sample k at k/hz s; paced at `speed` times real time.
  const std::uint64_t samples = static_cast<std::uint64_t>(minutes * 60 * hz);
  const auto t0 = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point killed{}, restarted{};
  auto at_virtual = [&](double s) {
    return t0 +
           std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s / speed));
  };
  // What the first subscriber received, kept when the broker dies (it would reconnect to the new
  // one and count what the second one receives twice).
  std::map<std::string, connect::test::Subscriber::Device> devices_before;
  std::unique_ptr<connect::test::Subscriber> after;
  for (std::uint64_t k = 0; k < samples; ++k) {
    const double v = static_cast<double>(k) / hz;
    std::this_thread::sleep_until(at_virtual(v));
    if (restart && k == samples / 2) {
      for (auto& x : fleet) x.at_kill = x.agent->next_sequence();
      broker.kill();
      killed = std::chrono::steady_clock::now();
      devices_before = sub->devices();
      sub.reset();
    }
    if (restart && killed != std::chrono::steady_clock::time_point{} &&
        restarted == std::chrono::steady_clock::time_point{} &&
        std::chrono::steady_clock::now() - killed >= std::chrono::duration<double>(down_s)) {
      if (!broker.start()) return std::fprintf(stderr, "the broker did not start again\n"), 1;
      after = std::make_unique<connect::test::Subscriber>(broker.port());
      if (!eventually([&] { return after->subscribed(); }, 10s))
        return std::fprintf(stderr, "no subscription\n"), 1;
      restarted = std::chrono::steady_clock::now();
      for (auto& x : fleet) x.at_restart = x.agent->next_sequence();
    }
    for (std::size_t m = 0; m < fleet.size(); ++m)
      fleet[m].agent->observe(connect::test::moving_status(k + 7 * m), static_cast<std::int64_t>(v * 1e6));
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (auto& x : fleet) x.pub->stop(30000);
  connect::test::Subscriber& last = after ? *after : *sub;
  // The broker may still be passing the last batches on.
  std::uint64_t expected = 0;
  for (auto& x : fleet) expected += x.agent->next_sequence() - (after ? x.at_restart : x.first);
  eventually(
      [&] {
        std::uint64_t n = 0;
        for (const auto& [uuid, d] : last.devices()) n += d.sequences.size();
        return n >= expected;
      },
      30s);
  std::this_thread::sleep_for(1s);  // and what was still on its way

  std::uint64_t published = 0, once = 0, twice = 0, missing = 0, in_gaps = 0, lost_in_broker = 0,
                lost_after_restart = 0, reported_gap = 0, dropped = 0, not_reconnected = 0;
  if (!restart) devices_before = sub->devices();
  const auto& received_before = devices_before;
  const auto devices_after = after ? after->devices() : decltype(devices_before){};
  for (auto& x : fleet) {
    const std::string& uuid = x.agent->model().uuid();
    const connect::MqttStats st = x.pub->stats();
    dropped += st.dropped;
    if (restart && st.connects < 2) ++not_reconnected;
    std::multiset<std::uint64_t> seen;
    std::vector<nlohmann::json> gaps;
    for (const auto* devs : {&received_before, &devices_after}) {
      const auto it = devs->find(uuid);
      if (it == devs->end()) continue;
      seen.insert(it->second.sequences.begin(), it->second.sequences.end());
      gaps.insert(gaps.end(), it->second.gaps.begin(), it->second.gaps.end());
    }
    auto reported = [&](std::uint64_t s) {
      for (const auto& g : gaps)
        if (s >= g["from"].get<std::uint64_t>() && s <= g["to"].get<std::uint64_t>()) return true;
      return false;
    };
    for (const auto& g : gaps) reported_gap += g["count"].get<std::uint64_t>();
    const std::uint64_t next = x.agent->next_sequence();
    for (std::uint64_t s = x.first; s < next; ++s) {
      ++published;
      const auto n = seen.count(s);
      once += n == 1;
      twice += n > 1;
      if (n > 0) continue;
      ++missing;
      if (reported(s))
        ++in_gaps;
      else if (restart && s < x.at_kill)
        ++lost_in_broker;
      else
        ++lost_after_restart;
    }
  }
  std::printf("%d machines, %.1f min of virtual time at %d Hz in %.1f s (%.0fx real time); broker %s\n",
              machines, minutes, hz, wall, minutes * 60 / wall,
              restart ? fmt::format("killed at {:.1f} s and back {:.1f} s later",
                                    std::chrono::duration<double>(killed - t0).count(),
                                    std::chrono::duration<double>(restarted - killed).count())
                            .c_str()
                      : "up throughout");
  std::printf("observations published %llu: received once %llu, twice %llu, missing %llu\n",
              static_cast<unsigned long long>(published), static_cast<unsigned long long>(once),
              static_cast<unsigned long long>(twice), static_cast<unsigned long long>(missing));
  std::printf(
      "  missing and reported as a gap (queue of %zu overflowed): %llu (gaps reported: %llu, publishers' "
      "drops: %llu)\n",
      queue, static_cast<unsigned long long>(in_gaps), static_cast<unsigned long long>(reported_gap),
      static_cast<unsigned long long>(dropped));
  std::printf("  missing, acknowledged by the killed broker before it passed them on: %llu\n",
              static_cast<unsigned long long>(lost_in_broker));
  std::printf("  missing otherwise (after the restart, or unexplained): %llu\n",
              static_cast<unsigned long long>(lost_after_restart));
  if (restart)
    std::printf("machines that did not reconnect: %llu\n", static_cast<unsigned long long>(not_reconnected));
  const bool ok = lost_after_restart == 0 && not_reconnected == 0 && in_gaps == reported_gap &&
                  (restart || (missing == 0 && twice == 0));
  std::printf("%s\n", ok ? "PASS" : "FAIL");
  return ok ? 0 : 1;
}
