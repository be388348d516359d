// SPDX-License-Identifier: GPL-3.0-or-later
// G38.2-G38.5 straight probing: the probe move, then a sync point for the probe result.
#include "opencnc/gcode/probing.hpp"

#include <cmath>
#include <memory>

#include <fmt/format.h>

namespace opencnc::gcode {

namespace {

// Where the stand-alone rs274 leaves the tool after probing from `start` to `end`: backed off
// from the end towards the start by probe_backoff(), in X, Y and Z (the other axes at the end).
Pose backed_off(const Pose& start, const Pose& end, canon::Units units) {
  Pose p = end;
  const double dx = start[0] - end[0], dy = start[1] - end[1], dz = start[2] - end[2];
  const double distance = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (distance != 0) {
    const double backoff = probe_backoff(units);
    p[0] = end[0] + backoff * (dx / distance);
    p[1] = end[1] + backoff * (dy / distance);
    p[2] = end[2] + backoff * (dz / distance);
  }
  return p;
}

class Probe final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    InterpState& st = ctx.state();
    const ModalState& m = st.modal;
    if (m.cutter_comp != CutterComp::Off)
      ctx.error(ErrorCode::CompProbe, "probing is not possible while cutter compensation is on (G40 first)");
    if (m.feed_rate == 0.0) ctx.error(ErrorCode::FeedZero, "probe move with zero feed rate (program an F word)");
    if (m.feed_mode == canon::FeedMode::UnitsPerRevolution)
      ctx.error(ErrorCode::ProbeFeedPerRevolution, "probing is not possible in feed per revolution mode (G95)");
    const Pose end = ctx.end_point(b);
    // G38.2 and G38.4 fail when the probe does not change state; G38.3 and G38.5 report it.
    const bool contact_required = code == 382 || code == 384;
    if (contact_required && end == st.position.current)
      ctx.error(ErrorCode::ProbeStartTooClose, "the probe move ends where it starts");
    // The canonical view of the start (what rs274's canon backs off towards).
    const Pose start = st.position.canon_position;
    canon::Sink& out = ctx.output();
    out.turn_probe_on();
    out.straight_probe(0, end);
    out.turn_probe_off();
    st.modal.motion = code;
    SyncValues assumed;
    assumed.kind = SyncKind::Probe;
    assumed.probe_position = end;
    assumed.probe_tripped = false;   // rs274 reports #5070 = 0
    assumed.position = backed_off(start, end, m.units);
    assumed.contact_required = contact_required;
    if (ctx.options().scan_assumption == ScanAssumption::Other) {  // a trip halfway
      Pose half = st.position.current;
      for (int i = 0; i < kAxisCount; ++i) half[i] = 0.5 * (half[i] + end[i]);
      assumed.probe_position = half;
      assumed.probe_tripped = true;
      assumed.position = half;
    }
    assumed.seeks_contact = code == 382 || code == 383;
    ctx.request_sync(assumed);
  }
};

}  // namespace

void add_probing(Extensions& ext) {
  auto probe = std::make_shared<Probe>();
  for (int code : {382, 383, 384, 385}) ext.g[static_cast<std::size_t>(code)] = probe;
}

}  // namespace opencnc::gcode
