// SPDX-License-Identifier: GPL-3.0-or-later
// The fleet view's model: the machines' own MQTT payloads read back into rows (values found by
// their MTConnect types, alarms, progress, the HMI's address), samples sent twice ignored, gaps
// and restarts told apart; then against a real mosquitto with machines publishing, one of them
// killed; and the fleet server's answers.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>

#include "mqtt_rig.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/fleet.hpp"
#include "opencnc/connect/mqtt_publisher.hpp"
#include "opencnc/hmi/fleet_server.hpp"

namespace opencnc::connect {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;
using test::eventually;

config::MachineProfile profile(const char* name = "mill-3axis") {
  return *config::load_profile(std::filesystem::path(OPENCNC_SOURCE_DIR) / "configs" /
                               (std::string(name) + ".toml"))
              .profile;
}

std::unique_ptr<Agent> machine(const std::string& name, std::uint64_t instance = 1) {
  AgentOptions o;
  o.device_name = name;
  o.instance_id = instance;
  return Agent::for_profile(profile(), o);
}

std::string topic(const Agent& a, const char* kind) {
  return mqtt_topic("MTConnect", kind, a.model().uuid());
}

/// The machine's device and current state, as its publisher writes them at a connection.
void introduce(Fleet& fleet, const Agent& a, std::int64_t now_ms, const std::string& hmi = {}) {
  fleet.take(topic(a, "Probe"), probe_json(a.model(), a.options(), hmi), now_ms);
  fleet.take(topic(a, "Availability"), "AVAILABLE", now_ms);
  std::uint64_t next = 0;
  const auto snap = a.snapshot(&next);
  fleet.take(topic(a, "Current"), current_json(a.model(), a.options(), snap, next, a.progress()), now_ms);
}

/// The agent's observations from `from` on as one Sample message.
std::string sample(const Agent& a, std::uint64_t from, Gap gap = {}) {
  const auto obs = a.observations(from, 100000);
  return sample_json(a.model(), a.options(), obs, gap, gap.count);
}

/// The row of `name` (a copy: the list is a temporary).
FleetMachine row(const std::vector<FleetMachine>& rows, const std::string& name) {
  for (const auto& r : rows)
    if (r.name == name) return r;
  throw std::runtime_error("no row " + name);
}

TEST(Fleet, AMachineIsReadFromItsOwnTopics) {
  auto a = machine("mill-7");
  controller::ControllerStatus st = test::moving_status(60);  // Auto, running
  st.program_name = "/parts/bracket.ngc";
  st.progress = 0.25;
  a->observe(st, 1'000'000);
  Fleet fleet;
  introduce(fleet, *a, 5000, "http://10.0.0.7:8080/");
  const FleetMachine m = row(fleet.machines(), "mill-7");
  EXPECT_EQ(m.uuid, "opencnc-mill-7");
  EXPECT_EQ(m.hmi, "http://10.0.0.7:8080/");
  EXPECT_EQ(m.availability, "AVAILABLE");
  EXPECT_EQ(m.execution, "ACTIVE");
  EXPECT_EQ(m.mode, "AUTOMATIC");
  EXPECT_EQ(m.program, "/parts/bracket.ngc");
  EXPECT_EQ(m.emergency_stop, "ARMED");
  EXPECT_DOUBLE_EQ(m.progress, 0.25);
  EXPECT_EQ(m.spindle_load, "UNAVAILABLE");  // MachineIO carries no drive load yet
  EXPECT_EQ(m.last_seen_ms, 5000);
  EXPECT_TRUE(m.alarms.empty());

  // A fault arrives in a sample; then it clears.
  const std::uint64_t from = a->next_sequence();
  st.servo.fault = control::Fault{control::FaultKind::FollowingError, 1, 0.2, 0.1, 5};
  st.servo.state = control::State::Faulted;
  st.fault_text = "Y followed 0.2 mm behind";
  a->observe(st, 2'000'000);
  fleet.take(topic(*a, "Sample"), sample(*a, from), 6000);
  ASSERT_EQ(row(fleet.machines(), "mill-7").alarms.size(), 1u);
  const FleetAlarm alarm = row(fleet.machines(), "mill-7").alarms[0];
  EXPECT_EQ(alarm.level, "Fault");
  EXPECT_EQ(alarm.native_code, "control.fault.following-error");
  EXPECT_EQ(alarm.message, st.fault_text);
  EXPECT_EQ(row(fleet.machines(), "mill-7").execution, "STOPPED");
  const std::uint64_t from2 = a->next_sequence();
  st.servo.fault = {};
  st.servo.state = control::State::Idle;
  a->observe(st, 3'000'000);
  fleet.take(topic(*a, "Sample"), sample(*a, from2), 7000);
  EXPECT_TRUE(row(fleet.machines(), "mill-7").alarms.empty());
  EXPECT_EQ(row(fleet.machines(), "mill-7").execution, "READY");
  EXPECT_EQ(row(fleet.machines(), "mill-7").last_seen_ms, 7000);

  // The will: unavailable.
  fleet.take(topic(*a, "Availability"), "UNAVAILABLE", 8000);
  EXPECT_EQ(row(fleet.machines(), "mill-7").availability, "UNAVAILABLE");
}

TEST(Fleet, SamplesSentTwiceAreIgnoredGapsCountedAndARestartStartsAfresh) {
  auto a = machine("mill-1");
  Fleet fleet;
  introduce(fleet, *a, 1);
  const std::uint64_t from = a->next_sequence();
  for (std::uint64_t i = 0; i < 30; ++i)
    a->observe(test::moving_status(i), static_cast<std::int64_t>(i) * 1000);
  const std::string batch = sample(*a, from);
  fleet.take(topic(*a, "Sample"), batch, 2);
  const std::uint64_t got = row(fleet.machines(), "mill-1").next_sequence;
  EXPECT_EQ(got, a->next_sequence());
  fleet.take(topic(*a, "Sample"), batch, 3);  // again, after a lost PUBACK
  EXPECT_EQ(row(fleet.machines(), "mill-1").next_sequence, got);
  EXPECT_EQ(row(fleet.machines(), "mill-1").duplicates, json::parse(batch)["observations"].size());
  // A gap reported by the publisher.
  const std::uint64_t from2 = a->next_sequence();
  a->observe(test::moving_status(99), 99'000);
  fleet.take(topic(*a, "Sample"), sample(*a, from2, Gap{got, got, 1}), 4);
  EXPECT_EQ(row(fleet.machines(), "mill-1").gaps, 1u);
  EXPECT_EQ(row(fleet.machines(), "mill-1").gap_observations, 1u);

  // The machine restarts: a new instance whose sequences begin again at 1.
  auto again = machine("mill-1", 2);
  again->observe(test::moving_status(0), 0);
  introduce(fleet, *again, 5);
  EXPECT_EQ(row(fleet.machines(), "mill-1").instance_id, 2u);
  EXPECT_EQ(row(fleet.machines(), "mill-1").next_sequence, again->next_sequence());
  EXPECT_EQ(row(fleet.machines(), "mill-1").mode, "MANUAL_DATA_INPUT");
}

TEST(Fleet, PayloadsThatAreNotTheTopicsAreCountedAndOtherTopicsIgnored) {
  Fleet fleet;
  EXPECT_TRUE(fleet.take("sensors/temp", "{}", 1));
  EXPECT_TRUE(fleet.take("MTConnect/Other/x", "{}", 1));
  EXPECT_TRUE(fleet.take("MTConnect/Probe/a/b", "{}", 1));
  EXPECT_TRUE(fleet.machines().empty());
  EXPECT_FALSE(fleet.take("MTConnect/Probe/m", "not json", 1));
  EXPECT_FALSE(fleet.take("MTConnect/Sample/m", R"({"observations":[{"sequence":"x"}]})", 1));
  EXPECT_FALSE(fleet.take("MTConnect/Availability/m", "MAYBE", 1));
  EXPECT_EQ(fleet.malformed(), 3u);
  EXPECT_TRUE(fleet.take("MTConnect/Current/m", "", 1));  // a retained message cleared
  const json j = json::parse(fleet.json(42));
  EXPECT_EQ(j["malformed"], 3);
  EXPECT_EQ(j["now"], 42);
}

/// GET (or another method) on the fleet server: status and body.
std::pair<int, std::string> http_get(int port, const std::string& target,
                                     boost::beast::http::verb verb = boost::beast::http::verb::get) {
  namespace http = boost::beast::http;
  boost::asio::io_context io;
  boost::beast::tcp_stream s(io);
  s.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"),
                                           static_cast<unsigned short>(port)));
  http::request<http::string_body> req{verb, target, 11};
  req.set(http::field::host, "127.0.0.1");
  http::write(s, req);
  boost::beast::flat_buffer b;
  http::response<http::string_body> res;
  http::read(s, b, res);
  return {static_cast<int>(res.result_int()), res.body()};
}

TEST(FleetWatcher, SeesEveryMachineOfTheBrokerAndAKilledOneTurnsUnavailable) {
  test::Broker broker;
  // One machine in this process, one in a process of its own to be killed.
  auto a = machine("cell-a");
  MqttOptions mo;
  mo.broker = MqttAddress{"127.0.0.1", broker.port()};
  mo.poll_ms = 10;
  mo.hmi_url = "http://127.0.0.1:8081/";
  MqttPublisher pub(*a, mo);
  pub.start();
  test::MachineProcess other("configs/mill-3axis.toml", "cell-b", broker.port(), 5);
  ASSERT_TRUE(other.running());

  FleetOptions fo;
  fo.broker = MqttAddress{"127.0.0.1", broker.port()};
  FleetWatcher watcher(fo);
  watcher.start();
  std::uint64_t i = 0;
  auto both = [&] {
    const std::uint64_t k = i++;
    a->observe(test::moving_status(k), static_cast<std::int64_t>(k) * 1000);
    const auto rows = watcher.machines();
    return rows.size() == 2 && rows[0].availability == "AVAILABLE" && rows[1].availability == "AVAILABLE" &&
           rows[0].execution == "ACTIVE" && rows[1].execution == "ACTIVE";
  };
  ASSERT_TRUE(eventually(both)) << watcher.json();
  EXPECT_TRUE(watcher.connected());
  EXPECT_EQ(row(watcher.machines(), "cell-a").hmi, "http://127.0.0.1:8081/");

  // The fleet server answers with the same rows, and serves its page.
  const auto page_dir = std::filesystem::temp_directory_path() / fmt::format("opencnc-fleet-{}", ::getpid());
  std::filesystem::create_directories(page_dir);
  std::ofstream(page_dir / "fleet.html") << "<!doctype html><title>fleet</title>";
  hmi::FleetServer server(watcher, hmi::FleetServerConfig{"127.0.0.1", 0, page_dir});
  std::string why;
  ASSERT_TRUE(server.start(&why)) << why;
  const auto [status, body] = http_get(server.port(), "/api/v1/fleet");
  EXPECT_EQ(status, 200);
  const json j = json::parse(body);
  EXPECT_EQ(j["machines"].size(), 2u);
  EXPECT_EQ(j["broker"]["connected"], true);
  EXPECT_EQ(http_get(server.port(), "/").second, "<!doctype html><title>fleet</title>");
  EXPECT_EQ(http_get(server.port(), "/../secret").first, 404);
  EXPECT_EQ(http_get(server.port(), "/api/v1/other").first, 404);
  EXPECT_EQ(http_get(server.port(), "/api/v1/fleet", boost::beast::http::verb::post).first, 405);

  // Killed: the broker sends its will, the row turns UNAVAILABLE.
  const auto killed = std::chrono::steady_clock::now();
  other.kill();
  ASSERT_TRUE(
      eventually([&] { return row(watcher.machines(), "cell-b").availability == "UNAVAILABLE"; }, 15s));
  const auto after =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - killed);
  EXPECT_LT(after, 7500ms);  // within 1.5 keep-alives of 5 s
  EXPECT_EQ(row(watcher.machines(), "cell-a").availability, "AVAILABLE");
  server.stop();
  pub.stop(500);
  std::filesystem::remove_all(page_dir);
}

}  // namespace
}  // namespace opencnc::connect
