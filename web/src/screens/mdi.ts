// SPDX-License-Identifier: GPL-3.0-or-later
// Manual machining and MDI: one line of G-code at a time (with the lines sent before), the
// spindle and the coolant by hand.
import { registerScreen } from "../registry";
import { button, el } from "../ui";

registerScreen({
  id: "mdi",
  title: "MDI / Manual",
  mount(root, ctx) {
    const line = el("input", { type: "text", class: "mdi", placeholder: "G0 X10 Y10", maxlength: "256" });
    const sent = el("ul", { class: "log" });
    const run = async () => {
      const text = line.value.trim();
      if (!text) return;
      if (ctx.status()?.mode !== "mdi" && !(await ctx.send("mode", { mode: "mdi" }))) return;
      if (await ctx.send("mdi", { line: text })) {
        sent.prepend(el("li", {}, text));
        line.value = "";
      }
    };
    line.addEventListener("keydown", (e) => {
      if (e.key === "Enter") void run();
    });
    const rpm = el("input", { type: "number", value: "3000", min: "0", max: `${ctx.machine.spindle_max_rpm}`, class: "num" });
    const manual = async () => ctx.status()?.mode === "manual" || ctx.send("mode", { mode: "manual" });
    root.append(
      el("h2", {}, "MDI"),
      el("div", { class: "row" }, line, button("Run line", () => void run(), "go")),
      sent,
      el("h2", {}, "Manual machining"),
      el("div", { class: "row" }, "Spindle rpm ", rpm,
        button("CW", async () => (await manual()) && void ctx.send("spindle-on", { rpm: Number(rpm.value), clockwise: true })),
        button("CCW", async () => (await manual()) && void ctx.send("spindle-on", { rpm: Number(rpm.value), clockwise: false })),
        button("Stop", () => void ctx.send("spindle-off"), "danger")),
      el("div", { class: "row" }, "Coolant ",
        button("Flood on", async () => (await manual()) && void ctx.send("coolant", { which: "flood", on: true })),
        button("Flood off", () => void ctx.send("coolant", { which: "flood", on: false })),
        button("Mist on", async () => (await manual()) && void ctx.send("coolant", { which: "mist", on: true })),
        button("Mist off", () => void ctx.send("coolant", { which: "mist", on: false }))),
    );
  },
});
