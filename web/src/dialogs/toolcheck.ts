// SPDX-License-Identifier: GPL-3.0-or-later
// The tool check dialog: the tool guard holds the program at a tool change because the live
// tool data differ from the backup. It lists the differences; the operator checks again (after
// correcting the table), accepts the live values as the new backup, or restores the backup's —
// both confirmed, nothing is overwritten silently (docs/tool-guard.md).
import { registerDialog } from "../registry";
import type { Status } from "../types";

/** The guard's check while it holds, if any. */
function check(s: Status) {
  return s.features?.tool_guard?.holding ? s.features.tool_guard.check : undefined;
}

/** The dialog's text: where the program stands, the differences, the choices. */
export function toolCheckText(s: Status): string {
  const c = check(s);
  if (!c) return "";
  if (c.error) return `The tool store cannot be read: ${c.error}. The program stays held.`;
  const lines = c.differences.length ? c.differences.join("\n") : "(the held tool's edges differ; check again)";
  const backup = c.backup ? `backup ${c.backup.id} of ${c.backup.taken}` : "no backup";
  return `The program stands at the tool change: the live tool data differ from ${backup}:\n${lines}\n` +
    "Correct the table and check again, accept the live values as the new backup, or restore the backup's values.";
}

registerDialog({
  id: "tool-check",
  wants: (s) => check(s) !== undefined && check(s) !== null,
  title: () => "Tool data differ from the backup",
  text: toolCheckText,
  actions: (s) => [
    { label: "Check again", kind: "feature", fields: { feature: "tool-guard", action: "check" } },
    { label: "Accept live values", kind: "feature", fields: { feature: "tool-guard", action: "accept" },
      confirm: "Make the live values the new backup? The program then goes on with them." },
    { label: "Restore backup", kind: "feature", fields: { feature: "tool-guard", action: "restore" },
      confirm: `Overwrite the live values with backup ${check(s)?.backup?.id ?? ""}'s? The program then goes on with those.`, cls: "go" },
    { label: "Abort", kind: "abort", cls: "danger" },
  ],
});
