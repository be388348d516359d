// SPDX-License-Identifier: GPL-3.0-or-later
// Publishing to a real mosquitto broker on loopback: every sequence number once, the retained
// device and state, a broker killed and restarted, a bounded queue that says what it dropped, the
// last will of a killed machine.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "mqtt_rig.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/mqtt_publisher.hpp"

namespace opencnc::connect {
namespace {

using namespace std::chrono_literals;
using test::Broker;
using test::eventually;
using test::moving_status;
using test::Subscriber;

config::MachineProfile mill() {
  return *config::load_profile(std::filesystem::path(OPENCNC_SOURCE_DIR) / "configs/mill-3axis.toml").profile;
}

std::unique_ptr<Agent> machine(const std::string& name) {
  AgentOptions o;
  o.device_name = name;
  return Agent::for_profile(mill(), o);
}

MqttOptions to(const Broker& b) {
  MqttOptions o;
  o.broker = MqttAddress{"127.0.0.1", b.port()};
  o.poll_ms = 10;
  return o;
}

/// Sequences in [from, to) missing from `seen`, and those seen more than once.
std::pair<std::uint64_t, std::uint64_t> missing_and_twice(const std::multiset<std::uint64_t>& seen,
                                                          std::uint64_t from, std::uint64_t to) {
  std::uint64_t missing = 0, twice = 0;
  for (std::uint64_t s = from; s < to; ++s) {
    const auto n = seen.count(s);
    missing += n == 0;
    twice += n > 1;
  }
  return {missing, twice};
}

TEST(MqttUrl, IsParsedOrRefusedWithTheReason) {
  std::string why;
  auto a = parse_mqtt_url("mqtt://broker.local:1884", &why);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->host, "broker.local");
  EXPECT_EQ(a->port, 1884);
  EXPECT_EQ(parse_mqtt_url("mqtt://10.0.0.2", &why)->port, 1883);
  EXPECT_EQ(parse_mqtt_url("mqtt://[::1]:1999/", &why)->host, "::1");
  EXPECT_FALSE(parse_mqtt_url("http://x:1", &why));
  EXPECT_NE(why.find("mqtt://HOST"), std::string::npos);
  EXPECT_FALSE(parse_mqtt_url("mqtt://x:0", &why));
  EXPECT_FALSE(parse_mqtt_url("mqtt://x:70000", &why));
  EXPECT_FALSE(parse_mqtt_url("mqtt://:1883", &why));
  EXPECT_FALSE(parse_mqtt_url("mqtt://x:", &why));
}

TEST(Mqtt, EverySequenceArrivesOnceWithTheDeviceAndItsStateRetained) {
  Broker broker;
  Subscriber sub(broker.port());
  ASSERT_TRUE(eventually([&] { return sub.subscribed(); }));
  std::vector<std::unique_ptr<Agent>> agents;
  std::vector<std::unique_ptr<MqttPublisher>> pubs;
  std::vector<std::uint64_t> first;
  for (int m = 0; m < 3; ++m) {
    agents.push_back(machine(fmt::format("mill-{}", m)));
    first.push_back(agents.back()->next_sequence());
    pubs.push_back(std::make_unique<MqttPublisher>(*agents.back(), to(broker)));
    pubs.back()->start();
  }
  for (std::uint64_t i = 0; i < 300; ++i) {
    for (auto& a : agents) a->observe(moving_status(i), static_cast<std::int64_t>(i) * 2000);
    std::this_thread::sleep_for(2ms);
  }
  for (auto& p : pubs) p->stop(5000);
  for (int m = 0; m < 3; ++m) {
    const std::string uuid = agents[static_cast<std::size_t>(m)]->model().uuid();
    const std::uint64_t next = agents[static_cast<std::size_t>(m)]->next_sequence();
    ASSERT_TRUE(eventually([&] {
      return sub.devices()[uuid].sequences.size() >= next - first[static_cast<std::size_t>(m)];
    })) << uuid;
    const auto d = sub.devices()[uuid];
    const auto [missing, twice] = missing_and_twice(d.sequences, first[static_cast<std::size_t>(m)], next);
    EXPECT_EQ(missing, 0u) << uuid;
    EXPECT_EQ(twice, 0u) << uuid;
    EXPECT_GT(next - first[static_cast<std::size_t>(m)],
              900u);  // several items changed in each of 300 samples
    EXPECT_TRUE(d.probe);
    EXPECT_TRUE(d.current);
    ASSERT_FALSE(d.availability.empty());
    EXPECT_EQ(d.availability.front(), "AVAILABLE");
    EXPECT_EQ(d.availability.back(), "UNAVAILABLE");  // a clean stop says so itself
    EXPECT_TRUE(d.gaps.empty());
    EXPECT_EQ(pubs[static_cast<std::size_t>(m)]->stats().dropped, 0u);
  }
  // A subscriber that comes later finds each machine's device and state retained.
  Subscriber late(broker.port());
  EXPECT_TRUE(eventually([&] {
    auto d = late.devices();
    return d.size() == 3 && std::all_of(d.begin(), d.end(),
                                        [](const auto& kv) { return kv.second.probe && kv.second.current; });
  }));
}

TEST(Mqtt, AMachineReconnectsAfterTheBrokerRestartsAndLosesNothingPublishedAfterIt) {
  Broker broker;
  auto sub = std::make_unique<Subscriber>(broker.port());
  ASSERT_TRUE(eventually([&] { return sub->subscribed(); }));
  auto agent = machine("mill-r");
  MqttOptions o = to(broker);
  o.reconnect_min_ms = 1500;  // the new subscriber is in place before the machine is back
  MqttPublisher pub(*agent, o);
  const std::uint64_t first = agent->next_sequence();
  pub.start();
  std::uint64_t i = 0;
  auto run = [&](int n) {
    for (int k = 0; k < n; ++k, ++i) {
      agent->observe(moving_status(i), static_cast<std::int64_t>(i) * 2000);
      std::this_thread::sleep_for(2ms);
    }
  };
  run(150);
  ASSERT_TRUE(eventually([&] { return pub.stats().queued == 0; }));
  // What the broker acknowledged reached the subscriber, once (a kill loses what it had not yet
  // passed on: the broker keeps no persistence here, as a restarted one without it would not).
  const std::uint64_t before_kill = agent->next_sequence();
  ASSERT_TRUE(eventually(
      [&] { return sub->devices()[agent->model().uuid()].sequences.size() >= before_kill - first; }));
  broker.kill();
  const std::uint64_t at_kill = agent->next_sequence();
  run(150);  // queued while the broker is away
  EXPECT_TRUE(eventually([&] { return !pub.stats().connected; }));
  const auto before = sub->devices()[agent->model().uuid()];
  sub.reset();
  ASSERT_TRUE(broker.start());
  Subscriber after(broker.port());
  ASSERT_TRUE(eventually([&] { return after.subscribed(); }));
  ASSERT_FALSE(pub.stats().connected);  // its back-off lets the new subscriber in first
  run(150);
  pub.stop(10000);
  const std::uint64_t next = agent->next_sequence();
  const MqttStats st = pub.stats();
  EXPECT_EQ(st.connects, 2u);
  EXPECT_EQ(st.dropped, 0u);
  // Everything from the kill on reaches the new subscriber, once (the broker may still be passing
  // the last batches on when the publisher stops).
  ASSERT_TRUE(eventually([&] {
    const auto seen = after.devices()[agent->model().uuid()].sequences;
    return missing_and_twice(seen, at_kill, next).first == 0;
  }));
  const auto d = after.devices()[agent->model().uuid()];
  const auto [missing, twice] = missing_and_twice(d.sequences, at_kill, next);
  EXPECT_EQ(missing, 0u);
  EXPECT_EQ(twice, 0u);
  const auto [lost, dup] = missing_and_twice(before.sequences, first, before_kill);
  EXPECT_EQ(lost, 0u);
  EXPECT_EQ(dup, 0u);
}

TEST(Mqtt, WhileTheBrokerIsAwayTheQueueIsBoundedAndTheLossIsPublished) {
  Broker broker(false);
  auto agent = machine("mill-q");
  MqttOptions o = to(broker);
  o.queue_limit = 100;
  o.batch_size = 10;
  o.reconnect_min_ms = o.reconnect_max_ms = 1000;  // the subscriber is in before the machine
  const std::uint64_t first = agent->next_sequence();
  MqttPublisher pub(*agent, o);
  pub.start();
  for (std::uint64_t i = 0; i < 200; ++i) {
    agent->observe(moving_status(i), static_cast<std::int64_t>(i) * 2000);
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE(eventually([&] { return pub.stats().next_sequence == agent->next_sequence(); }));
  const MqttStats away = pub.stats();
  EXPECT_LE(away.queued, 100u);
  EXPECT_GT(away.dropped, 0u);
  EXPECT_EQ(away.dropped + away.queued, agent->next_sequence() - first);
  ASSERT_TRUE(broker.start());
  Subscriber sub(broker.port());
  ASSERT_TRUE(eventually([&] { return sub.subscribed(); }));
  ASSERT_FALSE(pub.stats().connected);
  // The first batch to arrive carries the gap: the dropped observations' range and count.
  ASSERT_TRUE(eventually([&] { return pub.stats().queued == 0 && pub.stats().connected; }));
  pub.stop(2000);
  const auto d = sub.devices()[agent->model().uuid()];
  std::uint64_t reported = 0;
  for (const auto& g : d.gaps) reported += g["count"].get<std::uint64_t>();
  EXPECT_EQ(reported, away.dropped);
  ASSERT_EQ(d.gaps.size(), 1u);
  EXPECT_EQ(d.gaps[0]["from"].get<std::uint64_t>(), first);
  EXPECT_EQ(d.gaps[0]["to"].get<std::uint64_t>(), first + away.dropped - 1);
  EXPECT_EQ(d.sequences.size(), away.queued);
  EXPECT_EQ(*d.sequences.begin(), first + away.dropped);
}

TEST(Mqtt, AKilledMachineIsUnavailableWithinItsKeepAlive) {
  Broker broker;
  Subscriber sub(broker.port());
  ASSERT_TRUE(eventually([&] { return sub.subscribed(); }));
  test::MachineProcess machine_k("configs/mill-3axis.toml", "mill-k", broker.port(), 5);
  ASSERT_TRUE(machine_k.running());
  const std::string uuid = "opencnc-mill-k";
  ASSERT_TRUE(eventually([&] {
    auto d = sub.devices()[uuid];
    return !d.availability.empty() && d.availability.back() == "AVAILABLE" && d.sequences.size() > 50;
  }));
  machine_k.kill();
  const auto killed = std::chrono::steady_clock::now();
  ASSERT_TRUE(eventually([&] { return sub.devices()[uuid].availability.back() == "UNAVAILABLE"; }, 12s));
  const auto seen = sub.devices()[uuid].unavailable_at - killed;
  // The broker gives up on a silent client after 1.5 keep-alives (7.5 s here); it checks each second.
  EXPECT_LE(std::chrono::duration_cast<std::chrono::milliseconds>(seen).count(), 8500);
  RecordProperty("unavailable_after_ms",
                 static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(seen).count()));
}

}  // namespace
}  // namespace opencnc::connect
