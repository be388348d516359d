// SPDX-License-Identifier: GPL-3.0-or-later
// The SHDR adapter on loopback with real TCP clients standing in for a site's MTConnect agent: the
// snapshot on each connection equals the agent's current state, every change follows, PING is
// answered, conditions and awkward values are written as SHDR has them, and a client that reads
// nothing or stops pinging is dropped without holding up the others. The test reads SHDR with a
// parser of its own (it shares nothing with the adapter's writer).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <map>
#include <thread>

#include "mqtt_rig.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/json_messages.hpp"
#include "opencnc/connect/shdr_adapter.hpp"

namespace opencnc::connect {
namespace {

using namespace std::chrono_literals;
namespace asio = boost::asio;
using asio::ip::tcp;

std::unique_ptr<Agent> mill(const std::string& name = "mill-1") {
  AgentOptions o;
  o.device_name = name;
  return Agent::for_profile(
      *config::load_profile(std::filesystem::path(OPENCNC_SOURCE_DIR) / "configs/mill-3axis.toml").profile,
      o);
}

/// One SHDR field read back: a quoted one unescaped.
std::string unfield(std::string_view f) {
  if (f.size() < 2 || f.front() != '"' || f.back() != '"') return std::string(f);
  std::string out;
  for (std::size_t i = 1; i + 1 < f.size(); ++i) {
    if (f[i] == '\\' && i + 2 < f.size()) ++i;
    out += f[i];
  }
  return out;
}

/// A line split at the '|' that are not escaped inside quotes.
std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '\\' && i + 1 < line.size()) {
      out.back() += c;
      out.back() += line[++i];
    } else if (c == '"') {
      quoted = !quoted;
      out.back() += c;
    } else if (c == '|' && !quoted) {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

/// What a site's agent would hold: each item's value, or each condition item's active codes.
struct Seen {
  std::map<std::string, std::string> values;                        // id → value
  std::map<std::string, std::map<std::string, std::string>> conds;  // id → native code → LEVEL
  std::size_t lines = 0;
};

/// Reads lines into `seen` with the condition items of `model` told apart.
void apply(const DeviceModel& model, const std::string& line, Seen& seen) {
  if (line.empty() || line.front() == '*') return;
  const auto f = fields(line);
  ASSERT_GE(f.size(), 3u) << line;
  ++seen.lines;
  const auto item = model.find(f[1]);
  ASSERT_TRUE(item) << "an unknown key in: " << line;
  if (model.items()[*item].category == Category::Condition) {
    ASSERT_EQ(f.size(), 7u) << line;
    auto& active = seen.conds[f[1]];
    if (f[2] == "NORMAL" && f[3].empty())
      active.clear();
    else if (f[2] == "NORMAL" || f[2] == "UNAVAILABLE")
      active.erase(unfield(f[3]));
    else
      active[unfield(f[3])] = f[2];
    if (f[2] == "UNAVAILABLE") active.clear();
    return;
  }
  ASSERT_EQ(f.size() % 2, 1u) << line;
  for (std::size_t i = 1; i + 1 < f.size(); i += 2) {
    ASSERT_TRUE(model.find(f[i])) << f[i];
    seen.values[f[i]] = unfield(f[i + 1]);
  }
}

/// The agent's own current state in the same terms.
Seen expected(const Agent& agent) {
  Seen s;
  for (const Observation& o : agent.snapshot()) {
    const DataItem& item = agent.model().items()[o.item];
    if (item.category != Category::Condition)
      s.values[item.id] = o.value;
    else if (o.level == Level::Warning || o.level == Level::Fault)
      s.conds[item.id][o.native_code] = o.level == Level::Warning ? "WARNING" : "FAULT";
    else
      s.conds[item.id];
  }
  return s;
}

/// A TCP client reading lines with a deadline.
struct Client {
  explicit Client(int port) : socket(io) {
    socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  }
  /// The next line, or nullopt when none came within `limit` or the connection closed.
  std::optional<std::string> line(std::chrono::milliseconds limit = 5s) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (true) {
      if (const auto nl = buffer.find('\n'); nl != std::string::npos) {
        std::string l = buffer.substr(0, nl);
        buffer.erase(0, nl + 1);
        return l;
      }
      if (closed || std::chrono::steady_clock::now() > until) return std::nullopt;
      socket.non_blocking(true);
      char chunk[65536];
      boost::system::error_code ec;
      const std::size_t n = socket.read_some(asio::buffer(chunk), ec);
      if (ec == asio::error::would_block)
        std::this_thread::sleep_for(2ms);
      else if (ec)
        closed = true;
      else
        buffer.append(chunk, n);
    }
  }
  void send(const std::string& text) { asio::write(socket, asio::buffer(text)); }
  /// Lines until `done(seen)` or the deadline.
  template <typename F>
  bool read_until(const DeviceModel& model, Seen& seen, F done, std::chrono::milliseconds limit = 5s) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (!done(seen)) {
      const auto l = line(
          std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now()));
      if (!l) return false;
      apply(model, *l, seen);
    }
    return true;
  }
  asio::io_context io;
  tcp::socket socket;
  std::string buffer;
  bool closed = false;
};

ShdrOptions loopback() {
  ShdrOptions o;
  o.port = 0;
  o.poll_ms = 5;
  return o;
}

TEST(ShdrText, FieldsAreQuotedAndEscapedOnlyWhenTheyMustBe) {
  EXPECT_EQ(shdr_field("ACTIVE"), "ACTIVE");
  EXPECT_EQ(shdr_field("12.5 -3 0"), "12.5 -3 0");
  EXPECT_EQ(shdr_field("a|b"), R"("a\|b")");
  EXPECT_EQ(shdr_field(R"(say "hi")"), R"("say \"hi\"")");
  EXPECT_EQ(shdr_field("two\nlines"), R"("two lines")");
  EXPECT_EQ(unfield(shdr_field("x|\"y\"|z")), "x|\"y\"|z");
}

TEST(ShdrText, ValuesOfOneTimeShareALineAndEachConditionHasItsOwn) {
  auto agent = mill();
  const DeviceModel& m = agent->model();
  const auto x = *m.find("x_act"), exec = *m.find("execution"), sys = *m.find("system");
  std::vector<Observation> obs = {
      {1, 1000, static_cast<std::uint32_t>(x), Level::Unavailable, {}, "1.5"},
      {2, 1000, static_cast<std::uint32_t>(exec), Level::Unavailable, {}, "ACTIVE"},
      {3, 1000, static_cast<std::uint32_t>(sys), Level::Fault, "control.fault.x", "X|Y over"},
      {4, 1000, static_cast<std::uint32_t>(x), Level::Unavailable, {}, "1.6"},
      {5, 2000, static_cast<std::uint32_t>(x), Level::Unavailable, {}, "1.7"},
      {6, 2000, static_cast<std::uint32_t>(sys), Level::Normal, {}, {}},
  };
  const std::string t1 = iso_time(1000), t2 = iso_time(2000);
  EXPECT_EQ(shdr_lines(m, obs), fmt::format("{0}|x_act|1.5|execution|ACTIVE\n"
                                            "{0}|system|FAULT|control.fault.x|||\"X\\|Y over\"\n"
                                            "{0}|x_act|1.6\n"
                                            "{1}|x_act|1.7\n"
                                            "{1}|system|NORMAL||||\n",
                                            t1, t2));
}

TEST(Shdr, EachConnectionGetsTheWholeStateThenEveryChangeAndPingIsAnswered) {
  auto agent = mill();
  agent->observe(test::moving_status(1), 1'000'000);
  ShdrAdapter adapter(*agent, loopback());
  adapter.start();
  Client a(adapter.port());
  EXPECT_EQ(a.line(), "* adapterVersion: opencnc " OPENCNC_VERSION);
  EXPECT_EQ(a.line(), "* mtconnectVersion: 2.7");
  EXPECT_EQ(a.line(), "* device: " + agent->model().uuid());
  const Seen want = expected(*agent);
  Seen seen;
  ASSERT_TRUE(a.read_until(agent->model(), seen, [&](const Seen& s) {
    return s.values.size() + s.conds.size() == want.values.size() + want.conds.size();
  }));
  EXPECT_EQ(seen.values, want.values);
  EXPECT_EQ(seen.conds, want.conds);
  EXPECT_EQ(seen.values.at("avail"), "AVAILABLE");

  // A fault and a move: the changes follow, the condition on its own line.
  controller::ControllerStatus st = test::moving_status(2);
  st.servo.fault = control::Fault{control::FaultKind::FollowingError, 1, 0.2, 0.1, 5};
  st.fault_text = "Y followed | 0.2 mm behind";
  agent->observe(st, 2'000'000);
  const Seen now = expected(*agent);
  ASSERT_TRUE(a.read_until(agent->model(), seen, [&](const Seen& s) {
    return s.values == now.values && s.conds == now.conds;
  })) << seen.values.at("x_act");
  EXPECT_EQ(seen.values.at("x_act"), "0.0020");
  EXPECT_EQ(seen.conds.at("y_actuator").begin()->second, "FAULT");

  a.send("* PING\n");
  std::optional<std::string> l;
  while ((l = a.line()) && !l->starts_with("* PONG")) apply(agent->model(), *l, seen);
  EXPECT_EQ(l, "* PONG 10000");

  // A second agent connecting later starts from the state then, fault included.
  Client b(adapter.port());
  Seen late;
  ASSERT_TRUE(b.read_until(agent->model(), late, [&](const Seen& s) {
    return s.values.size() + s.conds.size() == want.values.size() + want.conds.size();
  }));
  EXPECT_EQ(late.values, expected(*agent).values);
  EXPECT_EQ(late.conds, expected(*agent).conds);
  EXPECT_EQ(adapter.stats().clients, 2u);
  EXPECT_EQ(adapter.stats().pongs, 1u);

  // The machine stops: every item UNAVAILABLE, on both connections.
  agent->mark_unavailable(3'000'000);
  for (Client* c : {&a, &b}) {
    Seen& s = c == &a ? seen : late;
    ASSERT_TRUE(c->read_until(agent->model(), s,
                              [](const Seen& x) { return x.values.at("avail") == "UNAVAILABLE"; }));
  }
  adapter.stop();
  while (a.line(1s)) {
  }
  EXPECT_TRUE(a.closed);  // the stop closed the connection
}

TEST(Shdr, AClientThatReadsNothingIsDroppedAndTheOthersGoOn) {
  auto agent = mill();
  ShdrOptions o = loopback();
  o.write_timeout_ms = 300;
  ShdrAdapter adapter(*agent, o);
  adapter.start();
  Client stalled(adapter.port());  // never reads
  Client reader(adapter.port());
  Seen seen;
  std::uint64_t i = 0;
  // The kernel's socket buffers take a few MB before a write waits: observe until the stalled
  // client is dropped, the reader reading all along.
  const auto until = std::chrono::steady_clock::now() + 60s;
  while (adapter.stats().dropped_slow == 0 && std::chrono::steady_clock::now() < until) {
    for (int k = 0; k < 200; ++k, ++i)
      agent->observe(test::moving_status(i), static_cast<std::int64_t>(i) * 1000);
    while (auto l = reader.line(1ms)) apply(agent->model(), *l, seen);
  }
  EXPECT_EQ(adapter.stats().dropped_slow, 1u);
  EXPECT_EQ(adapter.stats().clients, 1u);
  // The reader has every change up to the last.
  const std::string last_x = expected(*agent).values.at("x_act");
  ASSERT_TRUE(
      reader.read_until(agent->model(), seen, [&](const Seen& s) { return s.values.at("x_act") == last_x; }));
  EXPECT_EQ(seen.values, expected(*agent).values);
}

TEST(Shdr, AnAgentThatStopsPingingIsDroppedAfterTwoHeartbeatsAndOneWithoutPingIsKept) {
  auto agent = mill();
  ShdrOptions o = loopback();
  o.heartbeat_ms = 100;
  ShdrAdapter adapter(*agent, o);
  adapter.start();
  Client pinging(adapter.port()), silent(adapter.port()), legacy(adapter.port());
  silent.send("* PING\n");
  const auto until = std::chrono::steady_clock::now() + 600ms;
  while (std::chrono::steady_clock::now() < until) {
    pinging.send("* PING\n");
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(adapter.stats().dropped_silent, 1u);
  EXPECT_EQ(adapter.stats().clients, 2u);  // the pinging one and the one that never pinged
  while (silent.line(100ms)) {
  }
  EXPECT_TRUE(silent.closed);
}

TEST(Shdr, ConnectionsBeyondTheLimitAreClosedAndABusyPortIsNamed) {
  auto agent = mill();
  ShdrOptions o = loopback();
  o.max_clients = 1;
  ShdrAdapter adapter(*agent, o);
  adapter.start();
  Client first(adapter.port());
  ASSERT_TRUE(first.line());
  Client second(adapter.port());
  EXPECT_FALSE(second.line(2s));
  EXPECT_TRUE(second.closed);
  EXPECT_EQ(adapter.stats().refused, 1u);

  ShdrOptions same = loopback();
  same.port = adapter.port();
  ShdrAdapter clash(*agent, same);
  try {
    clash.start();
    ADD_FAILURE() << "a second listener on a busy port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("127.0.0.1:{}", adapter.port())), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace opencnc::connect
