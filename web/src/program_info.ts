// SPDX-License-Identifier: GPL-3.0-or-later
// What the page knows of the open program beyond the status (from its preview): the tools it puts
// in the spindle, for the tool check dialog's order. Set by main.ts when the preview loads.

/** The open program's tools (M6 after a T, M61), in number order; empty while unknown. */
export const programInfo: { name: string; tools: number[] } = { name: "", tools: [] };
