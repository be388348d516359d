// SPDX-License-Identifier: GPL-3.0-or-later
// Sync points: execute mode waits for the machine's answer, scan mode assumes it; either way
// the answer becomes parameters (#5061-#5070, #5399) and the current position.
#include "sync_points.hpp"

namespace opencnc::gcode {

void SyncPoints::ask(const SyncValues& assumed, Mode mode) {
  if (mode == Mode::Execute) {
    // A block may stop after asking for feedback (M66 P0 M0): the feedback first, then the stop.
    if (assumed.kind == SyncKind::ProgramStop) {
      if (pending_ == SyncKind::None) {
        pending_ = SyncKind::ProgramStop;
        request_ = assumed;
      } else {
        stop_after_ = true;
      }
      return;
    }
    if (pending_ == SyncKind::ProgramStop) stop_after_ = true;
    pending_ = assumed.kind;
    request_ = assumed;
    return;
  }
  if (assumed.kind == SyncKind::ProgramStop) return;  // nothing to assume: the scan goes on
  assumed_ = assumed;
  block_pending_ = true;
}

void SyncPoints::apply_assumed(InterpState& st) {
  block_pending_ = false;
  // A tool change leaves the machine where the canonical view of the position says it is.
  if (assumed_.kind == SyncKind::ToolChange) assumed_.position = st.position.canon_position;
  apply(assumed_, st);
}

SyncPoints::Answer SyncPoints::answer(const SyncValues& values, InterpState& st) {
  if (pending_ == SyncKind::None) return Answer::Done;
  apply(values, st);
  const bool no_contact =
      request_.kind == SyncKind::Probe && request_.contact_required && !values.probe_tripped;
  const bool seeks_contact = request_.seeks_contact;
  pending_ = stop_after_ ? SyncKind::ProgramStop : SyncKind::None;
  if (stop_after_) request_ = SyncValues{SyncKind::ProgramStop};
  stop_after_ = false;
  if (!no_contact) return Answer::Done;
  pending_ = SyncKind::None;  // the run ends with the probe's error: nothing more to wait for
  return seeks_contact ? Answer::NoContact : Answer::ContactKept;
}

void SyncPoints::apply(const SyncValues& values, InterpState& st) {
  auto& p = st.parameters;
  switch (values.kind) {
    case SyncKind::Probe:
      for (int i = 0; i < kAxisCount; ++i) p[static_cast<std::size_t>(5061 + i)] = values.probe_position[i];
      p[5070] = values.probe_tripped ? 1.0 : 0.0;
      st.position.current = values.position;
      st.position.canon_position = values.position;
      break;
    case SyncKind::Input:
      p[5399] = values.input_value;
      break;
    case SyncKind::ToolChange:
      st.position.current = values.position;
      break;
    case SyncKind::ProgramStop:
    case SyncKind::None:
      break;
  }
}

}  // namespace opencnc::gcode
