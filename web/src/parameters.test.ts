// SPDX-License-Identifier: GPL-3.0-or-later
// The machine-parameters screen's logic: which values a change sends, and the answer in words.
import { describe, expect, it } from "vitest";
import { changedValues, outcomeLines, type Parameter } from "./screens/parameters";

const params: Parameter[] = [
  { key: "axis.x.max_velocity", value: 100, unit: "mm/s", what: "" },
  { key: "axis.x.min_limit", value: -2000, unit: "mm", what: "" },
];

describe("machine parameters", () => {
  it("sends only the values that changed, as numbers", () => {
    expect(changedValues(params, { "axis.x.max_velocity": "80", "axis.x.min_limit": "-2000" })).toEqual({
      "axis.x.max_velocity": 80,
    });
    expect(changedValues(params, { "axis.x.max_velocity": "100", "axis.x.min_limit": "-2000.0" })).toEqual({});
  });
  it("refuses an empty field or text before anything is sent", () => {
    expect(changedValues(params, { "axis.x.max_velocity": "", "axis.x.min_limit": "0" })).toBe(
      "axis.x.max_velocity: a value is needed",
    );
    expect(changedValues(params, { "axis.x.max_velocity": "fast", "axis.x.min_limit": "0" })).toBe(
      'axis.x.max_velocity: "fast" is not a number',
    );
  });
  it("shows the refusal with the profile's file:line:col messages", () => {
    const lines = outcomeLines({
      message: "the profile refuses the change: m.toml:24:20: error: max_velocity must be > 0",
      diagnostics: [
        { severity: "error", text: "m.toml:24:20: error: max_velocity must be > 0", code: "config.range" },
        { severity: "warning", text: "m.toml:30:1: warning: the drive cannot reach it", code: "config.plausible" },
      ],
    });
    expect(lines).toEqual([
      "the profile refuses the change: m.toml:24:20: error: max_velocity must be > 0",
      "m.toml:30:1: warning: the drive cannot reach it",
    ]);
    expect(outcomeLines({ error: "this command needs the admin token" })).toEqual(["this command needs the admin token"]);
  });
});
