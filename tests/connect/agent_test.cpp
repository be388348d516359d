// SPDX-License-Identifier: GPL-3.0-or-later
// The MTConnect agent on every machine profile: probe, current, sample, assets and error documents
// valid against the MTConnect 2.7 schemas; sequence numbers over a bounded buffer; path filters;
// faults and alarms as conditions; the values of a machine that runs.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <libxml/parser.h>
#include <libxml/xmlschemas.h>
#include <libxml/xpath.h>
#include <libxml/xpathInternals.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "harness/golden.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/agent.hpp"
#include "scenario.hpp"

namespace opencnc::connect {
namespace {

namespace fs = std::filesystem;
using controller::test::Scenario;

constexpr std::int64_t kEpochUs = 1796601600LL * 1000000;  // 2026-12-07T00:00:00Z

/// The schemas, unpacked once into a folder of their own (xlink.xsd beside the ones importing it).
const fs::path& schema_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("opencnc-mtconnect-schema-" + std::to_string(::getpid()));
    fs::create_directories(d);
    for (const auto& e : fs::directory_iterator(fs::path(OPENCNC_SOURCE_DIR) / "tests/connect/schema")) {
      if (e.path().extension() != ".xz") continue;
      std::ofstream(d / e.path().stem(), std::ios::binary) << conformance::read_file(e.path());
    }
    return d;
  }();
  return dir;
}

/// The compiled schemas, kept for the process and freed at its end (LeakSanitizer counts them).
struct Schemas {
  std::map<std::string, xmlSchemaPtr> byName;
  ~Schemas() {
    for (auto& [name, schema] : byName) xmlSchemaFree(schema);
  }
};

/// Validates `xml` against the schema `name` ("MTConnectStreams"); "" = valid, else libxml2's words.
std::string invalid(const std::string& xml, const std::string& name) {
  static Schemas schemas;
  auto& schema = schemas.byName[name];
  if (schema == nullptr) {
    const std::string file = (schema_dir() / (name + "_2.7_1.0.xsd")).string();
    xmlSchemaParserCtxtPtr p = xmlSchemaNewParserCtxt(file.c_str());
    schema = xmlSchemaParse(p);
    xmlSchemaFreeParserCtxt(p);
    if (schema == nullptr) return "the schema " + file + " does not compile";
  }
  std::string errors;
  xmlDocPtr doc =
      xmlReadMemory(xml.data(), static_cast<int>(xml.size()), "doc.xml", nullptr, XML_PARSE_NONET);
  if (doc == nullptr) return "not well-formed XML";
  xmlSchemaValidCtxtPtr v = xmlSchemaNewValidCtxt(schema);
  xmlSchemaSetValidStructuredErrors(
      v,
      [](void* out, xmlErrorPtr e) {
        *static_cast<std::string*>(out) += fmt::format("line {}: {}", e->line, e->message);
      },
      &errors);
  const int rc = xmlSchemaValidateDoc(v, doc);
  xmlSchemaFreeValidCtxt(v);
  xmlFreeDoc(doc);
  return rc == 0 ? std::string() : (errors.empty() ? std::string("invalid") : errors);
}

/// XPath over a document, with its MTConnect namespace bound to `m`.
class Xml {
 public:
  explicit Xml(const std::string& text) {
    doc_ = xmlReadMemory(text.data(), static_cast<int>(text.size()), "doc.xml", nullptr, XML_PARSE_NONET);
    ctx_ = xmlXPathNewContext(doc_);
    const xmlChar* ns = xmlDocGetRootElement(doc_)->ns->href;
    xmlXPathRegisterNs(ctx_, reinterpret_cast<const xmlChar*>("m"), ns);
  }
  ~Xml() {
    xmlXPathFreeContext(ctx_);
    xmlFreeDoc(doc_);
  }
  /// The text (or attribute value) of every node `xpath` selects.
  std::vector<std::string> all(const std::string& xpath) const {
    std::vector<std::string> out;
    xmlXPathObjectPtr r = xmlXPathEvalExpression(reinterpret_cast<const xmlChar*>(xpath.c_str()), ctx_);
    if (r != nullptr && r->nodesetval != nullptr)
      for (int i = 0; i < r->nodesetval->nodeNr; ++i) {
        xmlChar* s = xmlNodeGetContent(r->nodesetval->nodeTab[i]);
        out.emplace_back(s != nullptr ? reinterpret_cast<const char*>(s) : "");
        xmlFree(s);
      }
    xmlXPathFreeObject(r);
    return out;
  }
  std::string one(const std::string& xpath) const {
    auto v = all(xpath);
    return v.size() == 1 ? v[0] : fmt::format("<{} nodes>", v.size());
  }

 private:
  xmlDocPtr doc_ = nullptr;
  xmlXPathContextPtr ctx_ = nullptr;
};

config::MachineProfile profile(const std::string& name, std::vector<std::string> overrides = {}) {
  auto load = config::load_profile(fs::path(OPENCNC_SOURCE_DIR) / "configs" / (name + ".toml"), overrides);
  if (!load.ok()) throw std::runtime_error(load.diagnostics.items().front().format());
  return *load.profile;
}

AgentResponse ask(const Agent& agent, const std::string& target, std::int64_t now = kEpochUs) {
  return agent.respond(parse_agent_request(target), now);
}

/// Observes the rig's status every `every` periods for `periods` periods (virtual time stamps).
void observe(Agent& agent, Scenario& s, int periods, int every = 10) {
  for (int i = 0; i < periods; i += every) {
    s.ticks(static_cast<std::uint64_t>(every));
    agent.observe(s.status(), kEpochUs + static_cast<std::int64_t>(s.status().servo.time_s * 1e6));
  }
}

class EveryProfile : public ::testing::TestWithParam<std::string> {};

/// A status with something in every item a profile may have: the machine moving, a fault of an
/// axis, every process alarm active, the EDM gap shorted, a coupling engaged, on battery, the
/// plasma torch cutting, held or failed in turn; every drive reporting its effort.
controller::ControllerStatus busy_status(const config::MachineProfile& p, int i) {
  controller::ControllerStatus s;
  s.servo.state = i % 3 == 0   ? control::State::Running
                  : i % 3 == 1 ? control::State::Held
                               : control::State::Faulted;
  s.servo.mode = control::Mode::Auto;
  s.servo.estop_input_ok = true;
  s.servo.run_active = true;
  s.servo.line = static_cast<std::uint32_t>(10 + i);
  s.program_name = "part <1> & \"2\".ngc";
  for (int a = 0; a < kAxisCount; ++a) s.servo.actual[static_cast<std::size_t>(a)] = 1.5 * a + 0.25 * i;
  s.servo.commanded = s.servo.actual;
  s.servo.path_velocity = 12.5 * i;
  s.servo.spindle_rpm = s.servo.spindle_rpm_actual = 1000 + i;
  if (s.servo.state == control::State::Faulted) {
    s.servo.fault = control::Fault{control::FaultKind::SoftLimit, 2, 5, 4, 7};
    s.fault_text = "Z beyond its soft limit";
  }
  s.servo.alarms_active = static_cast<std::uint16_t>((1u << p.alarms.alarms.count) - 1u);
  s.servo.edm.on = true;
  s.servo.edm.gap_state = machine::GapState::Short;
  s.servo.edm.gap_voltage_v = 3.5;
  s.servo.coupling.kind = motion::CouplingKind::ConstantPitch;
  s.servo.mains_ok = false;
  s.servo.on_battery = true;
  s.servo.load_kn = 1.25;
  s.servo.torch.phase = i % 3 == 0   ? control::TorchPhase::Cutting
                        : i % 3 == 1 ? control::TorchPhase::Paused
                                     : control::TorchPhase::Failed;
  s.servo.torch.torch_on = i % 3 == 0;
  s.servo.torch.arc_voltage_v = 121.5;
  s.servo.torch.correction_mm = -0.125;
  for (auto& j : s.servo.joints) {
    j.effort_valid = true;
    j.effort = -150.0 * i;
  }
  return s;
}

TEST_P(EveryProfile, EveryDocumentIsValidMTConnect27) {
  const auto p = profile(GetParam());
  auto agent = Agent::for_profile(p, AgentOptions{"test-host", "", 7, 4096, 1000});
  for (int i = 0; i < 6; ++i) agent->observe(busy_status(p, i), kEpochUs + i * 100000);
  agent->observe(controller::ControllerStatus{}, kEpochUs + 700000);  // everything back to rest
  agent->set_tools(
      {ToolAsset{1, 3, 120.5, 10, "end mill <10 mm> & co", kEpochUs}, ToolAsset{2, 0, 80, 6, "", kEpochUs}},
      kEpochUs + 1);

  const auto probe = ask(*agent, "/probe");
  EXPECT_EQ(probe.status, 200);
  EXPECT_EQ(invalid(probe.body, "MTConnectDevices"), "") << probe.body;
  for (const std::string target :
       {"/current", "/sample?count=1000", "/sample?from=1&count=5", "/current?at=3", "/current?at=60",
        "/current?path=//Axes//DataItem[@type=\"POSITION\"]"}) {
    const auto r = ask(*agent, target);
    EXPECT_EQ(r.status, 200) << target;
    EXPECT_EQ(invalid(r.body, "MTConnectStreams"), "") << target << "\n" << r.body;
  }
  const auto assets = ask(*agent, "/assets");
  EXPECT_EQ(invalid(assets.body, "MTConnectAssets"), "") << assets.body;
  for (const std::string target :
       {"/sample?from=999999", "/sample?count=0", "/sample?from=x", "/current?path=//Nope",
        "/current?path=((", "/other/probe", "/nothing", "/current?at=999999"}) {
    const auto r = ask(*agent, target);
    EXPECT_NE(r.status, 200) << target;
    EXPECT_EQ(invalid(r.body, "MTConnectError"), "") << target << "\n" << r.body;
  }
}

INSTANTIATE_TEST_SUITE_P(Connect, EveryProfile,
                         ::testing::Values("mill-3axis", "mill-4axis", "drill-retrofit", "edm-5axis",
                                           "broach-zc", "flame-cutter", "hmc-toolcheck", "plasma-table"),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           std::string n = param.param;
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

TEST(Agent, TheProbeDescribesTheProfilesAxesAndFeatures) {
  auto mill = Agent::for_profile(profile("mill-3axis"), {});
  Xml m(ask(*mill, "/probe").body);
  EXPECT_EQ(m.all("//m:Axes/m:Components/m:Linear/@name"), (std::vector<std::string>{"X", "Y", "Z"}));
  EXPECT_EQ(m.one("//m:Rotary[@id='s']/@name"), "S");
  EXPECT_EQ(m.one("//m:Path//m:DataItem[@type='EXECUTION']/@id"), "execution");
  EXPECT_TRUE(m.all("//m:DataItem[@type='VOLTAGE_DC']").empty());

  auto edm = Agent::for_profile(profile("edm-5axis"), {});
  Xml e(ask(*edm, "/probe").body);
  EXPECT_EQ(e.one("//m:DataItem[@id='edm_gap_v']/@units"), "VOLT");
  EXPECT_EQ(e.one("//m:Rotary[@name='B']//m:DataItem[@subType='ACTUAL']/@type"), "ANGLE");
  Xml t(ask(*Agent::for_profile(profile("plasma-table"), {}), "/probe").body);
  EXPECT_EQ(t.one("//m:Auxiliaries/m:Components/m:CuttingTorch/@id"), "torch");
  EXPECT_EQ(t.one("//m:CuttingTorch//m:DataItem[@type='VOLTAGE_DC' and @category='SAMPLE']/@units"), "VOLT");

  auto broach = Agent::for_profile(profile("broach-zc"), {});
  Xml b(ask(*broach, "/probe").body);
  EXPECT_EQ(b.one("//m:Rotary[@name='C']//m:DataItem[@type='AXIS_COUPLING']/@id"), "c_coupling");
  EXPECT_EQ(b.one("//m:Linear[@name='Z']//m:DataItem[@type='LINEAR_FORCE']/@units"), "NEWTON");
  EXPECT_EQ(b.one("//m:DataItem[@type='POWER_STATE']/@subType"), "LINE");
}

TEST(Agent, AMachineThatRunsShowsItsPositionsStateAndProgramValues) {
  const auto p = profile("mill-3axis");
  auto agent = Agent::for_profile(p, {});
  Scenario s(p);
  observe(*agent, s, 20);
  {
    Xml c(ask(*agent, "/current").body);
    EXPECT_EQ(c.one("//m:Availability"), "AVAILABLE");
    EXPECT_EQ(c.one("//m:ControllerMode"), "MANUAL");
    EXPECT_EQ(c.one("//m:Execution"), "STOPPED");  // the machine is off
  }
  s.on(control::Mode::Mdi);
  s.must(controller::Request::mdi("G0 X12.5 Y-3"));
  observe(*agent, s, 5000);
  Xml c(ask(*agent, "/current").body);
  EXPECT_EQ(c.one("//m:Execution"), "READY");
  EXPECT_EQ(c.one("//m:ControllerMode"), "MANUAL_DATA_INPUT");
  EXPECT_EQ(c.one("//m:Position[@dataItemId='x_act']"), "12.5000");
  EXPECT_EQ(c.one("//m:Position[@dataItemId='y_cmd']"), "-3.0000");
  EXPECT_EQ(c.one("//m:EmergencyStop"), "ARMED");
  EXPECT_EQ(c.one("//m:PathFeedrateOverride[@subType='PROGRAMMED']"), "100");
  EXPECT_EQ(c.all("//m:Condition/m:Normal").size(),
            1u + 2u * 3u);  // system, and travel and actuator per axis
  // The move was seen under way: some sample shows X between its ends at a feed above zero.
  Xml all(ask(*agent, "/sample?count=10000&path=//Linear[@name=\"X\"]//DataItem[@subType=\"ACTUAL\"]").body);
  const auto xs = all.all("//m:Position");
  EXPECT_GT(xs.size(), 5u);
  EXPECT_EQ(xs.front(), "UNAVAILABLE");  // from the agent's start to the first observation
  EXPECT_TRUE(std::any_of(xs.begin() + 1, xs.end(), [](const std::string& v) {
    const double x = std::stod(v);
    return x > 0.5 && x < 12;
  }));
  // X's drive pushed its table: its load rose above rest, never past the drive's peak (100 %).
  Xml loads(ask(*agent, "/sample?count=10000&path=//Linear[@name=\"X\"]//DataItem[@type=\"LOAD\"]").body);
  const auto ls = loads.all("//m:Load");
  ASSERT_GT(ls.size(), 2u);
  double peak = 0;
  for (const std::string& v : ls)
    if (v != "UNAVAILABLE") peak = std::max(peak, std::stod(v));
  EXPECT_GT(peak, 1.0);
  EXPECT_LE(peak, 100.0);
  EXPECT_NE(c.one("//m:Load[@dataItemId='x_load']"), "UNAVAILABLE");
  EXPECT_EQ(c.one("//m:Load[@dataItemId='s_load']"), "0.0");  // the spindle stands: no torque
}

// The spindle's LOAD is its drive's torque over the profile's rating (mill-3axis: 35 N·m; the
// simulated rotor 0.01 kg·m², friction 0.3 N·m + 0.05 N·m per 1000 rpm): it peaks while the spindle
// runs up at 4000 rpm/s (0.01 · 2π · 4000/60 = 4.19 N·m of acceleration), falls to its friction at
// speed, and carries a cut's torque.
TEST(Agent, TheSpindlesLoadIsItsDrivesTorqueOverItsRating) {
  const auto p = profile("mill-3axis");
  ASSERT_EQ(p.spindle.rated_torque_nm, 35.0);
  auto agent = Agent::for_profile(p, {});
  Scenario s(p);
  s.on(control::Mode::Mdi);
  s.must(controller::Request::mdi("M3 S6000"));
  observe(*agent, s, 2500);  // 1.5 s to speed, then at speed
  Xml all(ask(*agent, "/sample?count=10000&path=//Rotary[@name=\"S\"]//DataItem[@type=\"LOAD\"]").body);
  double peak = 0;
  for (const std::string& v : all.all("//m:Load"))
    if (v != "UNAVAILABLE") peak = std::max(peak, std::stod(v));
  const double run_up = 0.01 * 2 * std::numbers::pi * 4000 / 60;
  EXPECT_NEAR(peak, 100 * (run_up + 0.3 + 0.05 * 6) / 35, 0.1);  // at the end of the ramp
  Xml at_speed(ask(*agent, "/current").body);
  EXPECT_EQ(at_speed.one("//m:Torque[@dataItemId='s_torque']"), "0.60");
  EXPECT_EQ(at_speed.one("//m:Load[@dataItemId='s_load']"), "1.7");  // 0.6 / 35

  s.sim().set_spindle_load(17.5);  // a cut
  observe(*agent, s, 20);
  Xml cutting(ask(*agent, "/current").body);
  EXPECT_EQ(cutting.one("//m:Torque[@dataItemId='s_torque']"), "18.10");
  EXPECT_EQ(cutting.one("//m:Load[@dataItemId='s_load']"), "51.7");
}

TEST(Agent, SampleWalksEverySequenceOnceInOrderAndRefusesWhatTheBufferForgot) {
  const auto p = profile("mill-3axis");
  auto agent = Agent::for_profile(p, AgentOptions{"h", "", 1, 64, 1000});
  Scenario s(p);
  s.on(control::Mode::Mdi);
  s.must(controller::Request::mdi("G1 X20 F600"));
  observe(*agent, s, 3000);
  const std::uint64_t next = agent->next_sequence();
  ASSERT_GT(next, 200u);  // the buffer of 64 has turned over
  Xml head(ask(*agent, "/current").body);
  EXPECT_EQ(head.one("//m:Header/@firstSequence"), std::to_string(next - 64));
  EXPECT_EQ(head.one("//m:Header/@lastSequence"), std::to_string(next - 1));
  EXPECT_EQ(head.one("//m:Header/@nextSequence"), std::to_string(next));
  EXPECT_EQ(head.one("//m:Header/@bufferSize"), "64");

  std::vector<std::uint64_t> seen;
  std::uint64_t from = next - 64;
  while (from < next) {
    Xml page(ask(*agent, fmt::format("/sample?from={}&count=10", from)).body);
    for (const auto& v : page.all("//m:ComponentStream/*/*/@sequence")) seen.push_back(std::stoull(v));
    const std::uint64_t to = std::stoull(page.one("//m:Header/@nextSequence"));
    ASSERT_GT(to, from);
    from = to;
  }
  std::sort(seen.begin(), seen.end());  // a document groups by component, not by sequence
  ASSERT_EQ(seen.size(), 64u);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], next - 64 + i);

  const auto gone = ask(*agent, fmt::format("/sample?from={}", next - 65));
  EXPECT_EQ(gone.status, 400);
  EXPECT_EQ(Xml(gone.body).one("//m:OutOfRange/m:QueryParameter/@name"), "from");
  // The state at the last sequence is the current state.
  Xml now(ask(*agent, "/current").body), at(ask(*agent, fmt::format("/current?at={}", next - 1)).body);
  EXPECT_EQ(now.all("//m:Position"), at.all("//m:Position"));
}

TEST(Agent, AFaultIsAConditionOfItsAxisAndClearsToNormal) {
  const auto p = profile("mill-3axis");
  auto agent = Agent::for_profile(p, {});
  controller::ControllerStatus st;
  st.servo.state = control::State::Idle;
  st.servo.estop_input_ok = true;
  agent->observe(st, kEpochUs);
  st.servo.state = control::State::Faulted;
  st.servo.fault = control::Fault{control::FaultKind::FollowingError, 1, 0.2, 0.1, 5};
  st.fault_text = "Y followed 0.2 mm behind (0.1 allowed)";
  agent->observe(st, kEpochUs + 1000);
  {
    Xml c(ask(*agent, "/current").body);
    EXPECT_EQ(c.one("//m:Fault/@dataItemId"), "y_actuator");
    EXPECT_EQ(c.one("//m:Fault/@nativeCode"), "control.fault.following-error");
    EXPECT_EQ(c.one("//m:Fault"), st.fault_text);
    EXPECT_EQ(c.one("//m:Execution"), "STOPPED");
  }
  st.servo.state = control::State::Off;
  st.servo.fault = {};
  agent->observe(st, kEpochUs + 2000);
  Xml c(ask(*agent, "/current").body);
  EXPECT_TRUE(c.all("//m:Fault").empty());
  EXPECT_EQ(c.one("//m:Normal[@dataItemId='y_actuator']/@nativeCode"), "<0 nodes>");  // Normal as a whole
  Xml history(ask(*agent, "/sample?path=//DataItem[@id=\"y_actuator\"]").body);
  EXPECT_EQ(history.all("//m:Condition/*/@nativeCode"),
            (std::vector<std::string>{"control.fault.following-error", "control.fault.following-error"}));
}

TEST(Agent, AnAgentWhoseControllerWentAwayShowsEverythingUnavailable) {
  const auto p = profile("mill-3axis");
  auto agent = Agent::for_profile(p, {});
  controller::ControllerStatus st;
  agent->observe(st, kEpochUs);
  agent->mark_unavailable(kEpochUs + 1);
  Xml c(ask(*agent, "/current").body);
  EXPECT_EQ(c.one("//m:Availability"), "UNAVAILABLE");
  EXPECT_EQ(c.one("//m:Execution"), "UNAVAILABLE");
  EXPECT_EQ(c.all("//m:Condition/m:Unavailable").size(), 7u);
  agent->observe(st, kEpochUs + 2);
  EXPECT_EQ(Xml(ask(*agent, "/current").body).one("//m:Availability"), "AVAILABLE");
}

TEST(Agent, RequestsAreDecodedAndTheDeviceMayBeNamed) {
  const auto r = parse_agent_request("/mill-3axis/sample?path=%2F%2FAxes+x&from=3&flag");
  EXPECT_EQ(r.path, "/mill-3axis/sample");
  EXPECT_EQ(r.query.at("path"), "//Axes x");
  EXPECT_EQ(r.query.at("from"), "3");
  EXPECT_EQ(r.query.at("flag"), "");
  auto agent = Agent::for_profile(profile("mill-3axis"), {});
  EXPECT_EQ(ask(*agent, "/mill-3axis/probe").status, 200);
  EXPECT_EQ(ask(*agent, "/").status, 200);
  const auto other = ask(*agent, "/lathe/current");
  EXPECT_EQ(other.status, 404);
  EXPECT_NE(other.body.find("NoDevice"), std::string::npos);
  EXPECT_NE(ask(*agent, "/current?path=%2F%2FNothing").body.find("selects no data item"), std::string::npos);
}

TEST(Agent, ToolsAreCuttingToolAssetsAndTheirChangesEvents) {
  auto agent = Agent::for_profile(profile("mill-3axis"), {});
  agent->set_tools({ToolAsset{5, 2, 100, 8, "drill", kEpochUs}}, kEpochUs);
  agent->set_tools(
      {ToolAsset{5, 2, 100.25, 8, "drill", kEpochUs + 5}, ToolAsset{6, 0, 50, 4, "", kEpochUs + 5}},
      kEpochUs + 5);
  agent->set_tools({ToolAsset{6, 0, 50, 4, "", kEpochUs + 5}}, kEpochUs + 9);
  Xml a(ask(*agent, "/assets").body);
  EXPECT_EQ(a.all("//m:CuttingTool/@assetId"), (std::vector<std::string>{"T6"}));
  EXPECT_EQ(a.one("//m:FunctionalLength"), "50.0000");
  Xml s(ask(*agent, "/sample").body);
  EXPECT_EQ(s.all("//m:AssetChanged"), (std::vector<std::string>{"UNAVAILABLE", "T5", "T5", "T6"}));
  EXPECT_EQ(s.all("//m:AssetRemoved"), (std::vector<std::string>{"UNAVAILABLE", "T5"}));
  EXPECT_EQ(s.all("//m:AssetChanged/@assetType"),
            (std::vector<std::string>{"UNAVAILABLE", "CuttingTool", "CuttingTool", "CuttingTool"}));
}

}  // namespace
}  // namespace opencnc::connect
