// SPDX-License-Identifier: GPL-3.0-or-later
// The admin's machine parameters, pitch-error tables and EDM machining conditions through the HMI
// server on loopback: read by anyone with a token, changed by the admin only (403 for the
// operator), a bad value answered with the profile's own message and nothing changed, a busy
// machine refused, a good one in the file and the live limits, audited.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "../control/test_profiles.hpp"
#include "../support/drill_comp_file.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/hmi/api.hpp"
#include "opencnc/hmi/history.hpp"
#include "server_rig.hpp"

namespace opencnc::hmi {
namespace {

using namespace test;
using nlohmann::json;

/// The simulated mill, its profile a copy in the rig's folder that the admin may edit.
struct AdminRig : ServerRig {
  AdminRig() : ServerRig(options()) {}
  static RigOptions options() {
    RigOptions o;
    o.profile_copy = true;
    return o;
  }
  double parameter(const std::string& key) {
    const Reply r = get(port, "/api/v1/parameters", kOperator);
    for (const json& p : r.body["parameters"])
      if (p["key"] == key) return p["value"].get<double>();
    return -1;
  }
};

TEST(AdminParameters, TheOperatorReadsThemOnlyTheAdminChangesThem) {
  AdminRig rig;
  const Reply list = get(rig.port, "/api/v1/parameters", kOperator);
  ASSERT_EQ(list.status, 200);
  EXPECT_EQ(list.body["profile"], rig.profile_path);
  EXPECT_EQ(list.body["parameters"].size(), 15u);
  EXPECT_EQ(list.body["parameters"][0], (json{{"key", "axis.x.max_velocity"},
                                              {"value", 100.0},
                                              {"unit", "mm/s"},
                                              {"what", "fastest speed of the axis"}}));
  const std::string change = R"({"kind":"set-parameters","values":{"axis.x.max_velocity":40}})";
  EXPECT_EQ(post(rig.port, change, kOperator).status, 403);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  EXPECT_EQ(get(rig.port, "/api/v1/status").body["limits_version"], 0);
  const Reply ok = post(rig.port, change, kAdmin);
  ASSERT_EQ(ok.status, 200) << ok.text;
  EXPECT_EQ(ok.body["message"], "axis.x.max_velocity 100.0 → 40.0");
  // The status tells the pages the limits changed (the 3D view reads the soft-limit box again).
  EXPECT_TRUE(rig.until([](const json& s) { return s["limits_version"] == 1; }, 5));
  std::string expected = rig.profile_original;
  expected.replace(expected.find("max_velocity = 100.0"), 20, "max_velocity = 40.0");
  EXPECT_EQ(rig.profile_text(), expected);
  EXPECT_EQ(rig.parameter("axis.x.max_velocity"), 40.0);
  EXPECT_EQ(get(rig.port, "/api/v1/machine", kOperator).body["axes"][0]["max_velocity"], 40.0);
  // The API's own checks use the new limit at once: a jog above it is a 422.
  EXPECT_EQ(post(rig.port, R"({"kind":"jog","axis":"X","velocity":50})", kOperator).status, 422);
  rig.history->flush();
  const json audit = get(rig.port, "/api/v1/audit", kAdmin).body;
  ASSERT_GE(audit.size(), 2u);
  const json& done = audit[audit.size() - 2];  // newest first: the jog, the change, the refusal
  EXPECT_EQ(done["role"], "admin");
  EXPECT_EQ(done["status"], 200);
  EXPECT_EQ(done["result"], "accepted: axis.x.max_velocity 100.0 → 40.0");
  EXPECT_EQ(audit.back()["status"], 403);
}

TEST(AdminParameters, ABadValueGetsTheProfilesMessageAndNothingChanges) {
  AdminRig rig;
  const Reply bad =
      post(rig.port, R"({"kind":"set-parameters","values":{"axis.z.max_acceleration":-3}})", kAdmin);
  ASSERT_EQ(bad.status, 409) << bad.text;
  EXPECT_EQ(bad.body["code"], "control.bad-value");
  ASSERT_FALSE(bad.body["diagnostics"].empty());
  const std::string text = bad.body["diagnostics"][0]["text"];
  EXPECT_EQ(text.rfind(rig.profile_path + ":", 0), 0u) << text;  // file:line:col: error: message
  EXPECT_NE(text.find("max_acceleration"), std::string::npos) << text;
  EXPECT_EQ(bad.body["message"].get<std::string>().rfind(
                "the profile refuses the change: " + rig.profile_path + ":", 0),
            0u);
  EXPECT_EQ(
      post(rig.port, R"({"kind":"set-parameters","values":{"axis.x.homing.position":1}})", kAdmin).status,
      422);
  EXPECT_EQ(
      post(rig.port, R"({"kind":"set-parameters","values":{"axis.x.max_velocity":"fast"}})", kAdmin).status,
      400);
  EXPECT_EQ(post(rig.port, R"({"kind":"set-parameters","values":{}})", kAdmin).status, 400);
  EXPECT_EQ(post(rig.port, R"({"kind":"set-parameters"})", kAdmin).status, 400);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  EXPECT_EQ(rig.parameter("axis.z.max_acceleration"), 1000.0);
}

TEST(ApiAdmin, SetParametersIsTheAdminsAndBecomesAnEditProfileRequest) {
  EXPECT_EQ(role_for("set-parameters"), Role::Admin);
  EXPECT_EQ(role_for("set-compensation"), Role::Admin);
  const config::MachineProfile p = control::test::mill();
  const auto parsed =
      parse_command(json::parse(R"({"kind":"set-parameters","values":{"axis.y.max_limit":500.5}})"), p,
                    OPENCNC_SOURCE_DIR "/examples");
  const auto* c = std::get_if<Command>(&parsed);
  ASSERT_NE(c, nullptr);
  const auto& r = std::get<controller::Request>(*c);
  const auto& e = std::get<controller::requests::EditProfile>(r.body);
  ASSERT_EQ(e.edits.size(), 1u);
  EXPECT_EQ(e.edits[0].key, "axis.y.max_limit");
  EXPECT_EQ(e.edits[0].value, "500.5");
  EXPECT_EQ(r.name(), "edit-profile");
}

/// A machine whose profile is a copy (with its tool table) the admin may edit, with a history.
struct EditableRig : ServerRig {
  explicit EditableRig(const char* machine) : ServerRig(options(machine)) {}
  static RigOptions options(const char* machine) {
    RigOptions o;
    o.machine = machine;
    o.profile_copy = true;
    o.history = true;
    return o;
  }
};

TEST(AdminCompensation, TheOperatorReadsTheTablesOnlyTheAdminChangesThem) {
  EditableRig rig("drill-retrofit.toml");  // X's table one for both ways, Y's per direction
  const Reply list = get(rig.port, "/api/v1/compensation", kOperator);
  ASSERT_EQ(list.status, 200) << list.text;
  ASSERT_EQ(list.body["axes"].size(), 2u);
  const json& x = list.body["axes"][0];
  EXPECT_EQ(x["axis"], "X");
  EXPECT_EQ(x["backlash"], 0.02);
  EXPECT_EQ(x["table"]["one_table"], true);
  EXPECT_EQ(x["table"]["positions"].size(), 13u);
  EXPECT_EQ(x["table"]["forward"][3], 0.010);
  EXPECT_EQ(x["editable"], true);
  const std::string change =
      R"({"kind":"set-compensation","axis":"X","interval":100,"forward":[0,0.006,0.015,0.022,0.028,0.033,0.04],)"
      R"("reverse":[0.002,0.008,0.017,0.024,0.030,0.035,0.042]})";
  EXPECT_EQ(post(rig.port, change, kOperator).status, 403);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  const Reply ok = post(rig.port, change, kAdmin);
  ASSERT_EQ(ok.status, 200) << ok.text;
  EXPECT_EQ(ok.body["message"],
            "axis.x.compensation.interval 50.0 → 100.0; axis.x.compensation.forward 13 points → 7 points; "
            "axis.x.compensation.reverse 13 points → 7 points");
  const std::string text = rig.profile_text();
  EXPECT_NE(text.find("forward = [0.0, 0.006, 0.015, 0.022, 0.028, 0.033, 0.04]\n"), std::string::npos);
  EXPECT_EQ(text.find("errors = ["), std::string::npos);
  EXPECT_NE(text.find("# The seed's table as it entered it"), std::string::npos);
  const json now = get(rig.port, "/api/v1/compensation", kOperator).body["axes"][0]["table"];
  EXPECT_EQ(now["positions"][6], 600.0);
  EXPECT_EQ(now["reverse"][0], 0.002);
  EXPECT_EQ(now["one_table"], false);
  rig.history->flush();
  const json audit = get(rig.port, "/api/v1/audit", kAdmin).body;
  ASSERT_GE(audit.size(), 2u);
  EXPECT_EQ(audit[0]["result"], "accepted: " + ok.body["message"].get<std::string>());
  EXPECT_EQ(audit[0]["role"], "admin");
}

TEST(AdminCompensation, ABadTableGetsTheProfilesMessageAndNothingChanges) {
  EditableRig rig("drill-retrofit.toml");  // X's table one for both ways, Y's per direction
  const Reply steep = post(
      rig.port,
      R"({"kind":"set-compensation","axis":"y","forward":[0,0,0,0,0,0,0,0,2],"reverse":[0,0,0,0,0,0,0,0,0]})",
      kAdmin);
  ASSERT_EQ(steep.status, 409) << steep.text;
  EXPECT_EQ(steep.body["code"], "control.bad-value");
  ASSERT_FALSE(steep.body["diagnostics"].empty());
  const std::string text = steep.body["diagnostics"][0]["text"];
  EXPECT_EQ(text.rfind(rig.profile_path + ":", 0), 0u) << text;
  const std::string unequal = R"({"kind":"set-compensation","axis":"Y","forward":[0,0.001],"reverse":[0]})";
  EXPECT_EQ(post(rig.port, unequal, kAdmin).status, 409);
  EXPECT_EQ(
      post(rig.port, R"({"kind":"set-compensation","axis":"Z","forward":[0],"reverse":[0]})", kAdmin).status,
      422);
  json big = {
      {"kind", "set-compensation"}, {"axis", "X"}, {"forward", json::array()}, {"reverse", json::array()}};
  for (int i = 0; i < 257; ++i) {
    big["forward"].push_back(0.0);
    big["reverse"].push_back(0.0);
  }
  EXPECT_EQ(post(rig.port, big.dump(), kAdmin).status, 422);
  EXPECT_EQ(post(rig.port, R"({"kind":"set-compensation","axis":"X","forward":[0]})", kAdmin).status, 400);
  EXPECT_EQ(post(rig.port, R"({"kind":"set-compensation","axis":"X","forward":["a"],"reverse":[0]})", kAdmin)
                .status,
            400);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  EXPECT_EQ(get(rig.port, "/api/v1/compensation", kOperator).body["axes"][1]["table"]["forward"][8], -0.012);
}

// The drill with Y's table in a LinuxCNC comp file: listed as editable with its file and type;
// the admin's table goes into that file (comment lines kept, the profile untouched), into the
// live table and the audit; positions that do not increase get the loader's message at the comp
// file's line; start and interval are refused; nothing changed.
TEST(AdminCompensation, ATableInACompFileIsWrittenThere) {
  RigOptions o = EditableRig::options("drill-retrofit.toml");
  o.edit_copy = [](const std::string& text, const std::filesystem::path& dir) {
    EXPECT_TRUE(write_file_atomically((dir / opencnc::test::kDrillYCompName).string(),
                                      opencnc::test::kDrillYComp, nullptr));
    return opencnc::test::drill_with_y_comp_file(text);
  };
  ServerRig rig(o);
  const std::string comp = (rig.dir / opencnc::test::kDrillYCompName).string();
  const json y = get(rig.port, "/api/v1/compensation", kOperator).body["axes"][1];
  EXPECT_EQ(y["comp_file"], opencnc::test::kDrillYCompName);
  EXPECT_EQ(y["comp_file_type"], 0);
  EXPECT_EQ(y["editable"], true);
  ASSERT_EQ(y["table"]["positions"].size(), 9u);
  const std::string bad =
      R"({"kind":"set-compensation","axis":"Y","positions":[0,50,100,150,150,250,300,350,400],)"
      R"("forward":[0,0,0,0,0,0,0,0,0],"reverse":[0,0,0,0,0,0,0,0,0]})";
  const Reply refused = post(rig.port, bad, kAdmin);
  ASSERT_EQ(refused.status, 409) << refused.text;
  const std::string where = refused.body["diagnostics"][0]["text"];
  EXPECT_EQ(where.rfind(comp + ":7:1:", 0), 0u) << where;
  EXPECT_EQ(
      post(rig.port, R"({"kind":"set-compensation","axis":"Y","interval":10,"forward":[0],"reverse":[0]})",
           kAdmin)
          .status,
      422);
  EXPECT_EQ(
      post(rig.port, R"({"kind":"set-compensation","axis":"X","positions":[0],"forward":[0],"reverse":[0]})",
           kAdmin)
          .status,
      422);
  std::string text;
  ASSERT_TRUE(read_file(comp, text, nullptr));
  EXPECT_EQ(text, opencnc::test::kDrillYComp);
  const std::string change =
      R"({"kind":"set-compensation","axis":"Y","forward":[0,-0.002,-0.004,-0.0045,-0.006,-0.007,-0.009,-0.0105,-0.012],)"
      R"("reverse":[0.015,0.013,0.011,0.0105,0.01,0.008,0.006,0.0045,0.003]})";
  EXPECT_EQ(post(rig.port, change, kOperator).status, 403);
  const Reply ok = post(rig.port, change, kAdmin);
  ASSERT_EQ(ok.status, 200) << ok.text;
  EXPECT_EQ(ok.body["message"],
            "axis.y.compensation.forward 9 points → 9 points, 1 changed (largest -0.005 → -0.006 at 200.0); "
            "axis.y.compensation.reverse 9 points → 9 points, unchanged");
  ASSERT_TRUE(read_file(comp, text, nullptr));
  std::string expected = opencnc::test::kDrillYComp;
  expected.replace(expected.find("199.995"), 7, "199.994");
  EXPECT_EQ(text, expected);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  const json now = get(rig.port, "/api/v1/compensation", kOperator).body["axes"][1]["table"];
  EXPECT_NEAR(now["forward"][4].get<double>(), -0.006, 1e-12);
  rig.history->flush();
  const json audit = get(rig.port, "/api/v1/audit", kAdmin).body;
  ASSERT_GE(audit.size(), 1u);
  EXPECT_EQ(audit[0]["result"], "accepted: " + ok.body["message"].get<std::string>());
}

TEST(AdminConditions, AnEdmsConditionsAreListedInTheProfilesOrder) {
  RigOptions o;
  o.machine = "edm-5axis.toml";
  o.history = false;
  ServerRig rig(o);
  const Reply r = get(rig.port, "/api/v1/conditions", kOperator);
  ASSERT_EQ(r.status, 200) << r.text;
  const json& list = r.body["conditions"];
  ASSERT_EQ(list.size(), 4u);
  EXPECT_EQ(list[0]["number"], 1);
  EXPECT_EQ(list[0]["peak_current_a"], 12.0);
  EXPECT_EQ(list[0]["on_time_us"], 100.0);
  EXPECT_EQ(list[0]["polarity"], "+");
  EXPECT_EQ(list[0]["jump_height_mm"], 0.4);
  EXPECT_EQ(list[1]["orbit"], "circle");
  EXPECT_EQ(list[2]["orbit"], "square");
  EXPECT_EQ(list[2]["jump_mode"], "path");
  EXPECT_EQ(list[3]["number"], 9);
  EXPECT_EQ(get(rig.port, "/api/v1/conditions", "").status, 401);
}

// The condition sequence for an electrode: its steps with their orbits and, with a depth, the
// program; what the table does not allow in words (422), a malformed query 400.
TEST(AdminConditions, TheSequenceForAnElectrodeIsPlannedFromTheTable) {
  RigOptions o;
  o.machine = "edm-5axis.toml";
  o.history = false;
  ServerRig rig(o);
  const Reply r = get(
      rig.port, "/api/v1/edm-sequence?area=20&finish=VDI18&undersize=0.08&surface=-20&depth=0.1", kOperator);
  ASSERT_EQ(r.status, 200) << r.text;
  ASSERT_EQ(r.body["steps"].size(), 3u);
  EXPECT_EQ(r.body["steps"][0]["condition"], 1);
  EXPECT_EQ(r.body["steps"][2]["condition"], 3);
  EXPECT_NEAR(r.body["steps"][2]["orbit_mm"].get<double>(), 0.068, 1e-9);
  EXPECT_EQ(r.body["vdi"], 18);
  EXPECT_NE(r.body["program"].get<std::string>().find("M180 P3 Q0.0680\nG1 Z-20.1000"), std::string::npos);
  const Reply small = get(rig.port, "/api/v1/edm-sequence?area=2&finish=0.8&undersize=0.08", kOperator);
  EXPECT_EQ(small.status, 422);
  EXPECT_NE(small.body["message"].get<std::string>().find("takes at most 1.2 A"), std::string::npos)
      << small.text;
  const Reply bad = get(rig.port, "/api/v1/edm-sequence?area=x&finish=0.8&undersize=0.08", kOperator);
  EXPECT_EQ(bad.status, 400);
  EXPECT_EQ(bad.body["message"], "\"area\" must be a number, not \"x\"");
  EXPECT_EQ(get(rig.port, "/api/v1/edm-sequence?area=20&undersize=0.08", kOperator).body["message"],
            "\"finish\" is needed");
}

// A boolean of issue 28 through set-conditions: a TOML boolean in the file, refused as a number.
TEST(AdminConditions, TheAdaptiveSwitchIsSetAsAChoice) {
  EditableRig rig("edm-5axis.toml");
  const Reply ok =
      post(rig.port, R"({"kind":"set-conditions","condition":3,"values":{"adaptive":"false"}})", kAdmin);
  ASSERT_EQ(ok.status, 200) << ok.text;
  EXPECT_EQ(ok.body["message"], "edm.condition.3.adaptive true → false");
  std::string expected = rig.profile_original;
  expected.replace(expected.find("adaptive = true\ngain_max"), 15, "adaptive = false");
  EXPECT_EQ(rig.profile_text(), expected);
  EXPECT_EQ(
      post(rig.port, R"({"kind":"set-conditions","condition":3,"values":{"adaptive":1}})", kAdmin).status,
      400);
}

TEST(AdminConditions, TheOperatorReadsThemOnlyTheAdminChangesThemAndTheChangeIsAudited) {
  EditableRig rig("edm-5axis.toml");
  const json fields = get(rig.port, "/api/v1/conditions", kOperator).body["fields"];
  ASSERT_EQ(fields.size(), 31u);  // issue 28's finishing and adaptive keys among them
  EXPECT_EQ(fields[21]["choices"], json::array({"true", "false"}));
  EXPECT_EQ(fields[0], (json{{"key", "on_time_us"}, {"unit", "µs"}, {"what", "pulse on-time"}}));
  EXPECT_EQ(fields[4]["choices"], json::array({"+", "-"}));
  const std::string change =
      R"({"kind":"set-conditions","condition":3,"values":{"on_time_us":20,"orbit":"circle"}})";
  EXPECT_EQ(post(rig.port, change, kOperator).status, 403);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  const Reply ok = post(rig.port, change, kAdmin);
  ASSERT_EQ(ok.status, 200) << ok.text;
  EXPECT_EQ(ok.body["message"],
            "edm.condition.3.on_time_us 15.0 → 20.0; edm.condition.3.orbit square → circle");
  std::string expected = rig.profile_original;
  expected.replace(expected.find("on_time_us = 15.0"), 17, "on_time_us = 20.0");
  expected.replace(expected.find("orbit = \"square\""), 16, "orbit = \"circle\"");
  EXPECT_EQ(rig.profile_text(), expected);
  const json now = get(rig.port, "/api/v1/conditions", kOperator).body["conditions"][2];
  EXPECT_EQ(now["on_time_us"], 20.0);
  EXPECT_EQ(now["orbit"], "circle");
  rig.history->flush();
  const json audit = get(rig.port, "/api/v1/audit", kAdmin).body;
  ASSERT_GE(audit.size(), 2u);
  EXPECT_EQ(audit[0]["result"], "accepted: " + ok.body["message"].get<std::string>());
  EXPECT_EQ(audit[0]["role"], "admin");
  EXPECT_EQ(audit[1]["status"], 403);
}

TEST(AdminConditions, ABadValueGetsTheProfilesMessageAndABusyMachineIsRefusedAndNothingChanges) {
  EditableRig rig("edm-5axis.toml");
  const Reply bad =
      post(rig.port, R"({"kind":"set-conditions","condition":1,"values":{"servo_reference_v":150}})", kAdmin);
  ASSERT_EQ(bad.status, 409) << bad.text;
  EXPECT_EQ(bad.body["code"], "control.bad-value");
  ASSERT_FALSE(bad.body["diagnostics"].empty());
  const std::string text = bad.body["diagnostics"][0]["text"];
  EXPECT_EQ(text.rfind(rig.profile_path + ":", 0), 0u) << text;  // file:line:col: error: message
  EXPECT_NE(text.find("must be below voltage_v"), std::string::npos) << text;
  const auto status = [&](const char* body) { return post(rig.port, body, kAdmin).status; };
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":4,"values":{"on_time_us":1}})"), 422);
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":1,"values":{"side_gap_mm":0.1}})"), 422);
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":1,"values":{"polarity":"x"}})"), 422);
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":1,"values":{"polarity":1}})"), 400);
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":1,"values":{"on_time_us":"long"}})"), 400);
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":"1","values":{"on_time_us":1}})"), 400);
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":1,"values":{}})"), 400);
  // A jog runs: the change waits for the machine to stand still.
  EXPECT_EQ(post(rig.port, R"({"kind":"machine-on"})", kOperator).status, 200);
  EXPECT_EQ(post(rig.port, R"({"kind":"jog","axis":"Z","velocity":1})", kOperator).status, 200);
  const Reply busy =
      post(rig.port, R"({"kind":"set-conditions","condition":1,"values":{"on_time_us":90}})", kAdmin);
  EXPECT_EQ(busy.status, 409) << busy.text;
  EXPECT_EQ(busy.body["code"], "control.busy");
  EXPECT_EQ(post(rig.port, R"({"kind":"jog-stop","axis":"Z"})", kOperator).status, 200);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  EXPECT_EQ(get(rig.port, "/api/v1/conditions", kOperator).body["conditions"][0]["on_time_us"], 100.0);
}

TEST(AdminConditions, TheAdminAddsACopyAndDeletesOneTheOpenProgramDoesNotSelect) {
  EditableRig rig("edm-5axis.toml");
  ASSERT_EQ(rig.command({{"kind", "machine-on"}}).status, 200);
  ASSERT_EQ(rig.command({{"kind", "mode"}, {"mode", "auto"}}).status, 200);
  const Reply open = rig.command({{"kind", "open"}, {"program", "edm-turbine-channel.ngc"}});
  ASSERT_EQ(open.status, 200) << open.text;
  const std::string add = R"({"kind":"add-condition","condition":4})";  // a copy of 3, the one below
  EXPECT_EQ(post(rig.port, add, kOperator).status, 403);
  const Reply added = post(rig.port, add, kAdmin);
  ASSERT_EQ(added.status, 200) << added.text;
  EXPECT_EQ(added.body["message"], "edm.condition.4 none → a copy of condition 3");
  // The open program selects 3 (line 29): deleting it is refused with that line, nothing changes.
  const std::string after_add = rig.profile_text();
  const Reply selected = post(rig.port, R"({"kind":"delete-condition","condition":3})", kAdmin);
  ASSERT_EQ(selected.status, 409) << selected.text;
  EXPECT_EQ(selected.body["code"], "control.program");
  const std::string why = selected.body["message"];
  EXPECT_NE(why.find("the open program selects a condition this would delete"), std::string::npos) << why;
  EXPECT_NE(why.find("edm-turbine-channel.ngc:29:"), std::string::npos) << why;
  EXPECT_EQ(rig.profile_text(), after_add);
  const Reply deleted = post(rig.port, R"({"kind":"delete-condition","condition":9})", kAdmin);
  ASSERT_EQ(deleted.status, 200) << deleted.text;
  EXPECT_EQ(deleted.body["message"], "edm.condition.9 defined → deleted");
  const json list = get(rig.port, "/api/v1/conditions", kOperator).body["conditions"];
  ASSERT_EQ(list.size(), 4u);
  EXPECT_EQ(list[3]["number"], 4);
  EXPECT_EQ(list[3]["on_time_us"], 15.0);  // condition 3's
  EXPECT_EQ(list[3]["orbit"], "square");
  const std::string text = rig.profile_text();
  EXPECT_NE(text.find("# Condition 4: a copy of condition 3.\n[[edm.condition]]\nnumber = 4\n"), std::string::npos);
  EXPECT_EQ(text.find("number = 9"), std::string::npos);
  EXPECT_NE(text.find("# Finishing: 2 A"), std::string::npos);  // the others' comments stay
  rig.history->flush();
  const json audit = get(rig.port, "/api/v1/audit", kAdmin).body;
  ASSERT_GE(audit.size(), 4u);
  EXPECT_EQ(audit[0]["result"], "accepted: edm.condition.9 defined → deleted");
  EXPECT_EQ(audit[1]["status"], 409);
  EXPECT_EQ(audit[2]["result"], "accepted: edm.condition.4 none → a copy of condition 3");
}

TEST(AdminConditions, AddsAndDeletesThatCannotBeAreRefusedAndChangeNothing) {
  EditableRig rig("edm-5axis.toml");
  const auto status = [&](const char* body) { return post(rig.port, body, kAdmin).status; };
  EXPECT_EQ(status(R"({"kind":"add-condition","condition":3})"), 422);               // exists
  EXPECT_EQ(status(R"({"kind":"add-condition","condition":0})"), 422);               // 1 to 99
  EXPECT_EQ(status(R"({"kind":"add-condition","condition":4294967300})"), 422);      // not 4
  EXPECT_EQ(status(R"({"kind":"delete-condition","condition":4294967305})"), 422);   // not 9
  EXPECT_EQ(status(R"({"kind":"set-conditions","condition":4294967297,"values":{"on_time_us":1}})"), 422);
  EXPECT_EQ(status(R"({"kind":"add-condition","condition":5,"from":6})"), 422);      // no 6 to copy
  EXPECT_EQ(status(R"({"kind":"add-condition","condition":5,"from":"3"})"), 400);
  EXPECT_EQ(status(R"({"kind":"add-condition"})"), 400);
  EXPECT_EQ(status(R"({"kind":"delete-condition","condition":6})"), 422);            // no 6
  EXPECT_EQ(status(R"({"kind":"delete-condition","condition":"9"})"), 400);
  EXPECT_EQ(rig.profile_text(), rig.profile_original);
  AdminRig mill;
  EXPECT_EQ(post(mill.port, R"({"kind":"add-condition","condition":1})", kAdmin).status, 422);
}

TEST(AdminConditions, AMachineWithoutEdmHasNone) {
  AdminRig rig;
  EXPECT_EQ(get(rig.port, "/api/v1/conditions", kOperator).body["conditions"], json::array());
}

}  // namespace
}  // namespace opencnc::hmi
