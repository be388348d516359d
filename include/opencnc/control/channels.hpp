// SPDX-License-Identifier: GPL-3.0-or-later
// ServoChannels — the only things the real-time servo and the non-real-time controller share:
// fixed-size lock-free queues and the status buffer, without pointers (shared-memory ready).
#pragma once

#include <array>
#include <atomic>
#include <type_traits>

#include "opencnc/control/command.hpp"
#include "opencnc/control/spsc_ring.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/control/triple_buffer.hpp"
#include "opencnc/machine/edm.hpp"
#include "opencnc/motion/compensation.hpp"
#include "opencnc/traj/block_queue.hpp"

namespace opencnc::control {

/// Pitch-error tables handed to the tick (an admin's edit): two buffers per joint, allocated once
/// with the channels. The tick reads the buffer it switched to last (none at start: it uses its
/// configuration's table); the controller writes only the other one, and only while no change is
/// in flight, then names it in a StagePitchTable command: the command ring's release/acquire
/// publishes the table with it. Once the tick has applied it (ApplyJointLimits accepted), the
/// buffer it used before is the controller's to write. Plain data.
struct PitchTableArea {
  std::array<std::array<motion::PitchTable, 2>, motion::kMaxCompensatedJoints> joints{};
};

/// The machining conditions handed to the tick (an admin's edit): the controller writes them only
/// while no change of the profile is in flight, then sends StageEdmConditions and
/// ApplyJointLimits; the tick reads them only in that apply (checks them, then copies them into
/// its configuration), so one buffer is enough. Plain data.
struct EdmConditionTable {
  std::array<machine::EdmCondition, machine::kMaxEdmConditions> conditions{};
  int count = 0;
};

/// Every queue has exactly one producer and one consumer:
///
/// | member     | producer                  | consumer   |
/// |------------|---------------------------|------------|
/// | commands   | controller                | servo tick |
/// | blocks     | planner (controller)      | servo tick |
/// | actions    | controller                | servo tick |
/// | events     | servo tick                | controller |
/// | status     | servo tick                | controller |
/// | trace      | servo tick (when enabled) | recorder   |
///
/// and `pitch_tables` and `edm_conditions` are written by the controller, read by the servo tick
/// (PitchTableArea, EdmConditionTable).
/// About 4 MB; construct it on the heap or in shared memory (standard layout, lock-free atomics).
struct ServoChannels {
  SpscRing<Command, 256> commands;
  traj::BlockQueue blocks;
  /// The machine side of the markers of the current run, in action order; as many as blocks
  /// can be queued, so the record of every queued marker is always there.
  SpscRing<MachineAction, traj::BlockQueue::kCapacity> actions;
  SpscRing<ServoEvent, 1024> events;
  TripleBuffer<ServoStatus> status;
  SpscRing<TraceSample, 8192> trace;
  std::atomic<bool> trace_enabled{false};
  PitchTableArea pitch_tables;
  EdmConditionTable edm_conditions;
};

static_assert(std::is_standard_layout_v<ServoChannels>);

}  // namespace opencnc::control
