// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::BreakpointRecord — where a power failure stopped a program and what the machine was
// doing: plain data and its versioned, checksummed serialisation (the journal's payload).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "opencnc/core/axes.hpp"

namespace opencnc::recovery {

/// How far the record is: written at the signal (the axes still stopping), or completed with
/// where the motion came to rest.
enum class BreakpointStage : std::uint8_t { Stopping = 0, AtRest = 1 };

/// "stopping", "at-rest". Any thread.
const char* to_string(BreakpointStage s) noexcept;

/// The coupling law that held when the power failed (control::CouplingStatus, kind 0 = none).
struct BreakpointCoupling {
  std::uint8_t kind = 0;  ///< motion::CouplingKind
  std::int8_t master_axis = -1, slave_axis = -1;
  std::int32_t table = 0;
  double pitch_mm = 0, pitch_rate = 0;
  double master_origin = 0, slave_origin = 0;  ///< machine coordinates at engagement
  bool operator==(const BreakpointCoupling&) const = default;
};

/// One breakpoint (docs/broaching.md, "The breakpoint record"). Positions are machine
/// coordinates (mm, degrees), every axis.
struct BreakpointRecord {
  static constexpr std::uint32_t kVersion = 1;

  bool valid = false;  ///< a recovery choice is pending (cleared once one has completed)
  BreakpointStage stage = BreakpointStage::Stopping;
  std::string program_path;        ///< as opened
  std::uint64_t program_hash = 0;  ///< FNV-1a 64 of the file's bytes (hash_file)
  std::uint64_t program_size = 0;  ///< bytes
  Pose program_start{};            ///< where the program was placed when opened (resume replays from it)
  /// Where in the program: the interpreter's segment id of the interrupted move, the job's move
  /// number, and the path length from the move's start to the commanded position.
  std::uint64_t segment = 0;
  std::uint64_t job_move = 0;
  double segment_offset_mm = 0;
  std::string source_file;  ///< the block's file and line
  std::uint32_t line = 0;
  /// The interrupted move: its kind (canon::MoveKind), start and end, and the path length left
  /// from the commanded position to its end.
  std::uint8_t move_kind = 0;
  Pose move_start{}, move_end{};
  double move_remaining_mm = 0;
  Pose commanded{}, actual{};
  /// Digest of the interpreter's modal state at the segment (modal_digest.hpp); 0 = not known.
  std::uint64_t modal_digest = 0;
  std::int32_t tool = 0;
  double spindle_rpm = 0;
  std::int8_t spindle_direction = 0;  ///< 1 clockwise, −1 counterclockwise, 0 stopped
  bool flood = false, mist = false;
  BreakpointCoupling coupling;
  double signal_time_s = 0;  ///< servo time of the power-fail signal
  double rest_time_s = 0;    ///< servo time the commanded motion came to rest (AtRest)

  bool operator==(const BreakpointRecord&) const = default;
};

/// The record as bytes: magic "OCBP", version, the fields little-endian, CRC-32 of all before it.
/// Any thread.
std::vector<std::byte> encode(const BreakpointRecord& r);
/// The record from `bytes`, or nullopt with the reason in `*error` (wrong magic or version,
/// truncated, checksum). Any thread.
std::optional<BreakpointRecord> decode(std::span<const std::byte> bytes, std::string* error);

/// The record in words for the operator: program, line, segment, stage, valid, positions of the
/// coupled axes. Any thread.
std::string describe(const BreakpointRecord& r);

/// FNV-1a 64 of a file's bytes and its size, or nullopt if it cannot be read. Blocks on the
/// disk: not the servo's nor the controller's thread for large files.
struct FileHash {
  std::uint64_t hash = 0;
  std::uint64_t size = 0;
};
std::optional<FileHash> hash_file(const std::string& path);

}  // namespace opencnc::recovery
