// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI's command bodies: each kind to its typed request, and every malformed or out-of-range
// body refused with its status and a message.
#include <gtest/gtest.h>

#include "../control/test_profiles.hpp"
#include "opencnc/hmi/api.hpp"
#include "opencnc/run_from_line/run_from_line.hpp"

namespace opencnc::hmi {
namespace {

using nlohmann::json;

class ApiParse : public ::testing::Test {
 protected:
  config::MachineProfile profile = control::test::mill();
  std::filesystem::path programs = OPENCNC_SOURCE_DIR "/examples";

  controller::Request request(const json& body) {
    auto r = parse_command(body, profile, programs);
    EXPECT_TRUE(std::holds_alternative<Command>(r)) << std::get<ApiError>(r).message;
    return std::get<controller::Request>(std::get<Command>(r));
  }
  ApiError error(const json& body) {
    auto r = parse_command(body, profile, programs);
    EXPECT_TRUE(std::holds_alternative<ApiError>(r)) << body.dump();
    return std::holds_alternative<ApiError>(r) ? std::get<ApiError>(r) : ApiError{0, ""};
  }
};

TEST_F(ApiParse, EachKindBecomesItsRequest) {
  EXPECT_EQ(request({{"kind", "cycle-start"}}).name(), "cycle-start");
  EXPECT_EQ(request({{"kind", "tool-changed"}}).name(), "tool-changed");
  const auto jog =
      std::get<controller::requests::Jog>(request({{"kind", "jog"}, {"axis", "y"}, {"velocity", -20}}).body);
  EXPECT_EQ(jog.axis, Axis::Y);
  EXPECT_EQ(jog.velocity, -20);
  const auto by = std::get<controller::requests::JogBy>(
      request({{"kind", "jog-by"}, {"axis", "Z"}, {"distance", 0.1}, {"speed", 5}}).body);
  EXPECT_EQ(by.distance, 0.1);
  EXPECT_FALSE(std::get<controller::requests::Home>(request({{"kind", "home"}}).body).axis);
  EXPECT_EQ(std::get<controller::requests::Home>(request({{"kind", "home"}, {"axis", "X"}}).body).axis,
            Axis::X);
  const auto seek = std::get<controller::requests::SeekLimit>(
      request({{"kind", "seek-limit"}, {"axis", "Z"}, {"direction", "-"}}).body);
  EXPECT_EQ(seek.axis, Axis::Z);
  EXPECT_EQ(seek.direction, -1);
  EXPECT_EQ(error({{"kind", "seek-limit"}, {"axis", "Z"}, {"direction", "up"}}).status, 400);
  EXPECT_EQ(request({{"kind", "override"}, {"which", "feed"}, {"value", 1.5}}).name(), "feed-override");
  EXPECT_EQ(request({{"kind", "switch"}, {"which", "single-block"}, {"on", true}}).name(), "single-block");
  EXPECT_EQ(std::get<controller::requests::SetMode>(request({{"kind", "mode"}, {"mode", "mdi"}}).body).mode,
            control::Mode::Mdi);
  EXPECT_EQ(std::get<controller::requests::Mdi>(request({{"kind", "mdi"}, {"line", "G0 X1"}}).body).line,
            "G0 X1");
  const auto open =
      std::get<controller::requests::OpenFile>(request({{"kind", "open"}, {"program", "bracket.ngc"}}).body);
  EXPECT_TRUE(open.path.ends_with("examples/bracket.ngc"));
  EXPECT_EQ(request({{"kind", "coolant"}, {"which", "mist"}, {"on", true}}).name(), "coolant");
  EXPECT_EQ(request({{"kind", "spindle-on"}, {"rpm", 1000}}).name(), "spindle-on");
  const auto from =
      std::get<controller::requests::Feature>(request({{"kind", "run-from-line"}, {"line", 66}}).body);
  EXPECT_EQ(from.feature, "run-from-line");
  EXPECT_EQ(std::any_cast<run_from_line::RunFromLineArgs>(from.args).line, 66u);
  EXPECT_EQ(error({{"kind", "run-from-line"}, {"line", 2.5}}).status, 422);
  EXPECT_EQ(error({{"kind", "run-from-line"}, {"line", "x"}}).status, 400);
}

TEST_F(ApiParse, MalformedBodiesAre400WithTheReason) {
  EXPECT_EQ(error(json::array()).status, 400);
  EXPECT_EQ(error({{"kind", 3}}).message, "\"kind\" must be a string");
  EXPECT_EQ(error({{"nokind", "x"}}).message, "\"kind\" is missing");
  EXPECT_EQ(error({{"kind", "fly"}}).message, "unknown command kind \"fly\" (docs/api.md lists them)");
  EXPECT_EQ(error({{"kind", "jog"}, {"axis", "X"}}).message, "\"velocity\" is missing");
  EXPECT_EQ(error({{"kind", "jog"}, {"axis", "X"}, {"velocity", "fast"}}).message,
            "\"velocity\" must be a number");
  EXPECT_EQ(error({{"kind", "jog"}, {"axis", "Q"}, {"velocity", 1}}).status, 400);
  EXPECT_EQ(error({{"kind", "switch"}, {"which", "single-block"}, {"on", 1}}).message,
            "\"on\" must be true or false");
  EXPECT_EQ(error({{"kind", "mode"}, {"mode", "turbo"}}).status, 400);
  EXPECT_EQ(error({{"kind", "mdi"}, {"line", "G0 X1\nG0 X2"}}).message, "\"line\" must be one line");
}

TEST_F(ApiParse, OutOfRangeIs422) {
  EXPECT_EQ(error({{"kind", "override"}, {"which", "feed"}, {"value", 2.5}}).status, 422);
  EXPECT_EQ(error({{"kind", "override"}, {"which", "rapid"}, {"value", 1.1}}).status, 422);
  EXPECT_EQ(error({{"kind", "jog"}, {"axis", "X"}, {"velocity", 1e6}}).status, 422);
  EXPECT_EQ(error({{"kind", "jog"}, {"axis", "X"}, {"velocity", 0}}).status, 422);
  EXPECT_EQ(error({{"kind", "jog"}, {"axis", "A"}, {"velocity", 1}}).message, "this machine has no A axis");
  EXPECT_EQ(error({{"kind", "jog-by"}, {"axis", "X"}, {"distance", 1}, {"speed", -1}}).status, 422);
  EXPECT_EQ(error({{"kind", "spindle-on"}, {"rpm", 1e9}}).status, 422);
  EXPECT_EQ(error({{"kind", "handwheel"}, {"axis", "X"}, {"step", 0.01}}).message,
            "this machine has no handwheel");
  EXPECT_EQ(error({{"kind", "set-tool"}, {"tool", 1.5}, {"diameter", 6}}).status, 422);
  EXPECT_EQ(error({{"kind", "mdi"}, {"line", std::string(300, 'G')}}).status, 422);
}

TEST_F(ApiParse, ProgramsStayInsideTheirFolder) {
  EXPECT_EQ(error({{"kind", "open"}, {"program", "../configs/mill-3axis.toml"}}).status, 400);
  EXPECT_EQ(error({{"kind", "open"}, {"program", "/etc/passwd"}}).status, 400);
  EXPECT_EQ(error({{"kind", "open"}, {"program", ""}}).status, 400);
  EXPECT_EQ(error({{"kind", "open"}, {"program", "missing.ngc"}}).status, 404);
}

TEST(ApiRoles, AdminOnlyForToolDataOperatorForTheRest) {
  EXPECT_EQ(role_for("set-tool"), Role::Admin);
  for (const char* k : {"cycle-start", "feed-hold", "jog", "home", "open", "mdi", "tool-changed", "override",
                        "run-from-line", "seek-limit"}) {
    EXPECT_EQ(role_for(k), Role::Operator) << k;
  }
  EXPECT_FALSE(role_for("fly"));
}

TEST(ApiJson, StatusCarriesWhatTheScreensShow) {
  const config::MachineProfile p = control::test::mill();
  controller::ControllerStatus s;
  s.servo.state = control::State::Held;
  s.servo.actual[0] = 12.5;
  s.wait_text = "the operator's resume (feed hold)";
  const json j = status_json(s, p);
  EXPECT_EQ(j["state"], "held");
  EXPECT_EQ(j["machine"]["X"], 12.5);
  EXPECT_EQ(j["wait_text"], "the operator's resume (feed hold)");
  EXPECT_TRUE(j["following_error"].contains("Z"));
  EXPECT_FALSE(j["machine"].contains("A"));
  // Work coordinates: the feedback position less the offsets; distance to go as the status has it.
  s.offsets.system = 3;
  s.offsets.g5x[0] = 2.5;
  s.offsets.g92[0] = 1;
  s.distance_to_go[0] = -4;
  const json w = status_json(s, p);
  EXPECT_EQ(w["offsets"]["system"], "G56");
  EXPECT_EQ(w["work"]["X"], 9.0);
  EXPECT_EQ(w["distance_to_go"]["X"], -4.0);
  EXPECT_EQ(w["offsets"]["g92"]["X"], 1.0);
  const json m = machine_json(p);
  EXPECT_EQ(m["axes"].size(), 3u);
  EXPECT_EQ(m["axes"][0]["axis"], "X");
  EXPECT_EQ(m["axes"][0]["seek"], json::array());  // the mill has no limit switches to seek
  // A seek: only the axes that have been sought, with the phase and what it found.
  EXPECT_EQ(w["seek"], json::object());
  s.servo.seek[2] = {control::SeekPhase::Done, -1, true, -81.0004, -80.99, -80.0};
  const json k = status_json(s, p)["seek"];
  EXPECT_EQ(k.size(), 1u);
  EXPECT_EQ(k["Z"]["phase"], "done");
  EXPECT_EQ(k["Z"]["direction"], "-");
  EXPECT_EQ(k["Z"]["tripped_at"], -81.0004);
  EXPECT_EQ(k["Z"]["rest_at"], -80.0);
}

}  // namespace
}  // namespace opencnc::hmi
