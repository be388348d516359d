// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI server: HTTP with the versioned JSON API (docs/api.md), a WebSocket stream of status
// and events, and the built front end, on threads of its own. It talks to the controller only
// through its thread-safe API (submit, outcome, status, an EventCursor per client): the servo
// never waits on it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/connect/agent.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/hmi/simulation.hpp"
#include "opencnc/hmi/tokens.hpp"

namespace opencnc::controller {
class GcodeProgramSource;
}

namespace opencnc::hmi {

class History;
class MachineFeatures;

struct ServerConfig {
  std::string address = "127.0.0.1";   ///< where to listen (IPv4 or IPv6 literal)
  std::uint16_t port = 8080;           ///< 0: any free port (port() tells which)
  std::filesystem::path programs_dir;  ///< `open` names programs relative to this folder
  std::filesystem::path static_dir;    ///< the built front end ("" or missing: none served)
  double stream_hz = 30;               ///< status messages per second on the WebSocket stream
  /// Messages a client may have waiting before it is dropped as one that stopped reading.
  std::size_t max_queued = 64;
  double command_timeout_s = 10;  ///< how long POST /commands waits for the answer (then 202)
  int io_threads = 1;
  /// The machine's features: their state goes into the status as `features` (null: none).
  const MachineFeatures* features = nullptr;
  /// The simulated machine's controls (`{"kind": "simulate", …}`, admin): applies the event and
  /// returns "" or why it cannot. Empty: none (a 409).
  std::function<std::string(const SimulationEvent&)> simulate;
  /// The machine's MTConnect agent (docs/connectivity.md): /probe, /current, /sample (streamed with
  /// `interval`), /assets, also under /mtconnect/ (null: those answer 404). It must outlive the server.
  const connect::Agent* mtconnect = nullptr;
  /// How long a streamed /sample may wait for its reader before it is dropped as one that stopped.
  double mtconnect_write_timeout_s = 10;
};

/// Counters of the server. Any thread.
struct ServerStats {
  std::size_t clients = 0;            ///< WebSocket clients connected now
  std::uint64_t dropped = 0;          ///< clients dropped because they stopped reading
  std::uint64_t stream_ticks = 0;     ///< status snapshots made for the stream so far
  std::uint64_t status_messages = 0;  ///< status messages queued to clients so far
  std::uint64_t http_requests = 0;
  std::size_t mtconnect_streams = 0;    ///< MTConnect /sample?interval= streams open now
  std::uint64_t mtconnect_dropped = 0;  ///< streams dropped because their reader stopped
  std::uint64_t mtconnect_parts = 0;    ///< documents sent on those streams so far
};

/// The server. start()/stop() from one thread; the rest from any.
class Server {
 public:
  /// `controller`, `history` (may be null) and `source` (may be null: no preview, no tool data)
  /// must outlive the server.
  Server(controller::Controller& controller, const config::MachineProfile& profile, Tokens tokens,
         History* history, const controller::GcodeProgramSource* source, ServerConfig config);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Binds, listens and starts the threads; false and `*error` when it cannot.
  bool start(std::string* error);
  /// Closes every connection and joins the threads. Idempotent.
  void stop();
  /// The port listened on (after start()).
  std::uint16_t port() const;
  /// Whether the address is a loopback one (then GET /api/v1/status needs no token).
  bool loopback_only() const;
  ServerStats stats() const;

  struct Impl;  ///< (server.cpp)

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace opencnc::hmi
