// SPDX-License-Identifier: GPL-3.0-or-later
// The tool check dialog: the tool guard holds the program at a tool change because the live
// tool data differ from the backup. It lists the differences; the operator checks again (after
// correcting the table), accepts the live values as the new backup, or restores the backup's —
// both confirmed, nothing is overwritten silently (docs/tool-guard.md). The differences of the
// tools the open program uses come first; the others are folded below them.
import { programInfo } from "../program_info";
import { registerDialog } from "../registry";
import type { Status } from "../types";

/** The guard's check while it holds, if any. */
function check(s: Status) {
  return s.features?.tool_guard?.holding ? s.features.tool_guard.check : undefined;
}

/** The differences split: those of the tools the program uses (all of them while its tools are
 *  not known) and the rest. */
export function splitDifferences(s: Status, tools: number[] = programInfo.tools): { used: string[]; rest: string[] } {
  const c = check(s);
  if (!c) return { used: [], rest: [] };
  const of = c.difference_tools;
  if (!tools.length || !of || of.length !== c.differences.length) return { used: c.differences, rest: [] };
  const used: string[] = [], rest: string[] = [];
  c.differences.forEach((d, i) => (tools.includes(of[i]) ? used : rest).push(d));
  return { used, rest };
}

/** The dialog's text: where the program stands, the differences of the program's tools, the choices. */
export function toolCheckText(s: Status, tools: number[] = programInfo.tools): string {
  const c = check(s);
  if (!c) return "";
  if (c.error) return `The tool store cannot be read: ${c.error}. The program stays held.`;
  const { used, rest } = splitDifferences(s, tools);
  const lines = used.length ? used.join("\n")
    : rest.length ? "(none of the program's tools; the others differ, below)" : "(the held tool's edges differ; check again)";
  const backup = c.backup ? `backup ${c.backup.id} of ${c.backup.taken}` : "no backup";
  const whose = rest.length ? ` in the program's tools (${tools.map((t) => `T${t}`).join(" ")})` : "";
  return `The program stands at the tool change: the live tool data differ from ${backup}${whose}:\n${lines}\n` +
    "Correct the table and check again, accept the live values as the new backup, or restore the backup's values.";
}

/** The other tools' differences, folded (accept and restore act on the whole table). */
export function toolCheckMore(s: Status, tools: number[] = programInfo.tools): { summary: string; text: string } | undefined {
  const { rest } = splitDifferences(s, tools);
  if (!rest.length) return undefined;
  return { summary: `${rest.length} more difference${rest.length > 1 ? "s" : ""} in tools the program does not use`, text: rest.join("\n") };
}

registerDialog({
  id: "tool-check",
  wants: (s) => check(s) !== undefined && check(s) !== null,
  title: () => "Tool data differ from the backup",
  text: (s) => toolCheckText(s),
  more: (s) => toolCheckMore(s),
  actions: (s) => [
    { label: "Check again", kind: "feature", fields: { feature: "tool-guard", action: "check" } },
    { label: "Accept live values", kind: "feature", fields: { feature: "tool-guard", action: "accept" },
      confirm: "Make the live values the new backup? The program then goes on with them." },
    { label: "Restore backup", kind: "feature", fields: { feature: "tool-guard", action: "restore" },
      confirm: `Overwrite the live values with backup ${check(s)?.backup?.id ?? ""}'s? The program then goes on with those.`, cls: "go" },
    { label: "Abort", kind: "abort", cls: "danger" },
  ],
});
