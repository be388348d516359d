// SPDX-License-Identifier: GPL-3.0-or-later
// Coordinates and jogging: continuous jogs (held with the mouse), increments, the handwheel,
// homing per axis and all, seeking an axis' limit switch (where the travel ends), and positioning
// to a point (an MDI G53 G0).
import { registerScreen, type Context } from "../registry";
import type { Status } from "../types";
import { button, el } from "../ui";

const increments = [0.001, 0.01, 0.1, 1, 10];

registerScreen({
  id: "jog",
  title: "Jog / Home",
  mount(root, ctx) {
    let step = 1;
    let speedPct = 20;
    const speedOf = (max: number) => (max * speedPct) / 100;
    const steps = el("div", { class: "row" }, "Increment: ");
    for (const inc of increments) {
      const b = button(`${inc}`, () => {
        step = inc;
        steps.querySelectorAll("button").forEach((x) => x.classList.toggle("on", x === b));
      });
      if (inc === step) b.classList.add("on");
      steps.append(b);
    }
    const speed = el("input", { type: "range", min: "1", max: "100", value: `${speedPct}` });
    const speedLabel = el("span", {}, `${speedPct} % of the axis' maximum`);
    speed.addEventListener("input", () => {
      speedPct = Number(speed.value);
      speedLabel.textContent = `${speedPct} % of the axis' maximum`;
    });
    const table = el("table", { class: "jog" });
    for (const a of ctx.machine.axes) {
      const cont = (sign: number) => {
        const b = button(sign > 0 ? `${a.axis} + (hold)` : `${a.axis} − (hold)`, () => {}, "jog");
        b.dataset.testid = `jog-${a.axis}${sign > 0 ? "+" : "-"}`;
        const stop = () => void ctx.send("jog-stop", { axis: a.axis });
        b.addEventListener("pointerdown", () => void ctx.send("jog", { axis: a.axis, velocity: sign * speedOf(a.max_velocity) }));
        b.addEventListener("pointerup", stop);
        b.addEventListener("pointerleave", (e) => {
          if ((e as PointerEvent).buttons) stop();
        });
        return b;
      };
      const inc = (sign: number) =>
        button(`${a.axis} ${sign > 0 ? "+" : "−"}step`, () =>
          void ctx.send("jog-by", { axis: a.axis, distance: sign * step, speed: speedOf(a.max_velocity) }),
        );
      const home = button(`Home ${a.axis}`, () => void ctx.send("home", { axis: a.axis }));
      const seeks = el("td", {});
      for (const side of a.seek ?? []) {
        const b = button(`${a.axis} to ${side === "+" ? "+" : "−"} limit`, () => void seekLimit(ctx, a.axis, side));
        b.dataset.testid = `seek-${a.axis}${side}`;
        seeks.append(b);
      }
      table.append(el("tr", {}, el("th", {}, a.axis), el("td", {}, cont(-1), cont(1)), el("td", {}, inc(-1), inc(1)), el("td", {}, home), seeks));
    }
    const homeAll = button("Home all", () => void homeAllAxes(ctx), "go");
    homeAll.dataset.testid = "home-all";
    const manual = button("Manual mode", () => void ctx.send("mode", { mode: "manual" }));
    const seekLine = el("div", { class: "row", "data-testid": "seek-status" });
    root.append(el("h2", {}, "Coordinates and jogging"), el("div", { class: "row" }, manual, homeAll), steps,
      el("div", { class: "row" }, "Speed: ", speed, speedLabel), table, seekLine);
    if (ctx.machine.handwheel) {
      const wheel = el("div", { class: "row" }, "Handwheel: ", button("off", () => void ctx.send("handwheel", {})));
      for (const a of ctx.machine.axes) {
        for (const s of ctx.machine.handwheel) wheel.append(button(`${a.axis} ×${s}`, () => void ctx.send("handwheel", { axis: a.axis, step: s })));
      }
      root.append(wheel);
    }
    const inputs: Record<string, HTMLInputElement> = {};
    const go = el("div", { class: "row" }, "Go to (machine coordinates): ");
    for (const a of ctx.machine.axes) {
      inputs[a.axis] = el("input", { type: "number", step: "0.001", placeholder: a.axis, class: "num" });
      go.append(inputs[a.axis]);
    }
    go.append(button("Go (rapid)", () => {
      const words = Object.entries(inputs).filter(([, i]) => i.value !== "").map(([k, i]) => `${k}${Number(i.value)}`);
      if (words.length) void positionTo(ctx, `G53 G0 ${words.join(" ")}`);
    }));
    root.append(el("h2", {}, "Positioning"), go);
  },
  update(s) {
    const line = document.querySelector('[data-testid="seek-status"]');
    if (line) line.textContent = seekText(s);
  },
});

/** The seeks of the limit switches in words: the phase of one running, else what each found. */
export function seekText(s: Status): string {
  return Object.entries(s.seek ?? {})
    .map(([axis, k]) => {
      const side = k.direction === "+" ? "+" : "−";
      if (k.phase !== "done" && k.phase !== "failed" && k.phase !== "idle") return `${axis} seeking its ${side} limit: ${k.phase}`;
      if (!k.found) return `${axis}: the ${side} limit switch was not found`;
      return `${axis} ${side} limit at ${k.tripped_at.toFixed(4)}, backed off to ${k.rest_at.toFixed(4)}`;
    })
    .join(" · ");
}

async function seekLimit(ctx: Context, axis: string, direction: string) {
  if (ctx.status()?.mode !== "manual" && !(await ctx.send("mode", { mode: "manual" }))) return;
  await ctx.send("seek-limit", { axis, direction });
}

async function homeAllAxes(ctx: Context) {
  if (ctx.status()?.mode !== "manual") await ctx.send("mode", { mode: "manual" });
  await ctx.send("home");
}

async function positionTo(ctx: Context, line: string) {
  if (ctx.status()?.mode !== "mdi" && !(await ctx.send("mode", { mode: "mdi" }))) return;
  await ctx.send("mdi", { line });
}
