// SPDX-License-Identifier: GPL-3.0-or-later
// The machine features through the HMI: the feature command kind to its typed requests (the
// choices that move the machine only when confirmed), the process side of the status (power,
// load, alarms, EDM), the features a profile calls for, and the power-fail flow on the broach
// served on loopback: mains off mid-cut, the record in the status, the power back, a retract.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "../control/test_profiles.hpp"
#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/edm/electrode_setting.hpp"
#include "opencnc/hmi/api.hpp"
#include "opencnc/hmi/machine_features.hpp"
#include "opencnc/hmi/machine_host.hpp"
#include "opencnc/hmi/server.hpp"
#include "opencnc/retrace/retrace.hpp"
#include "opencnc/store/tool_store.hpp"
#include "opencnc/tools/tool_text.hpp"
#include "server_rig.hpp"

namespace opencnc::hmi {
namespace {

using namespace test;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

config::MachineProfile load(const char* name, std::vector<std::string> sets = {}) {
  const config::ProfileLoad l =
      config::load_profile(std::string(OPENCNC_SOURCE_DIR "/configs/") + name, sets);
  EXPECT_TRUE(l.ok()) << name;
  return *l.profile;
}

class FeatureParse : public ::testing::Test {
 protected:
  config::MachineProfile profile = control::test::mill();

  controller::requests::Feature request(const json& body) {
    auto r = parse_command(body, profile, OPENCNC_SOURCE_DIR "/examples");
    EXPECT_TRUE(std::holds_alternative<Command>(r)) << std::get<ApiError>(r).message;
    return std::get<controller::requests::Feature>(std::get<controller::Request>(std::get<Command>(r)).body);
  }
  ApiError error(const json& body) {
    auto r = parse_command(body, profile, OPENCNC_SOURCE_DIR "/examples");
    EXPECT_TRUE(std::holds_alternative<ApiError>(r)) << body.dump();
    return std::holds_alternative<ApiError>(r) ? std::get<ApiError>(r) : ApiError{0, ""};
  }
};

TEST_F(FeatureParse, JournalChoicesCarryTheirArgumentsAndNeedTheOperatorsConfirmation) {
  EXPECT_EQ(request({{"kind", "feature"}, {"feature", "journal"}, {"action", "show"}}).action, "show");
  const ApiError unconfirmed = error({{"kind", "feature"}, {"feature", "journal"}, {"action", "discard"}});
  EXPECT_EQ(unconfirmed.status, 400);
  EXPECT_EQ(unconfirmed.message, "discard must be confirmed by the operator: add \"confirmed\": true");
  EXPECT_EQ(error({{"kind", "feature"}, {"feature", "journal"}, {"action", "discard"}, {"confirmed", false}})
                .status,
            400);
  const auto resume = request({{"kind", "feature"},
                               {"feature", "journal"},
                               {"action", "resume"},
                               {"confirmed", true},
                               {"run_in_mm", 1.5}});
  const auto r = std::any_cast<recovery::ResumeArgs>(resume.args);
  EXPECT_EQ(r.run_in_mm, 1.5);
  EXPECT_EQ(r.tolerance_mm, 0.01);  // the default where the body says nothing
  const auto retract = request({{"kind", "feature"},
                                {"feature", "journal"},
                                {"action", "retract"},
                                {"confirmed", true},
                                {"distance_mm", 5},
                                {"direction", "onward"},
                                {"speed_mm_min", 200}});
  const auto a = std::any_cast<recovery::RetractArgs>(retract.args);
  EXPECT_EQ(a.distance_mm, 5);
  EXPECT_TRUE(a.onward);
  EXPECT_EQ(a.speed_mm_min, 200);
  const json no_distance = {
      {"kind", "feature"}, {"feature", "journal"}, {"action", "retract"}, {"confirmed", true}};
  EXPECT_EQ(error(no_distance).message, "\"distance_mm\" is missing");
  json sideways = no_distance;
  sideways["distance_mm"] = 1;
  sideways["direction"] = "sideways";
  EXPECT_EQ(error(sideways).status, 400);
  json too_fast = no_distance;
  too_fast["distance_mm"] = 1;
  too_fast["speed_mm_min"] = 1e9;
  EXPECT_EQ(error(too_fast).status, 422);
  EXPECT_EQ(error({{"kind", "feature"}, {"feature", "journal"}, {"action", "rewind"}}).status, 400);
}

TEST_F(FeatureParse, RetraceElectrodeAndToolGuardActions) {
  const auto start = request({{"kind", "feature"},
                              {"feature", "retrace"},
                              {"action", "start"},
                              {"confirmed", true},
                              {"metric", "xyz"},
                              {"candidate", 1}});
  EXPECT_EQ(std::any_cast<recovery::RetraceStart>(start.args).metric, recovery::Metric::Xyz);
  EXPECT_EQ(std::any_cast<recovery::RetraceStart>(start.args).candidate, 1u);
  const auto step =
      request({{"kind", "feature"}, {"feature", "retrace"}, {"action", "step"}, {"distance_mm", -2}});
  EXPECT_EQ(std::any_cast<recovery::RetraceStep>(step.args).distance_mm, -2);
  EXPECT_EQ(request({{"kind", "feature"}, {"feature", "retrace"}, {"action", "pause"}}).action, "pause");
  const auto measure =
      request({{"kind", "feature"}, {"feature", "electrode"}, {"action", "measure"}, {"tool", 3}});
  EXPECT_EQ(std::any_cast<edm::ElectrodeMeasure>(measure.args).tool, 3);
  EXPECT_FALSE(
      std::any_cast<edm::ElectrodeMeasure>(measure.args).write);  // shown first, stored on confirmation
  EXPECT_EQ(error({{"kind", "feature"},
                   {"feature", "electrode"},
                   {"action", "measure"},
                   {"tool", 3},
                   {"write", true}})
                .status,
            400);
  const auto at_b = request(
      {{"kind", "feature"}, {"feature", "electrode"}, {"action", "measure"}, {"tool", 3}, {"b_deg", 40}});
  EXPECT_EQ(std::any_cast<edm::ElectrodeMeasure>(at_b.args).b_deg, 40.0);
  EXPECT_FALSE(std::any_cast<edm::ElectrodeMeasure>(measure.args).b_deg.has_value()) << "at the profile's b";
  const json calibrate = {{"kind", "feature"},
                          {"feature", "electrode"},
                          {"action", "calibrate-b"},
                          {"tool", 1},
                          {"angles_deg", {-45, 0, 45}}};
  EXPECT_EQ(error(calibrate).status, 400) << "B turns and the axis in use changes: confirmed";
  json confirmed_calibrate = calibrate;
  confirmed_calibrate["confirmed"] = true;
  EXPECT_EQ(std::any_cast<edm::BAxisCalibrate>(request(confirmed_calibrate).args).angles_deg,
            (std::vector<double>{-45, 0, 45}));
  json two_angles = confirmed_calibrate;
  two_angles["angles_deg"] = {0, 45};
  EXPECT_EQ(error(two_angles).status, 400);
  EXPECT_EQ(error({{"kind", "feature"}, {"feature", "electrode"}, {"action", "write"}}).status, 400);
  EXPECT_EQ(request({{"kind", "feature"}, {"feature", "electrode"}, {"action", "write"}, {"confirmed", true}})
                .action,
            "write");
  EXPECT_EQ(error({{"kind", "feature"}, {"feature", "electrode"}, {"action", "measure"}, {"tool", 0}}).status,
            422);
  EXPECT_EQ(request({{"kind", "feature"}, {"feature", "tool-guard"}, {"action", "check"}}).feature,
            "tool-guard");
  EXPECT_EQ(error({{"kind", "feature"}, {"feature", "tool-guard"}, {"action", "accept"}}).status, 400);
  const auto restore = request({{"kind", "feature"},
                                {"feature", "tool-guard"},
                                {"action", "restore"},
                                {"confirmed", true},
                                {"backup", 4}});
  EXPECT_EQ(std::any_cast<std::int64_t>(restore.args), 4);
  EXPECT_EQ(error({{"kind", "feature"}, {"feature", "warp"}, {"action", "x"}}).message,
            "unknown feature \"warp\" (journal, retrace, electrode, tool-guard)");
  EXPECT_EQ(error({{"kind", "feature"}, {"action", "x"}}).message, "\"feature\" is missing");
  EXPECT_EQ(role_for("feature"), Role::Operator);
  EXPECT_EQ(role_for("simulate"), Role::Admin);
  EXPECT_EQ(error({{"kind", "simulate"}, {"event", "earthquake"}}).status, 400);
}

TEST(ProcessJson, LoadAlarmsAndEdmAsTheProfileHasThem) {
  const config::MachineProfile broach = load("broach-zc.toml");
  control::ServoStatus s;
  s.load_kn = 4.3;
  s.load_action = control::LoadAction::Hold;
  s.mains_ok = false;
  const json b = process_json(s, broach);
  EXPECT_EQ(b["load"]["kn"], 4.3);
  EXPECT_EQ(b["load"]["action"], "hold");
  EXPECT_EQ(b["load"]["hold_kn"], 4.0);
  EXPECT_EQ(b["load"]["retract_kn"], 6.0);
  EXPECT_EQ(b["power"]["mains_ok"], false);
  EXPECT_FALSE(b.contains("edm"));

  const config::MachineProfile edm = load("edm-5axis.toml");
  ASSERT_GE(edm.alarms.alarms.count, 2);
  s = {};
  s.alarms_active = 0b10;
  s.alarm_values[1] = 47.5;
  s.edm.on = true;
  s.edm.condition = edm.edm.config.conditions[0].number;
  s.edm.gap_state = machine::GapState::Short;
  s.edm.gap_voltage_v = 3.5;
  s.edm.jumps = 12;
  const json e = process_json(s, edm);
  EXPECT_FALSE(e.contains("load"));
  EXPECT_EQ(e["alarms"][0]["name"], edm.alarms.names[0]);
  EXPECT_EQ(e["alarms"][0]["active"], false);
  EXPECT_EQ(e["alarms"][1]["active"], true);
  EXPECT_EQ(e["alarms"][1]["value"], 47.5);
  EXPECT_EQ(e["alarms"][1]["unit"], edm.alarms.units[1]);
  EXPECT_EQ(e["edm"]["gap_state"], "short");
  EXPECT_EQ(e["edm"]["gap_voltage_v"], 3.5);
  EXPECT_EQ(e["edm"]["jumps"], 12);
  EXPECT_EQ(e["edm"]["reference_v"], edm.edm.config.conditions[0].servo_reference_v);
}

TEST(MachineFeatures, EachProfileGetsTheFeaturesItCallsFor) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("opencnc-features-" + std::to_string(::getpid()));
  Diagnostics d;
  auto broach = MachineFeatures::create(load("broach-zc.toml"), {(dir / "journal").string()}, d);
  ASSERT_TRUE(broach) << (d.items().empty() ? "" : d.items()[0].format());
  EXPECT_EQ(broach->names(), (std::vector<std::string>{"journal", "run-from-line"}));
  EXPECT_TRUE(std::filesystem::exists(dir / "journal"));
  // Without a journal folder a power monitor alone installs no journal.
  EXPECT_EQ(MachineFeatures::create(load("broach-zc.toml"), {}, d)->names(),
            (std::vector<std::string>{"run-from-line"}));
  EXPECT_EQ(MachineFeatures::create(load("flame-cutter.toml"), {}, d)->names(),
            (std::vector<std::string>{"retrace", "run-from-line"}));
  EXPECT_EQ(MachineFeatures::create(load("edm-5axis.toml"), {}, d)->names(),
            (std::vector<std::string>{"electrode", "run-from-line"}));
  // A journal folder that cannot be made: refused with the reason, nothing installed.
  Diagnostics bad;
  EXPECT_FALSE(MachineFeatures::create(load("broach-zc.toml"), {"/proc/opencnc-journal"}, bad));
  ASSERT_FALSE(bad.items().empty());
  EXPECT_EQ(bad.items()[0].code, "setting.journal");
  std::filesystem::remove_all(dir);
}

/// A machine served on loopback with its features and the simulation controls; programs from
/// `programs` (default the examples).
RigOptions featured(const char* machine, std::vector<std::string> sets = {},
                    std::filesystem::path programs = OPENCNC_SOURCE_DIR "/examples") {
  RigOptions o;
  o.machine = machine;
  o.sets = std::move(sets);
  o.features = true;
  o.history = false;
  o.programs = std::move(programs);
  return o;
}

// A cut's torque simulated on the spindle (admin only) shows in the status as the drive's torque:
// the load plus the simulated spindle's friction at 3000 rpm (0.3 + 0.05 · 3 N·m).
TEST(ServerFeatures, ASimulatedSpindleLoadShowsAsTheDrivesTorque) {
  ServerRig rig(featured("mill-3axis.toml"));
  ASSERT_EQ(rig.command({{"kind", "machine-on"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "mode"}, {"mode", "manual"}}).status, 200);
  EXPECT_EQ(rig.status()["spindle"]["torque_nm"], 0.0);
  ASSERT_EQ(rig.command({{"kind", "spindle-on"}, {"rpm", 3000}}).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["spindle"]["at_speed"] == true; }));
  const json load = {{"kind", "simulate"}, {"event", "spindle-load"}, {"torque_nm", 12}};
  EXPECT_EQ(rig.command(load).status, 403);
  EXPECT_EQ(rig.command({{"kind", "simulate"}, {"event", "spindle-load"}, {"torque_nm", -1}}, kAdmin).status,
            422);
  ASSERT_EQ(rig.command(load, kAdmin).status, 200);
  EXPECT_TRUE(rig.until([](const json& s) {
    return std::abs(s["spindle"]["torque_nm"].get<double>() - 12.45) < 1e-9;
  })) << rig.status()["spindle"].dump();
}

// The oxy-fuel table with the preheat waiting for the operator: the API's start-cut is refused
// while no preheat is under way, then the cut waits in its preheat (the status says so) until the
// operator's start-cut, after which the cutting oxygen is on and the cut goes on.
TEST(ServerFeatures, AnOxyFuelPreheatWaitsForStartCutFromTheApi) {
  ServerRig rig(featured("oxyfuel-table.toml", {"process.oxyfuel.preheat=\"operator\""}));
  ASSERT_EQ(rig.command({{"kind", "machine-on"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "mode"}, {"mode", "auto"}}).status, 200);
  const Reply early = rig.command({{"kind", "start-cut"}});
  EXPECT_EQ(early.status, 409) << early.text;
  EXPECT_EQ(early.body["code"], "control.not-applicable");
  EXPECT_NE(early.body["message"].get<std::string>().find("no preheat is under way"), std::string::npos)
      << early.text;
  ASSERT_EQ(rig.command({{"kind", "open"}, {"program", "oxyfuel-bracket.ngc"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "cycle-start"}}).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["features"]["cutting"]["waiting_start"] == true; }))
      << rig.status()["features"].dump();
  const json waiting = rig.status()["features"]["cutting"];
  EXPECT_EQ(waiting["process"], "oxy-fuel");
  EXPECT_EQ(waiting["phase"], "preheating");
  EXPECT_EQ(waiting["torch_on"], true);
  EXPECT_EQ(waiting["cut_oxygen"], false);
  EXPECT_EQ(waiting["preheats"], 1);
  // Still waiting a while later (virtual time runs 200× the wall clock: seconds of preheat).
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const json later = rig.status()["features"]["cutting"];
  EXPECT_EQ(later["phase"], "preheating");
  EXPECT_GT(later["preheat_s"].get<double>(), waiting["preheat_s"].get<double>());
  const Reply start = rig.command({{"kind", "start-cut"}});
  ASSERT_EQ(start.status, 200) << start.text;
  EXPECT_TRUE(rig.until([](const json& s) {
    const json& c = s["features"]["cutting"];
    return c["phase"] == "cutting" && c["cut_oxygen"] == true;
  })) << rig.status()["features"].dump();
  EXPECT_EQ(rig.command({{"kind", "abort"}}).status, 200);
}

TEST(ServerFeatures, PowerFailRecordInTheStatusThenARetractConfirmedByTheOperator) {
  ServerRig rig(featured("broach-zc.toml"));
  for (const char* k : {"machine-on"}) ASSERT_EQ(rig.command({{"kind", k}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "mode"}, {"mode", "auto"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "open"}, {"program", "broach-constant.ngc"}}).status, 200);
  const json before = rig.status();
  EXPECT_EQ(before["features"]["installed"], json({"journal", "run-from-line"}));
  EXPECT_TRUE(before["features"]["journal"]["record"].is_null());
  EXPECT_EQ(before["load"]["hold_kn"], 4.0);
  ASSERT_EQ(rig.command({{"kind", "cycle-start"}}).status, 200);
  // Mid-cut (the load cell pulls): the mains fail. The operator may not simulate.
  ASSERT_TRUE(rig.until([](const json& s) { return s["load"]["kn"].get<double>() > 1.0; }));
  EXPECT_EQ(rig.command({{"kind", "simulate"}, {"event", "mains-off"}}).status, 403);
  ASSERT_EQ(rig.command({{"kind", "simulate"}, {"event", "mains-off"}}, kAdmin).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) {
    const json& r = s["features"]["journal"]["record"];
    return !r.is_null() && r["stage"] == "at-rest";
  }));
  json s = rig.status();
  EXPECT_EQ(s["state"], "faulted");
  EXPECT_EQ(s["power"]["mains_ok"], false);
  const json& j = s["features"]["journal"];
  EXPECT_EQ(j["record"]["valid"], true);
  EXPECT_EQ(j["record"]["coupled"], true);
  EXPECT_TRUE(j["record"]["program"].get<std::string>().ends_with("broach-constant.ngc"));
  EXPECT_TRUE(j["can_resume"].get<bool>());
  EXPECT_TRUE(j["can_retract"].get<bool>());
  EXPECT_EQ(j["resume_defaults"]["tolerance_mm"], rig.profile.power.resume_tolerance_mm);  // the dialog's
  EXPECT_EQ(j["resume_defaults"]["run_in_mm"], rig.profile.power.resume_run_in_mm);
  // Unconfirmed: 400 and nothing happens.
  EXPECT_EQ(rig.command({{"kind", "feature"}, {"feature", "journal"}, {"action", "discard"}}).status, 400);
  // The power returns; reset, machine on; the retract, confirmed, completes and clears the record.
  ASSERT_EQ(rig.command({{"kind", "simulate"}, {"event", "mains-on"}}, kAdmin).status, 200);
  ASSERT_TRUE(rig.until([](const json& st) { return st["power"]["mains_ok"].get<bool>(); }));
  ASSERT_EQ(rig.command({{"kind", "reset"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "machine-on"}}).status, 200);
  const double z = rig.status()["machine"]["Z"].get<double>();
  const Reply retract = rig.command({{"kind", "feature"},
                                     {"feature", "journal"},
                                     {"action", "retract"},
                                     {"distance_mm", 2},
                                     {"direction", "back"},
                                     {"speed_mm_min", 600},
                                     {"confirmed", true}});
  ASSERT_EQ(retract.status, 200) << retract.body.dump();
  // Done, then the record written again without its valid flag (the writer's thread makes it durable).
  ASSERT_TRUE(rig.until([](const json& st) {
    return st["features"]["journal"]["phase"] == "done" &&
           st["features"]["journal"]["record"]["valid"] == false;
  }));
  s = rig.status();
  EXPECT_EQ(s["features"]["journal"]["record"]["valid"], false);
  EXPECT_NEAR(std::abs(s["machine"]["Z"].get<double>() - z), 2.0, 0.01);
  // With no valid record a choice is the controller's refusal: 409 with the reason.
  const Reply again =
      rig.command({{"kind", "feature"}, {"feature", "journal"}, {"action", "discard"}, {"confirmed", true}});
  EXPECT_EQ(again.status, 409);
  EXPECT_EQ(again.body["message"], "the journal holds no valid breakpoint");
}

TEST(ServerFeatures, RetracePausesStepsBackAndCutsOnFromTheNearestPoint) {
  ServerRig rig(featured("flame-cutter.toml"));
  EXPECT_EQ(rig.status()["features"]["installed"], json({"retrace", "run-from-line"}));
  ASSERT_EQ(rig.command({{"kind", "machine-on"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "home"}}).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["all_homed"] == true; }));
  ASSERT_EQ(rig.command({{"kind", "mode"}, {"mode", "auto"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "open"}, {"program", "nesting.ngc"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "cycle-start"}}).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["job"]["progress"].get<double>() > 0.05; }));
  const json retrace = {{"kind", "feature"}, {"feature", "retrace"}};
  auto with = [&retrace](json extra) {
    extra.update(retrace);
    return extra;
  };
  ASSERT_EQ(rig.command(with({{"action", "pause"}})).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["features"]["retrace"]["phase"] == "paused"; }));
  EXPECT_EQ(rig.status()["mode"], "manual");  // the operator may jog the torch off the path
  ASSERT_EQ(rig.command(with({{"action", "step"}, {"distance_mm", -5}})).status, 200);
  // The status the rig reads may be a stream period older than the step's answer: see the step
  // under way (5 mm at 1000 mm/min: 0.3 s, many periods) before waiting for its end.
  ASSERT_TRUE(rig.until([](const json& s) { return s["features"]["retrace"]["phase"] == "stepping"; }));
  ASSERT_TRUE(rig.until([](const json& s) { return s["features"]["retrace"]["phase"] == "paused"; }));
  EXPECT_EQ(rig.command(with({{"action", "start"}})).status, 400);  // not confirmed
  const Reply start = rig.command(with({{"action", "start"}, {"confirmed", true}}));
  ASSERT_EQ(start.status, 200) << start.body.dump();
  ASSERT_TRUE(rig.until([](const json& s) { return s["features"]["retrace"]["phase"] == "cutting"; }));
  const json last = rig.status()["features"]["retrace"]["last"];
  EXPECT_EQ(rig.status()["features"]["retrace"]["retraces"], 1);
  EXPECT_TRUE(last["line"].get<std::string>().find("nesting.ngc:") != std::string::npos) << last.dump();
  EXPECT_LT(last["distance_mm"].get<double>(), 0.01);  // the torch stood on the path: C is where it stood
}

TEST(ServerFeatures, ElectrodeMeasuredOnTheSphereIsShownThenStoredOnConfirmation) {
  // A copy of the tool table: the write goes into it, not into the repository's file.
  const auto tables =
      std::filesystem::temp_directory_path() / ("opencnc-electrode-" + std::to_string(::getpid()));
  std::filesystem::create_directories(tables);
  std::filesystem::copy_file(OPENCNC_SOURCE_DIR "/configs/edm-5axis.tbl", tables / "edm-5axis.tbl",
                             std::filesystem::copy_options::overwrite_existing);
  ServerRig rig(
      featured("edm-5axis.toml", {"interpreter.tool_table=\"" + (tables / "edm-5axis.tbl").string() + "\""}));
  EXPECT_EQ(rig.status()["features"]["installed"], json({"electrode", "run-from-line"}));
  ASSERT_EQ(rig.command({{"kind", "machine-on"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "home"}}).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["all_homed"] == true; }));
  // The electrode in the spindle sits 0.05, -0.03 and 0.2 mm off tool 1's table offsets (0, 0, 0).
  ASSERT_EQ(rig.command({{"kind", "simulate"},
                         {"event", "electrode"},
                         {"offset", {0.05, -0.03, 0.2}},
                         {"tip_radius", 0.8}},
                        kAdmin)
                .status,
            200);
  const Reply measure =
      rig.command({{"kind", "feature"}, {"feature", "electrode"}, {"action", "measure"}, {"tool", 1}});
  ASSERT_EQ(measure.status, 200) << measure.body.dump();
  ASSERT_TRUE(rig.until([](const json& s) {
    const json& e = s["features"]["electrode"];
    return e["phase"] == "idle" && !e["last"].is_null();
  }));
  const json last = rig.status()["features"]["electrode"]["last"];
  ASSERT_EQ(last["ok"], true) << last.dump();
  EXPECT_EQ(last["written"], false);
  EXPECT_NEAR(last["offset"][0].get<double>(), 0.05, 0.002);
  EXPECT_NEAR(last["offset"][1].get<double>(), -0.03, 0.002);
  EXPECT_NEAR(last["offset"][2].get<double>(), 0.2, 0.002);
  auto z_of_tool_1 = [&rig] {
    return get(rig.port, "/api/v1/tools", kOperator).body[0]["z_offset"].get<double>();
  };
  EXPECT_EQ(z_of_tool_1(), 0.0);  // shown, not stored
  EXPECT_EQ(rig.command({{"kind", "feature"}, {"feature", "electrode"}, {"action", "write"}}).status, 400);
  const Reply write =
      rig.command({{"kind", "feature"}, {"feature", "electrode"}, {"action", "write"}, {"confirmed", true}});
  ASSERT_EQ(write.status, 200) << write.body.dump();
  EXPECT_NEAR(z_of_tool_1(), 0.2, 0.002);
  ASSERT_TRUE(rig.until([](const json& s) { return s["features"]["electrode"]["last"]["written"] == true; }));
  // Stored once: a second write is the feature's refusal.
  EXPECT_EQ(
      rig.command({{"kind", "feature"}, {"feature", "electrode"}, {"action", "write"}, {"confirmed", true}})
          .status,
      409);
  // No calibration of B's axis yet (calibrate-b's request is FeatureParse's; through the server
  // it would be three more measurements in a test that is already the slowest under ASan).
  EXPECT_TRUE(rig.status()["features"]["electrode"]["b_axis"].is_null());
  std::filesystem::remove_all(tables);
}

/// A tool store made from hmc-toolcheck's table and backed up, and a three-tool program, in a
/// folder of their own.
struct GuardedStore {
  GuardedStore() {
    dir = std::filesystem::temp_directory_path() / ("opencnc-guard-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::string error, text;
    store = store::ToolStore::open((dir / "tools.db").string(), &error);
    EXPECT_NE(store, nullptr) << error;
    EXPECT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/hmc-toolcheck.tbl", text, &error)) << error;
    Diagnostics d;
    const auto set = tools::from_linuxcnc(tools::ToolTable::parse(text, "hmc-toolcheck.tbl", d), "hmc", d);
    EXPECT_TRUE(set && store->write(*set, "test", "import", &error)) << error;
    EXPECT_TRUE(store->backup("test", "backup", &error)) << error;
    std::ofstream(dir / "three-tools.ngc") << "G21 G90\nT1 M6\nG43 H1\nG0 X0 Y0 Z10\nT3 M6\nG43 H3\nG0 Z20\n"
                                              "T5 M6\nG43 H5\nG0 Z30\nM2\n";
  }
  ~GuardedStore() { std::filesystem::remove_all(dir); }
  std::vector<std::string> sets() const {
    return {"tool_guard.store=\"" + (dir / "tools.db").string() + "\"", "tool_guard.check=\"tool-change\"",
            "tool_changer.sim.prepare_time_s=0.05", "tool_changer.sim.change_time_s=0.1"};
  }
  std::filesystem::path dir;
  std::shared_ptr<store::ToolStore> store;
};

TEST(ServerFeatures, TheToolGuardsHoldShowsTheDifferencesAndARestoreLetsTheProgramGoOn) {
  GuardedStore tools;
  std::string error;
  ASSERT_TRUE(tools.store->set(5, 1, tools::Param::Length1, 139.225, "test", &error)) << error;  // a typo
  ServerRig rig(featured("hmc-toolcheck.toml", tools.sets(), tools.dir));
  EXPECT_EQ(rig.status()["features"]["installed"], json({"tool-guard", "run-from-line"}));
  ASSERT_EQ(rig.command({{"kind", "machine-on"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "mode"}, {"mode", "auto"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "open"}, {"program", "three-tools.ngc"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "cycle-start"}}).status, 200);
  ASSERT_TRUE(rig.until([](const json& s) { return s["features"]["tool_guard"]["holding"] == true; }));
  const json held = rig.status()["features"]["tool_guard"];
  EXPECT_EQ(held["check"]["ok"], false);
  EXPECT_EQ(held["check"]["backup"]["id"], 1);
  ASSERT_EQ(held["check"]["differences"].size(), 1u);
  EXPECT_EQ(held["check"]["difference_tools"], json::array({5}));
  EXPECT_EQ(held["check"]["differences"][0],
            "T5 D1 length1: backup 193.225, live 139.225 (-54 mm; geometry tolerance 0.001 mm)");
  // No silent overwrite: a restore without the operator's confirmation changes nothing.
  EXPECT_EQ(rig.command({{"kind", "feature"}, {"feature", "tool-guard"}, {"action", "restore"}}).status, 400);
  EXPECT_EQ(rig.status()["features"]["tool_guard"]["holding"], true);
  const Reply restored = rig.command(
      {{"kind", "feature"}, {"feature", "tool-guard"}, {"action", "restore"}, {"confirmed", true}});
  ASSERT_EQ(restored.status, 200) << restored.body.dump();
  EXPECT_EQ(restored.body["message"], "backup 1 is the live tool table again");
  ASSERT_TRUE(
      rig.until([](const json& s) { return s["runs_finished"].get<int>() >= 1 && s["state"] == "idle"; }));
  EXPECT_EQ(rig.status()["features"]["tool_guard"]["holding"], false);
  EXPECT_TRUE(rig.status()["features"]["tool_guard"]["check"].is_null());
}

}  // namespace
}  // namespace opencnc::hmi
