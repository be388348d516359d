// SPDX-License-Identifier: GPL-3.0-or-later
// connect: the agent's observations and device as JSON — the payloads of the MQTT topics
// (docs/connectivity.md, "MQTT").
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "opencnc/connect/agent.hpp"

namespace opencnc::connect {

/// Observations dropped before a batch (the queue overflowed while the broker was away, or the
/// agent's buffer turned over): the sequence numbers from `from` to `to`, `count` of them.
struct Gap {
  std::uint64_t from = 0, to = 0, count = 0;
};

/// `MTConnect/Probe/<uuid>`: the device, its components and data items, and where its own HMI is
/// (`hmi`, an opencnc field for the fleet view; "" = left out).
std::string probe_json(const DeviceModel& model, const AgentOptions& options, std::string_view hmi_url = {});
/// `MTConnect/Sample/<uuid>`: a batch of consecutive observations with its sequence range and the
/// gap before it, if any.
std::string sample_json(const DeviceModel& model, const AgentOptions& options,
                        std::span<const Observation> batch, const Gap& gap, std::uint64_t dropped_total);
/// `MTConnect/Current/<uuid>`: every item's current observation and the next sequence, and the
/// program's `progress` (0 … 1; an opencnc field beside MTConnect's, for the fleet view).
std::string current_json(const DeviceModel& model, const AgentOptions& options,
                         std::span<const Observation> snapshot, std::uint64_t next_sequence, double progress);
/// ISO 8601 UTC with microseconds ("2026-12-07T04:12:11.123456Z").
std::string iso_time(std::int64_t us);

}  // namespace opencnc::connect
