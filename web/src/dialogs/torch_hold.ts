// SPDX-License-Identifier: GPL-3.0-or-later
// The plasma torch's own hold (the arc lost, too many failed starts, no plate, the breakaway or the
// float switch): why the cut stopped, and the choices — retrace (pause: the torch up at the safe
// height, then the retrace panel steps back along the path and cuts on from the nearest point),
// resume where it stands (the torch finds the plate and pierces again there), or abort.
// Registered before the generic feed-hold dialog.
import { registerDialog, type DialogAction } from "../registry";
import type { Status } from "../types";

/** Why the torch held the run ("" when it did not). */
export function torchHold(s: Status): string {
  const c = s.features?.cutting;
  if (!c || s.state !== "held" || !s.job.active) return "";
  if (s.features?.retrace && s.features.retrace.phase !== "idle") return "";  // the retrace acts on it
  return c.hold_reason ?? "";
}

const kTexts: Record<string, [string, string]> = {
  "arc-lost": ["Arc lost", "The arc went out while cutting: the torch is off and the machine stands on the path."],
  failed: ["Torch start failed", "The torch could not start (no arc-OK after its retries, or no plate found): the run is held."],
  breakaway: ["Torch breakaway", "The torch's breakaway switch tripped (it hit a tipped part or the plate): the torch is off. Seat the torch first."],
  float: ["Torch touched the plate", "The float switch tripped while the torch burned: the torch is off and the machine stands on the path."],
};

registerDialog({
  id: "torch-hold",
  wants: (s) => torchHold(s) !== "",
  title: (s) => kTexts[torchHold(s)]?.[0] ?? "Torch held",
  text: (s) => {
    const [, text] = kTexts[torchHold(s)] ?? ["", "The torch stage held the run."];
    const retrace = s.features?.retrace ? " Retrace to go back along the path and pierce again before the gap," : "";
    return `${text}${retrace} resume to pierce again where the torch stands, or abort. (${s.wait_text})`.replace(" ()", "");
  },
  actions: (s) => {
    const out: DialogAction[] = [];
    if (s.features?.retrace) out.push({ label: "Retrace", kind: "feature", fields: { feature: "retrace", action: "pause" }, cls: "go" });
    out.push({ label: "Resume here", kind: "resume" }, { label: "Abort", kind: "abort", cls: "danger" });
    return out;
  },
});
