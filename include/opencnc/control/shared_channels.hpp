// SPDX-License-Identifier: GPL-3.0-or-later
// SharedSegment — the layout of the shared memory between the controller process and a servo tick
// running in another process (the HAL component): a header (magic, layout id, heartbeat, set-up
// hand-over), the servo's set-up, and the ServoChannels. Plain data and lock-free atomics only.
#pragma once

#include <atomic>
#include <cstdint>
#include <type_traits>

#include "opencnc/control/channels.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/machine/machine_io.hpp"

namespace opencnc::control {

/// "OCNCSHM\0" little-endian: a segment that is not ours is refused before anything else is read.
inline constexpr std::uint64_t kSharedMagic = 0x004d4853434e434fULL;
/// Bumped by hand when the meaning of a field changes without its size changing.
inline constexpr std::uint32_t kSharedLayoutRevision = 1;

/// What the controller hands to the tick before it may run: the servo's configuration (from the
/// machine profile) and what the machine has wired (the profile's declarations).
struct SharedSetup {
  ServoConfig servo{};
  machine::MachineCapabilities capabilities{};
};

/// The segment's header. Written once by its creator (the component): magic, layout_id,
/// size_bytes, period_ns; the rest as each field says.
struct SharedHeader {
  std::uint64_t magic = 0;
  std::uint64_t layout_id = 0;   ///< shared_layout_id() of the creator's build
  std::uint64_t size_bytes = 0;  ///< sizeof(SharedSegment) of the creator's build
  std::int64_t period_ns = 0;    ///< the period of the thread the tick runs in
  /// Incremented by the controller process while it lives (its heartbeat thread).
  std::atomic<std::uint64_t> heartbeat{0};
  /// Periods without a new heartbeat after which the tick stops the machine (creator sets it).
  std::atomic<std::uint32_t> heartbeat_timeout_ticks{0};
  /// Process id of the attached controller (0: none); written by the controller on attach.
  std::atomic<std::uint32_t> controller_pid{0};
  /// The controller bumps it after writing `setup`; the tick copies the setup and acknowledges
  /// it in `setup_taken` (or leaves it pending while the drives are enabled under another one).
  std::atomic<std::uint64_t> setup_generation{0};
  std::atomic<std::uint64_t> setup_taken{0};
  /// Periods run by the tick (the component's liveness, for the controller); tick writes.
  std::atomic<std::uint64_t> ticks{0};
  /// Times the tick saw the heartbeat stop; tick writes.
  std::atomic<std::uint32_t> heartbeat_losses{0};
  /// The tick's heartbeat view: true while a controller's heartbeat is fresh; tick writes.
  std::atomic<bool> controller_alive{false};
};

/// The whole segment (about 5 MB). Created by the process that runs the tick, attached by the
/// controller (control/shared_memory.hpp).
struct SharedSegment {
  SharedHeader header;
  SharedSetup setup;
  ServoChannels channels;
};

static_assert(std::is_standard_layout_v<SharedHeader>);
static_assert(std::is_trivially_copyable_v<SharedSetup>);
static_assert(std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<std::uint32_t>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "atomics in shared memory must be address-free");

}  // namespace opencnc::control
