// SPDX-License-Identifier: GPL-3.0-or-later
// The POSIX shared-memory segment that holds a SharedSegment: created by the process that runs the
// tick (the HAL component), attached by the controller process, which a segment of another build
// refuses. Not real-time: create and attach at set-up, the hand-over helpers from the controller.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "opencnc/control/shared_channels.hpp"

namespace opencnc::control {

/// The layout identity of this build: kSharedLayoutRevision, the size and alignment of every
/// shared type and a hash of the headers that define them. Any thread.
std::uint64_t shared_layout_id() noexcept;

/// A mapping of a named segment ("/opencnc" style: one leading slash, no other).
class SegmentMapping {
 public:
  /// Creates the segment `name` anew (a stale one of that name is unlinked first: mappings of
  /// it stay valid but are no longer found), initialises the header, the set-up and the
  /// channels, and maps it. Nothing on failure, with `error` saying why. Setup thread.
  static std::unique_ptr<SegmentMapping> create(const std::string& name, std::int64_t period_ns,
                                                std::uint32_t heartbeat_timeout_ticks, std::string& error);
  /// Maps an existing segment and checks it: ours (magic), of this build (layout id, size).
  /// Nothing on failure, with `error` saying why. Controller's setup thread.
  static std::unique_ptr<SegmentMapping> attach(const std::string& name, std::string& error);

  ~SegmentMapping();
  SegmentMapping(const SegmentMapping&) = delete;
  SegmentMapping& operator=(const SegmentMapping&) = delete;

  /// Any thread (the fields say who writes what).
  SharedSegment& segment() noexcept { return *segment_; }
  const std::string& name() const noexcept { return name_; }

 private:
  SegmentMapping(std::string name, SharedSegment* segment, bool owner) noexcept
      : name_(std::move(name)), segment_(segment), owner_(owner) {}
  std::string name_;
  SharedSegment* segment_;
  bool owner_;  ///< created it: unlinks the name on destruction
};

/// Controller side: writes `setup` and asks the tick to take it; returns the generation to wait
/// for with setup_taken(). Controller thread; only one controller may do this at a time.
std::uint64_t offer_setup(SharedSegment& s, const SharedSetup& setup) noexcept;
/// The tick has taken set-up `generation`. Any thread.
bool setup_taken(const SharedSegment& s, std::uint64_t generation) noexcept;

/// Drains what a previous controller left unread (events, trace samples), so that a controller
/// attaching to a running tick starts from now. Controller thread, on attach.
void drain_stale_output(SharedSegment& s) noexcept;

}  // namespace opencnc::control
