// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc serve`: the simulated machine with its controller, and the operator's HMI in the
// browser (docs/hmi.md, docs/api.md), until Ctrl-C.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/stat.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <thread>

#include "commands.hpp"
#include "listen_address.hpp"
#include "numeric_options.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/agent.hpp"
#include "opencnc/connect/mqtt_publisher.hpp"
#include "opencnc/connect/shdr_adapter.hpp"
#include "opencnc/connect/status_sampler.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/hmi/history.hpp"
#include "opencnc/hmi/machine_features.hpp"
#include "opencnc/hmi/machine_host.hpp"
#include "opencnc/hmi/server.hpp"
#include "opencnc/hmi/tokens.hpp"
#include "stop_signals.hpp"

namespace opencnc::cli {

namespace {

namespace fs = std::filesystem;

struct ServeOptions {
  std::string machine;
  std::vector<std::string> sets;
  std::string listen = "127.0.0.1:8080";
  std::string program;
  std::string programs_dir;
  std::string data_dir;
  std::string static_dir;
  std::string journal_dir;  ///< "" = <data>/journal (machines with a power monitor)
  double speed = 0;  ///< 0: real time on a periodic thread; else paced virtual time
  double stream_hz = 30;
  int servo_cpu = -1;  ///< real time: the servo thread's own CPU; the server keeps off it
  std::string device_name;   ///< the MTConnect device's name ("" = the profile's)
  double mtconnect_hz = 10;  ///< status samples per second into the MTConnect agent
  std::string mqtt;          ///< mqtt://HOST:PORT ("" = no MQTT)
  int mqtt_keepalive_s = 5;
  std::string shdr;     ///< ADDRESS:PORT of the SHDR adapter's listener ("" = none)
  std::string hmi_url;  ///< how the fleet view links to this HMI ("" = from --listen)
};

/// `$XDG_STATE_HOME/opencnc`, else `~/.local/state/opencnc`.
fs::path default_data_dir() {
  if (const char* x = std::getenv("XDG_STATE_HOME"); x && *x) return fs::path(x) / "opencnc";
  const char* home = std::getenv("HOME");
  return fs::path(home && *home ? home : ".") / ".local" / "state" / "opencnc";
}

/// Puts the machine in Auto and opens `program`, waiting for the answers.
bool open_program(controller::Controller& c, const std::string& program) {
  auto ask = [&c](controller::Request r) {
    const std::uint64_t id = c.submit(std::move(r));
    for (int k = 0; k < 30000; ++k) {
      if (auto o = c.outcome(id)) return *o;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return controller::Outcome{false, control::Refusal::Busy, "the controller does not answer", {}};
  };
  for (auto r : {controller::Request::simple(control::CommandKind::MachineOn),
                 controller::Request::set_mode(control::Mode::Auto), controller::Request::open(program)}) {
    const std::string name = r.name();
    const controller::Outcome o = ask(std::move(r));
    for (const Diagnostic& d : o.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
    if (!o.accepted && name == "open") {
      fmt::print(stderr, "error: {}: {}\n", program, o.message);
      return false;
    }
  }
  return true;
}

int serve(const ServeOptions& o) {
  std::string address;
  std::uint16_t port = 0;
  if (!split_listen(o.listen, address, port)) {
    fmt::print(stderr, "error: --listen: expected ADDRESS:PORT (127.0.0.1:8080, [::1]:8080), not \"{}\"\n",
               o.listen);
    return kExitUsage;
  }
  std::string shdr_address;
  std::uint16_t shdr_port = 0;
  if (!o.shdr.empty() && !split_listen(o.shdr, shdr_address, shdr_port)) {
    fmt::print(stderr, "error: --shdr: expected ADDRESS:PORT (127.0.0.1:7878), not \"{}\"\n", o.shdr);
    return kExitUsage;
  }
  std::optional<connect::MqttAddress> broker;
  if (!o.mqtt.empty()) {
    std::string why;
    broker = connect::parse_mqtt_url(o.mqtt, &why);
    if (!broker) {
      fmt::print(stderr, "error: --mqtt: {}\n", why);
      return kExitUsage;
    }
  }
  const config::ProfileLoad load = config::load_profile(o.machine, o.sets);
  for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
  if (!load.ok()) return kExitProgram;
  const config::MachineProfile& profile = *load.profile;

  const fs::path data = o.data_dir.empty() ? default_data_dir() : fs::path(o.data_dir);
  std::error_code ec;
  const bool created = fs::create_directories(data, ec);
  if (ec || !fs::is_directory(data, ec)) {
    fmt::print(stderr, "error: --data {}: {}\n", data.string(), ec ? ec.message() : "not a folder");
    return kExitUsage;
  }
  if (created) ::chmod(data.c_str(), 0700);  // a folder of ours; one given that exists keeps its mode
  // The features the profile calls for (docs/hmi.md, "Features"), with the program source.
  Diagnostics diags;
  hmi::FeatureOptions fo;
  fo.journal_dir = o.journal_dir.empty() ? (data / "journal").string() : o.journal_dir;
  const std::unique_ptr<hmi::MachineFeatures> features = hmi::MachineFeatures::create(profile, fo, diags);
  for (const Diagnostic& d : diags.items()) fmt::print(stderr, "{}\n", d.format());
  if (!features) return kExitUsage;
  const std::shared_ptr<controller::GcodeProgramSource> source = features->source();
  std::string error;
  const auto tokens = hmi::Tokens::load(data / "tokens", &error);
  if (!tokens) {
    fmt::print(stderr, "error: tokens: {}\n", error);
    return kExitUsage;
  }
  auto history = hmi::History::open(data / "history.sqlite", &error);
  if (!history) {
    fmt::print(stderr, "error: history: {}\n", error);
    return kExitUsage;
  }

  hmi::HostOptions ho;
  ho.realtime = o.speed == 0;
  ho.speed = o.speed == 0 ? 1.0 : o.speed;
  ho.servo_cpu = o.servo_cpu;
  hmi::MachineHost host(profile, source, ho);
  host.controller().attach(std::make_shared<hmi::HistoryRecorder>(*history, profile.servo_period_s));
  features->install(host.controller());
  std::vector<std::string> warnings;
  if (!host.start(&warnings)) {
    fmt::print(stderr, "error: the servo thread could not start\n");
    return kExitFailure;
  }
  for (const std::string& w : warnings) fmt::print(stderr, "warning: {}\n", w);

  // The MTConnect agent, sampled on a thread of its own, and its MQTT publisher (docs/connectivity.md).
  connect::AgentOptions ao;
  ao.sender = [] {
    char name[256] = {};
    return ::gethostname(name, sizeof name - 1) == 0 && name[0] != 0 ? std::string(name)
                                                                     : std::string("opencnc");
  }();
  ao.device_name = o.device_name;
  ao.start_us = connect::StatusSampler::wall_us();
  ao.instance_id = static_cast<std::uint64_t>(ao.start_us / 1000000);
  const std::unique_ptr<connect::Agent> agent = connect::Agent::for_profile(profile, ao);
  connect::StatusSampler sampler(
      *agent, [&host] { return host.controller().status(); },
      [&source] {
        std::vector<connect::ToolAsset> list;
        if (const auto service = source ? source->tools() : nullptr) {
          for (const tools::ToolEntry& e : service->snapshot()->entries())
            list.push_back(connect::ToolAsset{e.tool, e.pocket, e.offset[index(Axis::Z)], e.diameter,
                                              e.comment, connect::StatusSampler::wall_us()});
        }
        return list;
      },
      connect::SamplerOptions{std::chrono::milliseconds(static_cast<int>(1000.0 / o.mtconnect_hz)),
                              std::chrono::seconds(2)});
  sampler.start();

  hmi::ServerConfig sc;
  sc.mtconnect = agent.get();
  sc.address = address;
  sc.port = port;
  sc.programs_dir = !o.programs_dir.empty() ? fs::path(o.programs_dir)
                    : !o.program.empty()    ? fs::absolute(o.program).parent_path()
                                            : fs::current_path();
  sc.static_dir = o.static_dir.empty() ? default_static_dir() : fs::path(o.static_dir);
  if (!fs::exists(sc.static_dir / "index.html", ec)) {
    fmt::print(stderr, "warning: no front end in {} (scripts/hmi.sh builds it): the API alone is served\n",
               sc.static_dir.string());
    sc.static_dir.clear();
  }
  sc.stream_hz = o.stream_hz;
  sc.features = features.get();
  sc.simulate = [&host](const hmi::SimulationEvent& e) { return host.simulate(e); };
  hmi::Server server(host.controller(), profile, *tokens, history.get(), source.get(), sc);
  if (!server.start(&error)) {
    fmt::print(stderr, "error: {}\n", error);
    return kExitUsage;
  }
  const std::string host_part =
      address.find(':') != std::string::npos ? fmt::format("[{}]", address) : address;
  std::unique_ptr<connect::MqttPublisher> mqtt;
  if (broker) {
    connect::MqttOptions mo;
    mo.broker = *broker;
    mo.keepalive_s = o.mqtt_keepalive_s;
    mo.hmi_url = !o.hmi_url.empty() ? o.hmi_url
                 : address == "0.0.0.0" || address == "::"
                     ? fmt::format("http://{}:{}/", ao.sender, server.port())  // a wildcard: the host's name
                     : fmt::format("http://{}:{}/", host_part, server.port());
    mqtt = std::make_unique<connect::MqttPublisher>(*agent, mo);
    mqtt->start();
  }
  std::unique_ptr<connect::ShdrAdapter> shdr;
  if (!o.shdr.empty()) {
    connect::ShdrOptions so;
    so.host = shdr_address;
    so.port = shdr_port;
    shdr = std::make_unique<connect::ShdrAdapter>(*agent, so);
    try {
      shdr->start();
    } catch (const std::runtime_error& e) {
      fmt::print(stderr, "error: --shdr: {}\n", e.what());
      return kExitUsage;
    }
  }
  if (!o.program.empty() && !open_program(host.controller(), o.program)) return kExitProgram;

  fmt::print("opencnc serve: {} on the simulated machine ({})\n", profile.name,
             o.speed == 0 ? "real time" : fmt::format("virtual time at {}x", o.speed));
  fmt::print("  open      http://{}:{}/#token={}\n", host_part, server.port(), tokens->operator_token());
  fmt::print("  operator  {}\n  admin     in {}\n  history   {}\n", tokens->operator_token(),
             tokens->origin(), (data / "history.sqlite").string());
  if (features->has("journal")) fmt::print("  journal   {}\n", fo.journal_dir);
  fmt::print("  mtconnect http://{}:{}/probe  (device {}, {})\n", host_part, server.port(),
             agent->model().name(), agent->model().uuid());
  if (broker)
    fmt::print("  mqtt      {}:{} topics {}/…/{}\n", broker->host, broker->port, "MTConnect",
               agent->model().uuid());
  if (shdr)
    fmt::print("  shdr      {}:{} (an MTConnect agent's adapter; device {})\n", shdr_address, shdr->port(),
               agent->model().uuid());
  fmt::print("  features  {}\n  Ctrl-C stops.\n", fmt::join(features->names(), ", "));
  std::fflush(stdout);

  const StopSignals signals;
  while (StopSignals::requested().load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  fmt::print("\nopencnc serve: {}: stopping (a run in progress is aborted on the path)\n",
             signal_name(StopSignals::requested().load()));
  server.stop();
  sampler.stop();  // the machine UNAVAILABLE, then published as such
  if (mqtt) mqtt->stop(2000);
  if (shdr) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the UNAVAILABLE lines leave first
    shdr->stop();
  }
  host.controller().submit(controller::Request::simple(control::CommandKind::FeedHold));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  host.controller().submit(controller::Request::simple(control::CommandKind::Abort));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  host.stop();
  history->flush();
  if (host.overruns() > 0) fmt::print("servo overruns: {} of {} periods\n", host.overruns(), host.ticks());
  return kExitOk;
}

}  // namespace

void add_serve_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<ServeOptions>();
  CLI::App* cmd =
      app.add_subcommand("serve", "Run the simulated machine and serve the operator's HMI in the browser");
  cmd->add_option("--machine,-m", opts->machine, "Machine profile, e.g. configs/mill-3axis.toml")->required();
  cmd->add_option("--set", opts->sets, "Override a profile key (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option(
      "--listen", opts->listen,
      "ADDRESS:PORT to listen on (default 127.0.0.1:8080; port 0: any free port; any other address "
      "than loopback needs a token for every call)");
  cmd->add_option("--program", opts->program, "A G-code program to open at start (Auto mode)");
  cmd->add_option(
      "--programs", opts->programs_dir,
      "The folder programs are opened from (default: the --program's folder, else the current one)");
  cmd->add_option(
      "--data", opts->data_dir,
      "Where the tokens and the history live (default $XDG_STATE_HOME/opencnc or ~/.local/state/opencnc)");
  cmd->add_option(
      "--journal", opts->journal_dir,
      "The breakpoint journal's folder on a machine with a power monitor (default: journal in --data)");
  cmd->add_option("--static", opts->static_dir,
                  "The built front end (default: web/dist beside the build folder)");
  cmd->add_option("--speed", opts->speed,
                  "Virtual time at this many machine seconds per second instead of a real-time servo thread")
      ->check(finite_range(0.01, 1000));
  cmd->add_option("--servo-cpu", opts->servo_cpu,
                  "Real time: run the servo thread on this CPU and keep the server's threads off it "
                  "(best with that CPU isolated: isolcpus=N)")
      ->check(CLI::Range(0, 1023));
  cmd->add_option("--stream-hz", opts->stream_hz,
                  "Status messages per second on the WebSocket stream (default 30)")
      ->check(finite_range(1, 1000));
  cmd->add_option("--device-name", opts->device_name,
                  "The machine's name to MTConnect and MQTT (default: the profile's; machines of one profile "
                  "in one shop need their own)");
  cmd->add_option("--mtconnect-hz", opts->mtconnect_hz,
                  "Status samples per second into the MTConnect agent (default 10)")
      ->check(finite_range(0.1, 1000));
  cmd->add_option(
      "--mqtt", opts->mqtt,
      "Publish the machine's observations to this MQTT broker: mqtt://HOST[:PORT] (docs/connectivity.md)");
  cmd->add_option("--mqtt-keepalive", opts->mqtt_keepalive_s,
                  "Seconds between keep-alives; the broker marks the machine unavailable after 1.5 of them "
                  "without a word (default 5)")
      ->check(CLI::Range(5, 65535));
  cmd->add_option(
      "--hmi-url", opts->hmi_url,
      "How the fleet view links to this machine's HMI (default: http://ADDRESS:PORT/ of --listen, "
      "the host's name for 0.0.0.0 or ::)");
  cmd->add_option(
      "--shdr", opts->shdr,
      "Serve the machine's observations as an SHDR adapter on ADDRESS:PORT (127.0.0.1:7878), for a "
      "site's own MTConnect agent (docs/connectivity.md)");
  cmd->callback([opts, &registry] { registry.set_result(serve(*opts)); });
}

}  // namespace opencnc::cli
