// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI server on loopback with a real client: every call, the refusals (401, 403, 4xx with a
// message, 409 from the controller) changing nothing, the stream's rate and events, a client
// that stops reading dropped while another goes on, and a job run to its history entry.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "../control/test_profiles.hpp"
#include "opencnc/hmi/history.hpp"
#include "opencnc/hmi/machine_host.hpp"
#include "opencnc/hmi/server.hpp"
#include "opencnc/hmi/stream_tickets.hpp"
#include "server_rig.hpp"

namespace opencnc::hmi {
namespace {

using namespace test;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

/// The simulated mill with its history, its tool table a copy, and run from line.
RigOptions mill(ServerConfig sc = {}, std::string address = "127.0.0.1") {
  RigOptions o;
  o.tool_table_copy = true;
  o.run_from_line = true;
  o.server = sc;
  o.address = std::move(address);
  return o;
}

TEST(Server, StatusIsOpenOnLoopbackEverythingElseNeedsAToken) {
  ServerRig rig(mill());
  const Reply s = get(rig.port, "/api/v1/status");
  EXPECT_EQ(s.status, 200);
  EXPECT_EQ(s.body["mode"], "manual");
  EXPECT_EQ(get(rig.port, "/api/v1/machine").status, 401);
  EXPECT_EQ(get(rig.port, "/api/v1/machine", "wrong-token-wrong-token").status, 401);
  const Reply refused = post(rig.port, R"({"kind":"machine-on"})", "");
  EXPECT_EQ(refused.status, 401);
  EXPECT_EQ(refused.body["error"], "a valid token is needed (Authorization: Bearer TOKEN)");
  EXPECT_EQ(get(rig.port, "/api/v1/status").body["state"], "off");  // nothing changed
  EXPECT_EQ(get(rig.port, "/api/v1/machine", kOperator).body["axes"].size(), 3u);
}

TEST(Server, OnAnyOtherAddressTheStatusNeedsATokenToo) {
  ServerRig rig(mill({}, "0.0.0.0"));
  EXPECT_FALSE(rig.server->loopback_only());
  EXPECT_EQ(get(rig.port, "/api/v1/status").status, 401);
  EXPECT_EQ(get(rig.port, "/api/v1/status", kOperator).status, 200);
}

TEST(Server, BadRequestsGetA4xxWithAMessageAndChangeNothing) {
  ServerRig rig(mill());
  EXPECT_EQ(post(rig.port, "{not json", kOperator).status, 400);
  const Reply unknown = post(rig.port, R"({"kind":"fly"})", kOperator);
  EXPECT_EQ(unknown.status, 400);
  EXPECT_EQ(unknown.body["error"], "unknown command kind \"fly\" (docs/api.md lists them)");
  EXPECT_EQ(post(rig.port, R"({"kind":"override","which":"feed","value":7})", kOperator).status, 422);
  EXPECT_EQ(get(rig.port, "/api/v1/status").body["feed_override"], 1.0);
  EXPECT_EQ(post(rig.port, R"({"kind":"open","program":"../configs/mill-3axis.toml"})", kOperator).status,
            400);
  EXPECT_EQ(get(rig.port, "/api/v1/nothing", kOperator).status, 404);
  EXPECT_EQ(call(rig.port, Method::Get, "/api/v1/commands", kOperator).status, 405);
  EXPECT_EQ(call_declaring(rig.port, "/api/v1/commands", kOperator, 2 << 20).status, 413);
  // Refused by the controller: a jog while the machine is off.
  const Reply off = post(rig.port, R"({"kind":"jog","axis":"X","velocity":5})", kOperator);
  EXPECT_EQ(off.status, 409);
  EXPECT_EQ(off.body["code"], "control.machine-off");
  EXPECT_EQ(get(rig.port, "/api/v1/commands/" + off.body["id"].dump(), kOperator).body["accepted"], false);
}

// The route table's order of refusals: a token first (but for the loopback status), then the method
// (each route's own words), then the role; a path outside /api/v1/ is named as another version.
TEST(Server, EveryPathGetsItsRoutesRefusalsInOrder) {
  ServerRig rig(mill());
  EXPECT_EQ(call(rig.port, Method::Post, "/api/v1/machine", "", "{}").status, 401);
  const Reply wrong = call(rig.port, Method::Post, "/api/v1/machine", kOperator, "{}");
  EXPECT_EQ(wrong.status, 405);
  EXPECT_EQ(wrong.body["error"], "only GET here");
  EXPECT_EQ(call(rig.port, Method::Post, "/api/v1/status", "", "{}").status, 401);  // only GET is open
  EXPECT_EQ(call(rig.port, Method::Post, "/api/v1/nothing", kOperator, "{}").status, 405);
  const Reply none = get(rig.port, "/api/v1/nothing", kOperator);
  EXPECT_EQ(none.body["error"], "no such call: GET /api/v1/nothing");
  EXPECT_EQ(get(rig.port, "/api/v1/stream-ticket", kOperator).body["error"], "stream tickets are POSTed");
  EXPECT_EQ(get(rig.port, "/api/v1/commands", kOperator).body["error"], "commands are POSTed");
  EXPECT_EQ(get(rig.port, "/api/v1/commands/x", kOperator).status, 400);
  const Reply admin = get(rig.port, "/api/v1/audit", kOperator);
  EXPECT_EQ(admin.status, 403);
  EXPECT_EQ(admin.body["error"], "the audit trail is for the admin");
  EXPECT_EQ(call(rig.port, Method::Post, "/api/v1/audit", kOperator, "{}").status, 405);  // before the role
  const Reply other = get(rig.port, "/api/v2/status");
  EXPECT_EQ(other.status, 404);
  EXPECT_EQ(other.body["error"], "this server speaks /api/v1/");
  EXPECT_EQ(call(rig.port, Method::Post, "/index.html", "", "{}").status, 405);  // the front end's files
}

// The second hostile probe (issue 29): a number no double holds aborted the server; refused tokens
// on GET calls left no audit row.
TEST(Server, ANumberTooLargeForADoubleIsA400AndTheServerGoesOn) {
  ServerRig rig(mill());
  for (const char* body : {R"({"kind":"jog","axis":"X","velocity":1e400})",
                           R"({"kind":"override","which":"feed","value":-1e999})", R"([1e400])"}) {
    const Reply r = post(rig.port, body, kOperator);
    EXPECT_EQ(r.status, 400) << body << ": " << r.text;
  }
  EXPECT_EQ(get(rig.port, "/api/v1/status").status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"machine-on"})", kOperator).status, 200);
}

TEST(Server, EveryRefusedTokenIsAuditedOnGetCallsToo) {
  ServerRig rig(mill());
  EXPECT_EQ(get(rig.port, "/api/v1/tools", "not-a-token").status, 401);
  EXPECT_EQ(get(rig.port, "/api/v1/history").status, 401);
  EXPECT_EQ(get(rig.port, "/api/v1/audit", kOperator).status, 403);
  rig.history->flush();
  const json audit = get(rig.port, "/api/v1/audit", kAdmin).body;
  int refused = 0;
  for (const json& a : audit) {
    const std::string action = a["action"];
    if ((a["status"] == 401 && (action == "GET /api/v1/tools" || action == "GET /api/v1/history")) ||
        (a["status"] == 403 && action == "GET /api/v1/audit"))
      ++refused;
  }
  EXPECT_EQ(refused, 3) << audit.dump(1);
}

// The second hostile probe (issue 29): a comment with a newline wrote a line the interpreter read
// as a tool; 100 KB comments and control characters were written verbatim.
TEST(Server, AToolCommentIsOneBoundedLine) {
  ServerRig rig(mill());
  const json before = get(rig.port, "/api/v1/tools", kOperator).body;
  for (const std::string& comment :
       {std::string("x\nT99 P99 Z-1000 D1"), std::string("a\r\0b", 4), std::string(100000, 'x')}) {
    const json body = {{"kind", "set-tool"}, {"tool", 1}, {"comment", comment}};
    const Reply r = post(rig.port, body.dump(), kAdmin);
    EXPECT_EQ(r.status, 422) << r.text;
  }
  EXPECT_EQ(get(rig.port, "/api/v1/tools", kOperator).body, before);
  const Reply ok = post(rig.port, R"({"kind":"set-tool","tool":1,"comment":"end mill 6 mm, new"})", kAdmin);
  EXPECT_EQ(ok.status, 200) << ok.text;
}

TEST(Server, ToolDataIsTheAdminsAndEveryChangeIsAudited) {
  ServerRig rig(mill());
  const std::string change = R"({"kind":"set-tool","tool":1,"diameter":6.02})";
  EXPECT_EQ(post(rig.port, change, kOperator).status, 403);
  EXPECT_EQ(get(rig.port, "/api/v1/tools", kOperator).body[0]["diameter"], 6.0);
  const Reply ok = post(rig.port, change, kAdmin);
  EXPECT_EQ(ok.status, 200) << ok.text;
  EXPECT_EQ(get(rig.port, "/api/v1/tools", kOperator).body[0]["diameter"], 6.02);
  EXPECT_EQ(post(rig.port, R"({"kind":"set-tool","tool":77,"diameter":1})", kAdmin).status, 404);
  EXPECT_EQ(get(rig.port, "/api/v1/audit", kOperator).status, 403);
  rig.history->flush();
  const json audit = get(rig.port, "/api/v1/audit", kAdmin).body;
  ASSERT_GE(audit.size(),
            4u);  // newest first: the operator's look at the audit, T77, the change, the refusal
  EXPECT_EQ(audit[0]["action"], "GET /api/v1/audit");
  EXPECT_EQ(audit[0]["status"], 403);
  EXPECT_EQ(audit[2]["role"], "admin");
  EXPECT_EQ(audit[2]["status"], 200);
  EXPECT_EQ(audit[3]["role"], "operator");
  EXPECT_EQ(audit[3]["status"], 403);
  EXPECT_FALSE(audit[3]["time"].get<std::string>().empty());
}

TEST(Server, TheStreamOpensWithASingleUseTicketAndNeverATokenInTheUrl) {
  ServerRig rig(mill());
  const Reply issued = call(rig.port, Method::Post, "/api/v1/stream-ticket", kOperator, "");
  ASSERT_EQ(issued.status, 200) << issued.text;
  const std::string ticket = issued.body["ticket"];
  EXPECT_EQ(ticket.size(), 48u);
  EXPECT_EQ(issued.body["expires_in_s"], 30);
  EXPECT_EQ(call(rig.port, Method::Post, "/api/v1/stream-ticket", "", "").status, 401);
  EXPECT_EQ(get(rig.port, "/api/v1/stream-ticket", kOperator).status, 405);
  {
    Stream s(rig.port, "", 0, "?ticket=" + ticket);
    EXPECT_EQ(s.next()["type"], "status");
  }
  // Used up; a token in the query opens nothing (nor does it pass for any other call).
  EXPECT_THROW(Stream(rig.port, "", 0, "?ticket=" + ticket), std::runtime_error);
  EXPECT_THROW(Stream(rig.port, "", 0, "?token=" + kOperator), std::runtime_error);
  EXPECT_EQ(get(rig.port, "/api/v1/programs?token=" + kOperator).status, 401);
}

TEST(StreamTickets, LastTheirLifetimeAndOpenOnce) {
  StreamTickets t;
  const auto now = StreamTickets::Clock::now();
  std::string error;
  const auto a = t.issue(Role::Admin, now, &error), b = t.issue(Role::Operator, now, &error);
  ASSERT_TRUE(a && b) << error;
  EXPECT_NE(*a, *b);
  EXPECT_EQ(t.redeem(*a, now + std::chrono::seconds(29)), Role::Admin);
  EXPECT_FALSE(t.redeem(*a, now + std::chrono::seconds(29)));  // once
  EXPECT_FALSE(t.redeem(*b, now + StreamTickets::kLifetime));  // expired
  EXPECT_FALSE(t.redeem("", now));
  EXPECT_EQ(t.outstanding(), 0u);
  for (std::size_t k = 0; k < StreamTickets::kMaxOutstanding + 5; ++k)
    ASSERT_TRUE(t.issue(Role::Operator, now, &error));
  EXPECT_EQ(t.outstanding(), StreamTickets::kMaxOutstanding);
}

TEST(Server, TheStreamSendsStatusAtItsRateAndEachClientItsEvents) {
  ServerConfig sc;
  sc.stream_hz = 30;
  ServerRig rig(mill(sc));
  Stream a(rig.port, kOperator);
  EXPECT_THROW(Stream(rig.port, "not-a-token-at-all-0000"), std::runtime_error);
  const auto start = Clock::now();
  int status = 0;
  while (Clock::now() - start < std::chrono::milliseconds(500)) {
    if (a.next()["type"] == "status") ++status;
  }
  EXPECT_GE(status, 8);  // 15 at 30 Hz in 0.5 s; a loaded machine (or a sanitizer build) loses some
  EXPECT_LE(status, 17);
  Stream b(rig.port, kOperator);
  EXPECT_EQ(post(rig.port, R"({"kind":"machine-on"})", kOperator).status, 200);
  for (Stream* s : {&a, &b}) {  // both see the answer: their cursors are their own
    bool answered = false;
    for (int k = 0; k < 200 && !answered; ++k) {
      const json m = s->next();
      if (m["type"] != "events") continue;
      for (const json& e : m["events"])
        answered = answered || (e["kind"] == "answer" && e["accepted"] == true);
    }
    EXPECT_TRUE(answered);
  }
}

TEST(Server, AClientThatStopsReadingIsDroppedWithoutSlowingTheOthers) {
  ServerConfig sc;
  sc.stream_hz = 200;
  sc.max_queued = 8;
  ServerRig rig(mill(sc));
  Stream stalled(rig.port, kOperator, 4096);  // connects, then never reads
  Stream reader(rig.port, kOperator);
  // The reader gets every status the stream makes while the stalled client fills its queue,
  // whatever rate this machine (or a sanitizer build) reaches: nobody waits for the stalled one.
  const std::uint64_t ticks0 = rig.server->stats().stream_ticks;
  const auto start = Clock::now();
  std::uint64_t statuses = 0;
  while (rig.server->stats().dropped == 0 && Clock::now() - start < std::chrono::seconds(20)) {
    if (reader.next()["type"] == "status") ++statuses;
  }
  const std::uint64_t made = rig.server->stats().stream_ticks - ticks0;
  EXPECT_EQ(rig.server->stats().dropped, 1u);
  EXPECT_GT(made, 8u);
  EXPECT_GE(statuses + 10, made);                  // at most its own queue (8) and one tick behind
  EXPECT_TRUE(stalled.read_until_closed(100000));  // what was sent before, then the close
  EXPECT_FALSE(reader.read_until_closed(20));
}

TEST(Server, AJobRunsToItsEndWithHoldAndResumeAndLandsInTheHistory) {
  ServerRig rig(mill());
  const std::string& t = kOperator;
  EXPECT_EQ(post(rig.port, R"({"kind":"machine-on"})", t).status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"home"})", t).status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"mode","mode":"auto"})", t).status, 200);
  const json programs = get(rig.port, "/api/v1/programs", t).body;
  EXPECT_EQ(programs[0]["name"], "bracket.ngc");
  const Reply open = post(rig.port, R"({"kind":"open","program":"bracket.ngc"})", t);
  ASSERT_EQ(open.status, 200) << open.text;
  const json info = get(rig.port, "/api/v1/program", t).body;
  EXPECT_EQ(info["program"], "bracket.ngc");
  EXPECT_GT(info["moves"].get<int>(), 100);
  const json preview = get(rig.port, "/api/v1/program/preview", t).body;
  EXPECT_GT(preview["polylines"].size(), 2u);
  EXPECT_EQ(preview["tools"], json::array({1, 2}));  // T1 M6, T2 M6
  EXPECT_EQ(get(rig.port, "/api/v1/program/text?from=4&count=1", t).body["lines"][0],
            "G21 G17 G40 G49 G80 G90 G94");
  EXPECT_TRUE(
      get(rig.port, "/api/v1/program/text?from=4&count=1", t).body["more"]);  // a window: more after it
  const json tail = get(rig.port, "/api/v1/program/text?from=70&count=5000", t).body;
  EXPECT_FALSE(tail["more"]);
  EXPECT_EQ(tail["from"], 70);
  EXPECT_EQ(tail["lines"][0], "G80");
  EXPECT_EQ(post(rig.port, R"({"kind":"cycle-start"})", t).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["wait"] == "manual-tool-change"; }));
  EXPECT_EQ(post(rig.port, R"({"kind":"tool-changed"})", t).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["job"]["progress"].get<double>() > 0.2; }));
  EXPECT_EQ(post(rig.port, R"({"kind":"feed-hold"})", t).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["state"] == "held" && s["path_velocity"] == 0.0; }));
  const json held = get(rig.port, "/api/v1/status", t).body;
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(get(rig.port, "/api/v1/status", t).body["commanded"], held["commanded"]);  // it stands
  EXPECT_EQ(post(rig.port, R"({"kind":"resume"})", t).status, 200);
  ASSERT_TRUE(rig.until([&](const json& s) { return s["commanded"] != held["commanded"]; }));
  // On to the end, the operator confirming the second tool (T2) when asked.
  ASSERT_TRUE(rig.until(
      [&](const json& s) {
        if (s["wait"] == "manual-tool-change") post(rig.port, R"({"kind":"tool-changed"})", t);
        return s["runs_finished"] == 1 && s["state"] == "idle";
      },
      60));
  rig.history->flush();
  const json history = get(rig.port, "/api/v1/history", t).body;
  ASSERT_EQ(history.size(), 1u);
  EXPECT_EQ(history[0]["outcome"], "finished");
  EXPECT_TRUE(history[0]["program"].get<std::string>().ends_with("examples/bracket.ngc"));
  EXPECT_GT(history[0]["machining_s"].get<double>(), 10);
  const json events = get(rig.port, "/api/v1/events?after=0", t).body;
  bool ended = false;
  for (const json& e : events["events"])
    ended = ended || (e["kind"] == "job-ended" && e["end"] == "finished");
  EXPECT_TRUE(ended);
}

// The issue's reproduction: the spindle at 3000 rpm, an endless moving loop opened, then the
// e-stop. The e-stop is answered (200, not 202 pending) while the open's check runs, the machine
// stands e-stopped with the spindle stopped, and the e-stop cancelled the check.
TEST(Server, AnEStopIsAnsweredAndActsWhileAnEndlessProgramIsChecked) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("opencnc-hmi-estop-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "endless.ngc") << "G21 G90 F1000\no1 while [1]\nG1 X1\nG1 X0\no1 endwhile\nM2\n";
  RigOptions o = mill();
  o.programs = dir;
  o.server.command_timeout_s = 30;  // a 202 would mean the e-stop waited behind the open
  ServerRig rig(o);
  const std::string& t = kOperator;
  ASSERT_EQ(post(rig.port, R"({"kind":"machine-on"})", t).status, 200);
  ASSERT_EQ(post(rig.port, R"({"kind":"mode","mode":"manual"})", t).status, 200);
  ASSERT_EQ(post(rig.port, R"({"kind":"spindle-on","rpm":3000})", t).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["spindle"]["rpm"] == 3000.0; }));
  ASSERT_EQ(post(rig.port, R"({"kind":"mode","mode":"auto"})", t).status, 200);
  Reply open;
  std::thread opener([&] { open = post(rig.port, R"({"kind":"open","program":"endless.ngc"})", t); });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the check is under way
  const Reply estop = post(rig.port, R"({"kind":"estop"})", t);
  EXPECT_EQ(estop.status, 200) << estop.text;
  EXPECT_TRUE(estop.body.value("accepted", false)) << estop.text;
  EXPECT_TRUE(rig.until([](const json& s) { return s["state"] == "e-stopped"; }, 5));
  EXPECT_EQ(rig.status()["spindle"]["direction"], "stopped");
  opener.join();
  EXPECT_EQ(open.status, 409) << open.text;
  EXPECT_NE(open.text.find("control.superseded"), std::string::npos) << open.text;
  std::filesystem::remove_all(dir);
}

TEST(Server, TheStatusShowsWorkCoordinatesWithAG55OffsetAndAG92Shift) {
  ServerRig rig(mill());
  const std::string& t = kOperator;
  EXPECT_EQ(post(rig.port, R"({"kind":"machine-on"})", t).status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"mode","mode":"mdi"})", t).status, 200);
  const auto mdi = [&](const std::string& line) {
    ASSERT_EQ(post(rig.port, json{{"kind", "mdi"}, {"line", line}}.dump(), t).status, 200) << line;
    ASSERT_TRUE(
        rig.until([](const json& s) { return s["state"] == "idle" && !s["job"]["active"].get<bool>(); }));
  };
  mdi("G21 G90 G10 L2 P2 X10 Y20 Z-5");
  mdi("G55 G0 X1 Y2 Z0");
  mdi("G52 X1");                                        // a local shift (the G92 offset) of exactly 1
  const json s = get(rig.port, "/api/v1/status").body;  // tokenless on loopback
  EXPECT_EQ(s["offsets"]["system"], "G55");
  EXPECT_EQ(s["offsets"]["g5x"]["X"], 10.0);
  EXPECT_EQ(s["offsets"]["g5x"]["Y"], 20.0);
  EXPECT_EQ(s["offsets"]["g5x"]["Z"], -5.0);
  EXPECT_EQ(s["offsets"]["g92"]["X"], 1.0);
  EXPECT_NEAR(s["commanded"]["X"].get<double>(), 11.0, 1e-9);
  EXPECT_EQ(s["distance_to_go"]["X"], 0.0);
  // work = machine − offsets, from the feedback position
  const double machine_x = s["machine"]["X"].get<double>(), machine_y = s["machine"]["Y"].get<double>();
  EXPECT_EQ(s["work"]["X"].get<double>(), machine_x - 10.0 - 1.0);
  EXPECT_EQ(s["work"]["Y"].get<double>(), machine_y - 20.0);
  EXPECT_NEAR(s["work"]["X"].get<double>(), 0.0, 1e-3);  // X1 in G55 before the shift
  EXPECT_NEAR(s["work"]["Y"].get<double>(), 2.0, 1e-3);
}

TEST(Server, RunFromLineStartsTheProgramAtTheLineAfterTheApproach) {
  ServerRig rig(mill());
  const std::string& t = kOperator;
  EXPECT_EQ(post(rig.port, R"({"kind":"machine-on"})", t).status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"home"})", t).status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"mode","mode":"auto"})", t).status, 200);
  ASSERT_EQ(post(rig.port, R"({"kind":"open","program":"bracket.ngc"})", t).status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"run-from-line","line":0})", t).status, 422);
  EXPECT_EQ(post(rig.port, R"({"kind":"run-from-line"})", t).status, 400);
  const Reply none = post(rig.port, R"({"kind":"run-from-line","line":12})", t);  // an assignment
  EXPECT_EQ(none.status, 409);
  EXPECT_NE(none.text.find("line 12 makes no move"), std::string::npos) << none.text;
  // The drilling after the second tool change: the approach (T2 changed in by hand first, the
  // spindle on), then the program from line 66.
  const Reply from = post(rig.port, R"({"kind":"run-from-line","line":66})", t);
  ASSERT_EQ(from.status, 200) << from.text;
  EXPECT_NE(from.text.find("bracket.ngc:66"), std::string::npos) << from.text;
  EXPECT_NE(from.text.find("with tool 2 changed in"), std::string::npos) << from.text;
  ASSERT_TRUE(rig.until([&](const json& s) { return s["wait"] == "manual-tool-change"; }, 20));
  json s = get(rig.port, "/api/v1/status").body;
  EXPECT_EQ(s["job"]["kind"], "auxiliary");
  EXPECT_EQ(s["prepared_tool"], 2);
  EXPECT_EQ(post(rig.port, R"({"kind":"tool-changed"})", t).status, 200);
  ASSERT_TRUE(rig.until([&](const json& st) { return st["job"]["kind"] == "program"; }, 20));
  s = get(rig.port, "/api/v1/status").body;
  EXPECT_EQ(s["tool"], 2);
  EXPECT_EQ(s["spindle"]["direction"], "cw");
  EXPECT_EQ(s["offsets"]["tool"]["Z"], 62.5);  // configs/mill-3axis.tbl
  std::uint32_t first_line = 0;
  ASSERT_TRUE(rig.until(
      [&](const json& st) {
        if (first_line == 0 && st["job"]["kind"] == "program" && st["job"]["location"]["line"].get<int>() > 0)
          first_line = st["job"]["location"]["line"].get<std::uint32_t>();
        return st["runs_finished"].get<int>() >= 2 && st["job"]["kind"] == "" &&
               st["state"] == "idle";  // approach, program
      },
      60));
  // Seen while polling when the run is slow enough (a sanitizer build may run past it between polls).
  if (first_line != 0) {
    EXPECT_GE(first_line, 66u);
  }
  // In the history: the approach, then the program from there to its end.
  rig.history->flush();
  const json history = get(rig.port, "/api/v1/history", t).body;
  ASSERT_EQ(history.size(), 2u);
  EXPECT_EQ(history[1]["program"], "approach to line 66");
  EXPECT_EQ(history[1]["outcome"], "finished");
  EXPECT_EQ(history[0]["outcome"], "finished");
  EXPECT_TRUE(history[0]["program"].get<std::string>().ends_with("examples/bracket.ngc"));
}

TEST(MachineHost, InRealTimeTheServoTicksByItselfAndTheControllerAnswers) {
  const config::MachineProfile profile = control::test::mill();
  MachineHost host(profile, nullptr, HostOptions{true, 1});
  ASSERT_TRUE(host.start(nullptr));  // SCHED_FIFO or, with a warning, a normal thread
  const std::uint64_t id =
      host.controller().submit(controller::Request::simple(control::CommandKind::MachineOn));
  const auto end = Clock::now() + std::chrono::seconds(10);
  while (!host.controller().outcome(id) && Clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_TRUE(host.controller().outcome(id));
  EXPECT_TRUE(host.controller().outcome(id)->accepted);
  const std::uint64_t ticks = host.ticks();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_GT(host.ticks(), ticks);
  ASSERT_NE(host.latency(), nullptr);
  host.stop();
  const std::uint64_t stopped = host.ticks();
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(host.ticks(), stopped);
}

// On a machine with a CPU set aside for the servo, the server's threads must not wake on it: they
// would delay the servo's wake-up. Runs on a thread of its own, whose affinity the host changes.
TEST(MachineHost, AServoCpuKeepsTheHostsOtherThreadsOffIt) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  ASSERT_EQ(pthread_getaffinity_np(pthread_self(), sizeof allowed, &allowed), 0);
  if (CPU_COUNT(&allowed) < 2) GTEST_SKIP() << "one CPU allowed: nothing to keep the server off";
  int servo_cpu = -1;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &allowed)) servo_cpu = cpu;
  std::thread caller([&] {
    const config::MachineProfile profile = control::test::mill();
    HostOptions options;
    options.servo_cpu = servo_cpu;
    MachineHost host(profile, nullptr, options);
    std::vector<std::string> warnings;
    ASSERT_TRUE(host.start(&warnings));
    for (const std::string& w : warnings) EXPECT_EQ(w.find("CPU"), std::string::npos) << w;
    cpu_set_t later;
    std::thread started_after([&] { pthread_getaffinity_np(pthread_self(), sizeof later, &later); });
    started_after.join();
    EXPECT_FALSE(CPU_ISSET(servo_cpu, &later));
    EXPECT_EQ(CPU_COUNT(&later), CPU_COUNT(&allowed) - 1);
    const std::uint64_t ticks = host.ticks();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_GT(host.ticks(), ticks);
    host.stop();
  });
  caller.join();
}

}  // namespace
}  // namespace opencnc::hmi
