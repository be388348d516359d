// SPDX-License-Identifier: GPL-3.0-or-later
// hmi::FleetServer — the shop's fleet view (`opencnc fleet`, docs/connectivity.md, "The fleet"):
// the page (fleet.html of the built front end) and `GET /api/v1/fleet`, every machine the broker
// knows as connect::FleetWatcher keeps them. Read-only; it serves what any subscriber of the broker
// may read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "opencnc/connect/fleet.hpp"

namespace opencnc::hmi {

struct FleetServerConfig {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8090;         ///< 0: any free port (port() tells which)
  std::filesystem::path static_dir;  ///< the built front end ("" or without fleet.html: the API alone)
};

class FleetServer {
 public:
  /// `fleet` must outlive the server.
  FleetServer(const connect::FleetWatcher& fleet, FleetServerConfig config);
  ~FleetServer();
  FleetServer(const FleetServer&) = delete;
  FleetServer& operator=(const FleetServer&) = delete;

  /// Listens and serves on a thread of its own; false with the reason in `error`.
  bool start(std::string* error);
  void stop();
  std::uint16_t port() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace opencnc::hmi
