// SPDX-License-Identifier: GPL-3.0-or-later
// connect::ShdrAdapter — the adapter side of MTConnect's SHDR protocol (docs/connectivity.md,
// "SHDR"): a TCP listener that a site's own MTConnect agent connects to, and that writes it the
// agent's observations as pipe-delimited lines — the whole current state on each connection, then
// every change — answering `* PING` with `* PONG <heartbeat>`.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "opencnc/connect/agent.hpp"

namespace opencnc::connect {

struct ShdrOptions {
  std::string host = "127.0.0.1";  ///< the address listened on
  int port = 7878;                 ///< 0: any free port (port() tells which)
  /// Told to the agent in `* PONG`: it pings this often, and each side closes the connection when
  /// the other is silent for twice as long.
  int heartbeat_ms = 10000;
  int poll_ms = 50;             ///< how often the agent's new observations are read
  std::size_t max_clients = 8;  ///< connections beyond are closed at once
  /// A client's lines are read from the agent's buffer only while less than this waits to be
  /// written to it: the agent's buffer is the queue, each client reads it at its own pace.
  std::size_t max_backlog_bytes = std::size_t{256} << 10;
  /// A client whose write has waited this long, or that fell so far behind that the agent's buffer
  /// turned over under it, is dropped (it reconnects and starts again from a snapshot) rather than
  /// holding anyone up.
  int write_timeout_ms = 10000;
};

struct ShdrStats {
  std::uint64_t clients = 0;      ///< connected now
  std::uint64_t connections = 0;  ///< accepted since the start
  std::uint64_t refused = 0;      ///< closed at once: max_clients reached
  std::uint64_t lines = 0;        ///< observation lines written (snapshots included)
  std::uint64_t pongs = 0;
  std::uint64_t dropped_slow = 0;     ///< clients dropped: a write timed out, or they fell out of the buffer
  std::uint64_t dropped_garbage = 0;  ///< clients dropped for a line longer than 4 KB (not an agent)
  std::uint64_t dropped_silent = 0;   ///< clients that stopped pinging
};

/// `value` as one SHDR field: as it is, unless it holds '|', a quote or a line break, in which case it
/// is quoted and '|' and '"' escaped with '\' (line breaks become spaces: a line is a record).
std::string shdr_field(std::string_view value);

/// Observations as SHDR lines (each ending "\n"): consecutive samples and events of one timestamp
/// share a line (`time|id|value|id|value`), each condition has its own
/// (`time|id|LEVEL|native_code|native_severity|qualifier|message`). Keys are the data items' ids,
/// the same as in the probe, which a site's agent can take as its device file.
std::string shdr_lines(const DeviceModel& model, std::span<const Observation> observations);

class ShdrAdapter {
 public:
  /// Serves `agent`'s observations; the agent must outlive the adapter.
  ShdrAdapter(const Agent& agent, ShdrOptions options);
  ~ShdrAdapter();
  ShdrAdapter(const ShdrAdapter&) = delete;
  ShdrAdapter& operator=(const ShdrAdapter&) = delete;

  /// Binds the listener (throws std::runtime_error naming the address when it cannot) and starts
  /// serving on a thread of its own.
  void start();
  /// Closes every connection and the listener.
  void stop();
  /// The port listened on (after start()).
  int port() const noexcept;
  ShdrStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace opencnc::connect
