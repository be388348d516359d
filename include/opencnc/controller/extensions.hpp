// SPDX-License-Identifier: GPL-3.0-or-later
// The hub's extension points besides observers and features: what a machine feature adds to the
// G-code source (code modules, a pass over the moves), to the event log (the words of the events
// and faults its stage of the tick raises), to a run's report (a section written by its observer)
// and to a front end's status (its state); preflight.hpp has the one of the soft-limit check
// (MoveReach). The hub names no feature: it calls these. See docs/code-overview.md, "How to add a
// machine feature".
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "opencnc/canon/pass_through_sink.hpp"
#include "opencnc/canon/program.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/command.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/controller/controller_status.hpp"
#include "opencnc/controller/preflight.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/gcode/dialect.hpp"

namespace opencnc::gcode {
struct Extensions;
}

namespace opencnc::controller {

/// A pass over a program's moves as the builder appends them: it may rewrite the moves just
/// appended (a hand-fed axis held, a coupled slave's coordinate) and add actions before them.
/// One per program stream or scan; non-real-time; the builder's thread.
class MovePass {
 public:
  virtual ~MovePass() = default;
  /// Handles the moves of `program` appended since the last call (and the actions before them).
  virtual void process(canon::Program& program) = 0;
  /// A new leg: `program` becomes a new window numbered from 0, starting where the machine stands.
  virtual void restart() = 0;
  /// What the pass refused, each at its move's line: errors end the stream and fail the preflight.
  virtual const Diagnostics& failures() const = 0;
};

/// A pass over the canonical calls before the builder: where a MovePass can only rewrite the
/// moves appended, this one may hold calls back and hand others on in their place — a move split
/// in pieces (each piece a call with the move's segment id: the builder notes the split), a feed
/// changed, process codes added. A call it does not override is handed on after `before_call()`,
/// where a pass hands on what it holds; the hub calls `flush()` when the interpreter stops (a
/// sync point, the program's or an MDI line's end, an error). One per program stream or scan,
/// chained before the builder in the parts' order; non-real-time; the builder's thread.
class CallPass : public canon::PassThroughSink {
 public:
  /// Hands on every call held.
  virtual void flush() = 0;
};

/// What a feature adds to the G-code program source: code modules of its own (G or M codes) and a
/// pass over the moves. Immutable: the sources made from one set-up share it, from any thread.
class SourcePart {
 public:
  virtual ~SourcePart() = default;
  /// The modules a program of `dialect` reads with: `base` with this feature's added (`base`
  /// itself when it adds none).
  virtual std::shared_ptr<const gcode::Extensions> modules(
      gcode::Dialect /*dialect*/, std::shared_ptr<const gcode::Extensions> base) const {
    return base;
  }
  /// A fresh pass for one program (null: the feature has none).
  virtual std::unique_ptr<MovePass> pass() const { return nullptr; }
  /// A fresh pass over the calls for one program (null: the feature has none).
  virtual std::unique_ptr<CallPass> call_pass() const { return nullptr; }
  /// This part for a profile an admin has edited; null when a program reads the same with it.
  virtual std::shared_ptr<const SourcePart> for_profile(const config::MachineProfile& /*profile*/) const {
    return nullptr;
  }
};

/// A note for the event log: its severity, code and words.
struct EventNote {
  Severity severity = Severity::Note;
  std::string code;
  std::string text;
};

/// The words of what a feature's stage of the tick raises: its events, its faults, what a run
/// waits for there. Every call answers nothing for what is not the feature's. Controller thread.
class EventTexts {
 public:
  virtual ~EventTexts() = default;
  /// The note an event of the servo gets in the log.
  virtual std::optional<EventNote> event_note(const control::ServoEvent& /*e*/,
                                              const config::MachineProfile& /*profile*/,
                                              const control::ServoConfig& /*servo*/) const {
    return std::nullopt;
  }
  /// A fault's description (its code is control::fault_code's).
  virtual std::optional<std::string> fault_text(const control::Fault& /*f*/,
                                                const config::MachineProfile& /*profile*/,
                                                const control::ServoConfig& /*servo*/) const {
    return std::nullopt;
  }
  /// What the run waits for ("the coupled axes to stand …"), when it is the feature's stage.
  virtual std::optional<std::string> wait_text(const control::ServoStatus& /*s*/) const {
    return std::nullopt;
  }
};

/// An observer's section of a run's report (the EDM's burn, a power failure's stop): what the
/// command line prints and writes into the report's JSON under `report_key()`. Called after the
/// run, from the thread that ran it.
class ReportSection {
 public:
  virtual ~ReportSection() = default;
  /// The section's key in the report ("edm", "power_fail").
  virtual std::string report_key() const = 0;
  /// The section for the terminal: whole lines, each ending in '\n' ("" for none).
  virtual std::string report_text() const = 0;
  /// The section as JSON text (a value).
  virtual std::string report_json() const = 0;
};

/// A feature's state for a front end's status (the HMI's `features`): JSON text under
/// `state_key()`. Controller thread, after the feature's on_status (the HMI's board asks at its
/// status rate).
class FeatureState {
 public:
  virtual ~FeatureState() = default;
  /// The state's key in the status ("journal", "electrode").
  virtual std::string state_key() const = 0;
  /// The state as JSON text (a value), from what the feature saw up to `status`.
  virtual std::string state_json(const ControllerStatus& status) = 0;
};

}  // namespace opencnc::controller
