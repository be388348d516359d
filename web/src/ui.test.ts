// SPDX-License-Identifier: GPL-3.0-or-later
// The formats of the DRO and the overrides, and which dialog a status asks for.
import { describe, expect, it } from "vitest";
import { coord, percent } from "./ui";
import { dialogFor } from "./dialogs/waits";
import type { Status } from "./types";

describe("formats", () => {
  it("shows coordinates with a sign and three decimals, no negative zero", () => {
    expect(coord(12.34567)).toBe("+12.346");
    expect(coord(-0.0001)).toBe("+0.000");
    expect(coord(-3)).toBe("-3.000");
    expect(coord(undefined)).toBe("—");
  });
  it("shows overrides in per cent", () => {
    expect(percent(1.2)).toBe("120 %");
  });
});

describe("dialogs", () => {
  const base = { state: "running", wait: "", stop_reason: "", fault: "", job: { active: true } } as unknown as Status;
  it("asks for the tool at a manual tool change", () => {
    expect(dialogFor({ ...base, wait: "manual-tool-change" })?.id).toBe("tool-change");
  });
  it("asks to continue at M0 and M1, and after feed hold", () => {
    expect(dialogFor({ ...base, state: "stopped", stop_reason: "program-stop" })?.id).toBe("program-stop");
    expect(dialogFor({ ...base, state: "held" })?.id).toBe("feed-hold");
  });
  it("shows a fault and nothing while the program simply runs", () => {
    expect(dialogFor({ ...base, state: "faulted", fault: "following error on X" })?.id).toBe("fault");
    expect(dialogFor(base)).toBeUndefined();
  });
});
