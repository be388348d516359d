// SPDX-License-Identifier: GPL-3.0-or-later
// The Parameters screen: the machine parameters (parameters.ts: the admin changes them) and the
// tool data, which the admin may change (the server checks the range; the table file is written back).
import { registerScreen, type Context } from "../registry";
import { button, el } from "../ui";
import { ParametersPanel } from "./parameters";

interface Tool {
  tool: number;
  pocket: number;
  diameter: number;
  z_offset: number;
  comment: string;
}

let tools: HTMLElement | undefined;
let parameters: ParametersPanel | undefined;

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
    tools = el("tbody");
    parameters = new ParametersPanel(ctx);
    root.append(
      el("h2", {}, `Machine: ${m.name}`),
      el("p", {}, m.description),
      el("p", { class: "hint" }, `Servo period ${m.servo_period_s * 1000} ms; spindle up to ${m.spindle_max_rpm} rpm.`),
      el("div", { class: "row" }, "Admin token: ", el("input", { id: "admin-token", type: "password", class: "token" })),
    );
    parameters.mount(root);
    root.append(
      el("h2", {}, "Tool data"),
      el("table", { class: "grid" }, el("thead", {}, el("tr", {}, ...["tool", "pocket", "diameter", "Z offset", "comment", ""].map((h) => el("th", {}, h)))), tools),
    );
  },
  shown: (ctx) => {
    void parameters?.load();
    void loadTools(ctx);
  },
});
