// SPDX-License-Identifier: GPL-3.0-or-later
// Machine parameters (the profile's axes and limits, read-only here) and the tool data, which
// the admin may change (the server checks the range; the table file is written back).
import { registerScreen, type Context } from "../registry";
import { button, el } from "../ui";

interface Tool {
  tool: number;
  pocket: number;
  diameter: number;
  z_offset: number;
  comment: string;
}

let tools: HTMLElement | undefined;

async function loadTools(ctx: Context) {
  if (!tools) return;
  const list = await ctx.api.get<Tool[]>("tools");
  tools.replaceChildren(
    ...list.map((t) => {
      const d = el("input", { type: "number", step: "0.001", value: `${t.diameter}`, class: "num" });
      const z = el("input", { type: "number", step: "0.001", value: `${t.z_offset}`, class: "num" });
      const save = button("Save (admin)", async () => {
        const admin = (document.getElementById("admin-token") as HTMLInputElement | null)?.value ?? "";
        const res = await fetch("/api/v1/commands", {
          method: "POST",
          headers: { Authorization: `Bearer ${admin || ctx.api.token}`, "Content-Type": "application/json" },
          body: JSON.stringify({ kind: "set-tool", tool: t.tool, diameter: Number(d.value), z_offset: Number(z.value) }),
        });
        const body = await res.json();
        ctx.message(res.ok ? `T${t.tool} saved` : `T${t.tool}: ${body.error}`, res.ok ? "note" : "error");
      });
      return el("tr", {}, el("td", {}, `T${t.tool}`), el("td", {}, `${t.pocket}`), el("td", {}, d), el("td", {}, z), el("td", {}, t.comment), el("td", {}, save));
    }),
  );
}

registerScreen({
  id: "params",
  title: "Parameters",
  mount(root, ctx) {
    const m = ctx.machine;
    const axes = el("tbody");
    for (const a of m.axes) {
      axes.append(el("tr", {}, el("td", {}, a.axis), el("td", {}, `${a.min_limit}`), el("td", {}, `${a.max_limit}`), el("td", {}, `${a.max_velocity}`), el("td", {}, a.homing ? "moves" : "immediate")));
    }
    tools = el("tbody");
    root.append(
      el("h2", {}, `Machine: ${m.name}`),
      el("p", {}, m.description),
      el("table", { class: "grid" }, el("thead", {}, el("tr", {}, ...["axis", "min", "max", "max velocity", "homing"].map((h) => el("th", {}, h)))), axes),
      el("p", { class: "hint" }, `Servo period ${m.servo_period_s * 1000} ms; spindle up to ${m.spindle_max_rpm} rpm. The profile is edited in its file (opencnc profile checks it).`),
      el("h2", {}, "Tool data"),
      el("div", { class: "row" }, "Admin token: ", el("input", { id: "admin-token", type: "password", class: "token" })),
      el("table", { class: "grid" }, el("thead", {}, el("tr", {}, ...["tool", "pocket", "diameter", "Z offset", "comment", ""].map((h) => el("th", {}, h)))), tools),
    );
  },
  shown: (ctx) => void loadTools(ctx),
});
