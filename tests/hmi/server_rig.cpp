// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI server's test rig (server_rig.hpp): built once here, shared by every server test.
#include "server_rig.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/hmi/history.hpp"
#include "opencnc/hmi/machine_features.hpp"
#include "opencnc/hmi/machine_host.hpp"
#include "opencnc/run_from_line/setup.hpp"

namespace opencnc::hmi::test {

using nlohmann::json;

namespace {

/// A folder of the rig's own: tests in one binary run one after another, binaries in parallel.
std::filesystem::path fresh_folder() {
  static int counter = 0;
  const auto dir = std::filesystem::temp_directory_path() /
                   ("opencnc-serve-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

config::MachineProfile load(const std::string& path, const std::vector<std::string>& sets) {
  const config::ProfileLoad l = config::load_profile(path, sets);
  std::string messages;
  for (const auto& d : l.diagnostics.items()) messages += d.format() + "\n";
  EXPECT_TRUE(l.ok()) << path << "\n" << messages;
  return l.ok() ? *l.profile : config::MachineProfile{};
}

}  // namespace

ServerRig::ServerRig(RigOptions o) : dir(fresh_folder()) {
  std::string error;
  std::vector<std::string> sets = o.sets;
  if (o.tool_table_copy) {
    std::filesystem::copy_file(OPENCNC_SOURCE_DIR "/configs/mill-3axis.tbl", dir / "tools.tbl");
    sets.push_back("interpreter.tool_table=\"" + (dir / "tools.tbl").string() + "\"");
  }
  std::string path = OPENCNC_SOURCE_DIR "/configs/" + o.machine;
  if (o.profile_copy) {
    profile_path = (dir / o.machine).string();
    EXPECT_TRUE(read_file(path, profile_original, &error)) << error;
    if (o.edit_copy) profile_original = o.edit_copy(profile_original, dir);
    EXPECT_TRUE(write_file_atomically(profile_path, profile_original, &error)) << error;
    // The tool table a profile names beside it (the drill's), copied along.
    const std::filesystem::path tbl = std::filesystem::path(path).replace_extension(".tbl");
    if (std::filesystem::exists(tbl))
      std::filesystem::copy_file(tbl, dir / tbl.filename(),
                                 std::filesystem::copy_options::overwrite_existing);
    path = profile_path;
  }
  profile = load(path, sets);
  Diagnostics d;
  if (o.features) {
    features = MachineFeatures::create(profile, {(dir / "journal").string()}, d);
    EXPECT_TRUE(features) << (d.items().empty() ? "" : d.items()[0].format());
    source = features->source();
  } else {
    source = features::machine_setup(profile, d)->source();  // the features' codes and passes, no feature
  }
  if (o.history) history = History::open(dir / "history.sqlite", &error);
  host = std::make_unique<MachineHost>(profile, source, HostOptions{false, 200});
  if (history) host->controller().attach(std::make_shared<HistoryRecorder>(*history, profile.servo_period_s));
  if (features) features->install(host->controller());
  if (o.run_from_line) {  // run from line alone, as its setup adds it, reading the server's tool table
    auto machine = controller::MachineSetup::create(profile, {}, d);
    machine->source_config().tools = source->tools();
    run_from_line::setup(profile, *machine);
    machine->install(host->controller());
  }
  host->start(nullptr);
  ServerConfig sc = o.server;
  sc.address = o.address;
  sc.port = 0;
  sc.programs_dir = o.programs;
  if (features) {
    sc.features = features.get();
    sc.simulate = [this](const SimulationEvent& e) { return host->simulate(e); };
  }
  server = std::make_unique<Server>(host->controller(), profile, Tokens::of(kOperator, kAdmin), history.get(),
                                    source.get(), sc);
  EXPECT_TRUE(server->start(&error)) << error;
  port = server->port();
}

ServerRig::~ServerRig() {
  server->stop();
  host->stop();
  std::filesystem::remove_all(dir);
}

json ServerRig::status() {
  return get(port, "/api/v1/status", kOperator).body;
}

bool ServerRig::until(const std::function<bool(const json&)>& done, double seconds) {
  using Clock = std::chrono::steady_clock;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    if (done(status())) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

Reply ServerRig::command(const json& body, const std::string& token) {
  return post(port, body.dump(), token);
}

std::string ServerRig::profile_text() const {
  std::string s;
  read_file(profile_path, s, nullptr);
  return s;
}

}  // namespace opencnc::hmi::test
