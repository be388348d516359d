// SPDX-License-Identifier: GPL-3.0-or-later
// ServoChannels — the only things the real-time servo and the non-real-time controller share:
// fixed-size lock-free queues and the status buffer, without pointers (shared-memory ready).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

#include "opencnc/control/command.hpp"
#include "opencnc/control/spsc_ring.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/control/triple_buffer.hpp"
#include "opencnc/machine/edm.hpp"
#include "opencnc/motion/compensation.hpp"
#include "opencnc/traj/block_queue.hpp"

namespace opencnc::control {

/// Which of a joint's two pitch buffers its tick reads: 0 or 1, or −1 for its configuration's own
/// table (a servo just built). Written by the tick only (release), read by the controller (acquire).
struct PitchBufferInUse {
  std::atomic<std::int8_t> index{-1};
};

/// Pitch-error tables handed to the tick (an admin's edit): two buffers per joint, allocated once
/// with the channels. Ownership is published, not remembered: `reading[j]` names the buffer joint
/// j's tick reads, and the controller writes only the other one, after reading `reading[j]` (so a
/// controller that attaches to a tick that outlived the previous one never writes the table in
/// use), and only while no change is in flight. It then names the buffer in a StagePitchTable
/// command (the command ring's release/acquire publishes the table with it); the tick refuses a
/// stage that names the buffer it reads. When the tick switches (ApplyJointLimits accepted) it
/// publishes the new index; the buffer it read before is the controller's from then on. A new
/// controller's set-up drops whatever a dead one staged and did not apply. Plain data and
/// lock-free atomics.
struct PitchTableArea {
  std::array<std::array<motion::PitchTable, 2>, motion::kMaxCompensatedJoints> joints{};
  std::array<PitchBufferInUse, motion::kMaxCompensatedJoints> reading{};
};

static_assert(std::atomic<std::int8_t>::is_always_lock_free);
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
/// | urgent     | controller's submit() (any thread, one at a time) | servo tick |
/// | blocks     | planner (controller)      | servo tick |
/// | actions    | controller                | servo tick |
/// | events     | servo tick                | controller |
/// | status     | servo tick                | controller |
/// | trace      | servo tick (when enabled) | recorder   |
///
/// and `pitch_tables`' buffers and `edm_conditions` are written by the controller and read by the
/// servo tick, which publishes in `pitch_tables.reading` the buffer it reads (PitchTableArea,
/// EdmConditionTable).
/// About 4 MB; construct it on the heap or in shared memory (standard layout, lock-free atomics).
struct ServoChannels {
  SpscRing<Command, 256> commands;
  /// The stops and overrides an operator sends (e-stop, machine off, abort, feed hold, jog stop,
  /// spindle off, the overrides), pushed by the thread that submits them the moment it does: they
  /// never wait behind the controller's other work. The tick takes both queues in `seq` order and
  /// this one whole every period.
  SpscRing<Command, 32> urgent;
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
