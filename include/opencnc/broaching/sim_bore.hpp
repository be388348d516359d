// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::SimBore — the simulated broach's workpiece kept beside the breakpoint journal, so that
// the simulation powered up again after a power failure finds the groove cut before it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::recovery {

/// The simulated workpiece (machine::SimBroachLoad::bore(): the depth cut in every cell) and the
/// breakpoint it belongs to (the record's program hash and signal time): a bore from another
/// power failure is not this one's workpiece.
struct SimBore {
  std::uint64_t program_hash = 0;
  double signal_time_s = 0;
  std::vector<float> cells;
};

/// The file's name in the journal's folder.
inline constexpr const char* kSimBoreFile = "sim-bore.bin";

/// The bore as bytes: magic "OCSB", version, the hash, the time, the cell count, the cells
/// (little-endian IEEE), CRC-32 of all before it. Any thread.
std::string encode_sim_bore(const SimBore& b);
/// The bore from `bytes`, or nullopt with the reason in `*error`. Any thread.
std::optional<SimBore> decode_sim_bore(std::string_view bytes, std::string* error);

/// Writes `b` as `dir`/sim-bore.bin, replaced whole (core atomic file). Blocking I/O; not the servo.
bool save_sim_bore(const std::string& dir, const SimBore& b, std::string* error);
/// The bore in `dir` (nullopt: none there, or unreadable or corrupt with the reason in `*error`).
/// Blocking I/O; not the servo.
std::optional<SimBore> load_sim_bore(const std::string& dir, std::string* error);

}  // namespace opencnc::recovery
