// SPDX-License-Identifier: GPL-3.0-or-later
// Machining history: each job with its program, start, end, outcome, machining time and alarms.
import { registerScreen, type Context } from "../registry";
import { button, el } from "../ui";

interface Job {
  id: number;
  program: string;
  started: string;
  ended: string;
  outcome: string;
  machining_s: number;
  end_line: number;
  alarms: string[];
}

let body: HTMLElement | undefined;

async function load(ctx: Context) {
  if (!body) return;
  const jobs = await ctx.api.get<Job[]>("history?limit=100");
  body.replaceChildren(
    ...jobs.map((j) =>
      el("tr", { class: j.outcome },
        el("td", {}, `${j.id}`), el("td", {}, j.program.split("/").pop() ?? j.program), el("td", {}, j.started),
        el("td", {}, j.ended), el("td", {}, j.outcome), el("td", {}, j.machining_s.toFixed(1)), el("td", {}, j.end_line ? `${j.end_line}` : "—"),
        el("td", {}, j.alarms.join("; "))),
    ),
  );
}

registerScreen({
  id: "history",
  title: "History",
  mount(root, ctx) {
    body = el("tbody");
    body.dataset.testid = "history";
    const head = el("tr", {}, ...["#", "program", "started (UTC)", "ended (UTC)", "outcome", "machining [s]", "last line", "alarms"].map((h) => el("th", {}, h)));
    root.append(el("h2", {}, "Machining history"), button("Refresh", () => void load(ctx)), el("table", { class: "grid" }, el("thead", {}, head), body));
  },
  shown: (ctx) => void load(ctx),
});
