// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc fleet`: the shop's fleet view — every machine an MQTT broker knows, on one page
// (docs/connectivity.md, "The fleet"), until Ctrl-C.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <thread>

#include "commands.hpp"
#include "listen_address.hpp"
#include "opencnc/connect/fleet.hpp"
#include "opencnc/hmi/fleet_server.hpp"
#include "stop_signals.hpp"

namespace opencnc::cli {

namespace {

struct FleetCommandOptions {
  std::string broker;
  std::string listen = "127.0.0.1:8090";
  std::string static_dir;
  int keepalive_s = 5;
};

int fleet(const FleetCommandOptions& o) {
  std::string why;
  const auto broker = connect::parse_mqtt_url(o.broker, &why);
  if (!broker) {
    fmt::print(stderr, "error: --broker: {}\n", why);
    return kExitUsage;
  }
  hmi::FleetServerConfig sc;
  if (!split_listen(o.listen, sc.address, sc.port)) {
    fmt::print(stderr, "error: --listen: expected ADDRESS:PORT (127.0.0.1:8090, [::1]:8090), not \"{}\"\n",
               o.listen);
    return kExitUsage;
  }
  sc.static_dir = o.static_dir.empty() ? default_static_dir() : std::filesystem::path(o.static_dir);
  std::error_code ec;
  if (!std::filesystem::exists(sc.static_dir / "fleet.html", ec)) {
    fmt::print(stderr,
               "warning: no fleet page in {} (scripts/hmi.sh builds it): /api/v1/fleet alone is served\n",
               sc.static_dir.string());
    sc.static_dir.clear();
  }
  connect::FleetOptions fo;
  fo.broker = *broker;
  fo.keepalive_s = o.keepalive_s;
  connect::FleetWatcher watcher(fo);
  hmi::FleetServer server(watcher, sc);
  if (!server.start(&why)) {
    fmt::print(stderr, "error: --listen: {}\n", why);
    return kExitUsage;
  }
  watcher.start();
  const std::string host =
      sc.address.find(':') != std::string::npos ? fmt::format("[{}]", sc.address) : sc.address;
  fmt::print("opencnc fleet: the machines of mqtt://{}:{}\n  open      http://{}:{}/\n  Ctrl-C stops.\n",
             broker->host, broker->port, host, server.port());
  std::fflush(stdout);
  const StopSignals signals;
  while (StopSignals::requested().load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  server.stop();
  watcher.stop();
  return kExitOk;
}

}  // namespace

void add_fleet_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<FleetCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "fleet", "Serve the shop's fleet view: every machine an MQTT broker knows, on one page");
  cmd->add_option("--broker", opts->broker, "The machines' MQTT broker: mqtt://HOST[:PORT]")->required();
  cmd->add_option("--listen", opts->listen, "Where to serve the page: ADDRESS:PORT (default 127.0.0.1:8090)");
  cmd->add_option("--static", opts->static_dir, "The built front end (default: web/dist beside the build)");
  cmd->add_option("--keepalive", opts->keepalive_s, "Seconds between keep-alives to the broker (default 5)")
      ->check(CLI::Range(5, 65535));
  cmd->callback([opts, &registry] { registry.set_result(fleet(*opts)); });
}

}  // namespace opencnc::cli
