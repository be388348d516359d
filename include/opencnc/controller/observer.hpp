// SPDX-License-Identifier: GPL-3.0-or-later
// How features plug into the controller: observers that receive its events, status and trace, and
// features that also answer requests of their own (the journal writer, path retrace, the tool
// guard, the HMI server). See docs/code-overview.md, "Where features plug in".
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "opencnc/canon/program.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/controller/controller_status.hpp"
#include "opencnc/controller/events.hpp"
#include "opencnc/controller/request.hpp"

namespace opencnc::controller {

/// The answer to a request.
struct Outcome {
  bool accepted = false;
  control::Refusal refusal = control::Refusal::None;
  std::string message;      ///< why it was refused, in words
  Diagnostics diagnostics;  ///< program problems (open, MDI, cycle start)
};

/// What a trace sample refers to: the program window of the run it belongs to (its moves are
/// held until every observer has seen the samples on them), and the job's move number of the
/// window's first move. `program` is null for samples of a run no longer held.
struct TraceContext {
  const canon::Program* program = nullptr;
  std::uint64_t first_move = 0;
  JobKind job = JobKind::None;
  std::uint32_t job_id = 0;
};

/// Receives what the controller does. Every call comes from the controller's thread, inside
/// Controller::service(), in order: a slow observer slows the controller (never the servo);
/// hand work to a thread of your own if it may block. Exceptions are caught: the observer is
/// detached and a note says so.
class ControllerObserver {
 public:
  virtual ~ControllerObserver() = default;
  /// Every entry of the event log from the moment of attaching, in order.
  virtual void on_event(const ControllerEvent& /*e*/) {}
  /// The status, at the rate asked for (ObserverOptions::status_period_s).
  virtual void on_status(const ControllerStatus& /*s*/) {}
  /// Every servo period of a program run while tracing (ObserverOptions::trace).
  virtual void on_trace(const control::TraceSample& /*s*/, const TraceContext& /*c*/) {}
};

struct ObserverOptions {
  double status_period_s = 0;  ///< on_status every this much servo time (0: never)
  bool trace = false;          ///< on_trace for every period of program runs
};

/// What a feature may do from the controller's thread while it handles a request or observes.
class FeatureHost {
 public:
  virtual ~FeatureHost() = default;
  /// Queues a request as a front end would (it is handled in this or the next service()).
  virtual std::uint64_t submit(Request r) = 0;
  /// The status as of the last service().
  virtual const ControllerStatus& current_status() const = 0;
  virtual const config::MachineProfile& profile() const = 0;
  /// A note for the operator, in the event log.
  virtual void note(Severity severity, std::string code, std::string text) = 0;
  /// Inside Feature::handle only: the request being handled is answered later, by answer()
  /// (work on a thread of the feature's own: a scan of a long program); handle's Outcome is then
  /// not used. Returns the request's id. Controller thread.
  virtual std::uint64_t defer() = 0;
  /// The answer to a request deferred with defer() (once). Controller thread.
  virtual void answer(std::uint64_t id, Outcome outcome) = 0;
  /// Inside Feature::handle only: the request being handled is the controller's long work (it may
  /// wait for a disk or a database): `work` runs on the controller's task thread where the tick
  /// runs by itself, at once in virtual time (so runs repeat bit for bit); then `then`, on the
  /// controller's thread, gives the answer. handle's Outcome is then not used. Requests sent after
  /// it wait their turn; the stops do not (docs/controller.md, "Stops never wait").
  virtual void answer_after(std::function<void()> work, std::function<Outcome()> then) = 0;
};

/// What is about to start: asked of every feature before a program or auxiliary program starts.
struct StartCheck {
  JobKind job = JobKind::Program;  ///< Program (cycle start in Auto) or Auxiliary
  std::string name;                ///< the program's name or file
};

/// A sync point the machine has answered, before the interpreter reads on past it.
struct SyncCheck {
  JobKind job = JobKind::Program;
  SyncKind kind = SyncKind::None;
  SourceLocation where;  ///< the block that asked (M6 at part.ngc:12)
  /// ToolChange: the tool-table index of the tool the program changed to (LinuxCNC's
  /// CHANGE_TOOL index: entry k of the table the program runs with; 0: no tool).
  int tool_index = 0;
};

/// An observer that also answers requests::Feature requests addressed to its name().
class Feature : public ControllerObserver {
 public:
  /// Before a program (cycle start in Auto, not a resume) or an auxiliary program starts:
  /// false refuses the start (`control.feature-check`, `*why` the message, one line per
  /// reason); nothing moves. Controller thread; called with the program preflighted.
  virtual bool allow_start(const StartCheck& /*start*/, FeatureHost& /*host*/, std::string* /*why*/) {
    return true;
  }
  /// At a sync point the machine has passed (a tool change, M0/M1, M66), before the interpreter
  /// reads on: false holds the job there — the machine stands at the point, nothing after it is
  /// interpreted or planned — and the feature is asked again every service() until it says
  /// true (or the job is aborted). A feature that holds says why with a note. Controller thread.
  virtual bool allow_continue(const SyncCheck& /*sync*/, FeatureHost& /*host*/) { return true; }
  /// The name requests address ("retrace", "journal", …). Unique per controller.
  virtual std::string_view name() const = 0;
  /// Called once when added (Controller::add_feature), from the controller's thread.
  virtual void attached(FeatureHost& /*host*/) {}
  /// Handles one request addressed to this feature. Controller thread.
  virtual Outcome handle(const requests::Feature& request, FeatureHost& host) = 0;
  /// Every service(), before the job is served: a feature whose work runs on a thread of its
  /// own looks here whether it is done (and answers a deferred request). Controller thread; keep
  /// it cheap (an atomic load).
  virtual void poll(FeatureHost& /*host*/) {}
};

}  // namespace opencnc::controller
