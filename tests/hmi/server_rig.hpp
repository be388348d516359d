// SPDX-License-Identifier: GPL-3.0-or-later
// One HMI server on loopback around a simulated machine in virtual time, for the server's tests:
// the machine, its profile (or an editable copy), its history and features, stopped and cleaned up.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "client.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/hmi/server.hpp"

namespace opencnc::controller {
class GcodeProgramSource;
}

namespace opencnc::hmi {
class History;
class MachineFeatures;
class MachineHost;
}  // namespace opencnc::hmi

namespace opencnc::hmi::test {

inline const std::string kOperator = "operator-token-for-tests-0001";
inline const std::string kAdmin = "admin-token-for-tests-000000002";

/// What a rig serves. The defaults: the 3-axis mill with its history, the examples as programs.
struct RigOptions {
  std::string machine = "mill-3axis.toml";  ///< a profile under configs/
  std::vector<std::string> sets;            ///< `--set` overrides
  bool profile_copy = false;     ///< read the profile from a copy in the rig's folder (admin edits)
  /// With `profile_copy`: the copy's text from the original's (it may write files beside it in
  /// the rig's folder, the second argument).
  std::function<std::string(const std::string&, const std::filesystem::path&)> edit_copy;
  bool tool_table_copy = false;  ///< a copy of configs/mill-3axis.tbl as the interpreter's tool table
  bool history = true;           ///< a machining history in the rig's folder
  bool run_from_line = false;    ///< the run-from-line feature alone
  bool features = false;         ///< the profile's machine features (journal in <dir>/journal), simulation
  std::string address = "127.0.0.1";
  std::filesystem::path programs = OPENCNC_SOURCE_DIR "/examples";
  ServerConfig server;  ///< the rest of the server's settings (address, port and programs are set)
};

/// The machine at 200× the wall clock in virtual time and its server on a free port.
struct ServerRig {
  explicit ServerRig(RigOptions options = {});
  ~ServerRig();
  ServerRig(const ServerRig&) = delete;
  ServerRig& operator=(const ServerRig&) = delete;

  nlohmann::json status();
  /// Polls the status until `done` holds (at most `seconds` of wall time).
  bool until(const std::function<bool(const nlohmann::json&)>& done, double seconds = 20);
  /// POSTs a command with the operator's token unless another is given.
  Reply command(const nlohmann::json& body, const std::string& token = kOperator);
  /// The profile copy's text as it is now on disk.
  std::string profile_text() const;

  std::filesystem::path dir;
  std::string profile_path;      ///< the copy's path when `profile_copy`
  std::string profile_original;  ///< its text when the rig started
  config::MachineProfile profile;
  std::shared_ptr<controller::GcodeProgramSource> source;
  std::unique_ptr<History> history;
  std::unique_ptr<MachineFeatures> features;
  std::unique_ptr<MachineHost> host;
  std::unique_ptr<Server> server;
  std::uint16_t port = 0;
};

}  // namespace opencnc::hmi::test
