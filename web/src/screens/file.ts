// SPDX-License-Identifier: GPL-3.0-or-later
// File machining: the programs folder, open (the preflight checks the program: its warnings and
// errors show here), run, hold, resume, abort, single block, optional stop, block delete, and run
// from a line (typed, or clicked in the listing).
import { registerScreen, type Context } from "../registry";
import { button, el } from "../ui";

registerScreen({
  id: "file",
  title: "Program",
  mount(root, ctx) {
    const list = el("select", { size: "8", class: "programs" });
    list.dataset.testid = "programs";
    const report = el("div", { class: "report" });
    const refresh = async () => {
      const files = await ctx.api.get<{ name: string; bytes: number }[]>("programs");
      list.replaceChildren(...files.map((f) => el("option", { value: f.name }, `${f.name}  (${f.bytes} bytes)`)));
    };
    const open = async () => {
      const program = list.value;
      if (!program) return ctx.message("choose a program first", "warning");
      if (ctx.status()?.mode !== "auto" && !(await ctx.send("mode", { mode: "auto" }))) return;
      const o = await ctx.api.command("open", { program });
      report.replaceChildren(
        el("p", {}, o.accepted ? `${program}: checked, ready to run` : `${program}: ${o.message ?? o.error}`),
        ...(o.diagnostics ?? []).map((d) => el("p", { class: d.severity }, d.text)),
      );
      if (o.accepted) document.dispatchEvent(new CustomEvent("program-opened"));
    };
    const sw = (which: string, label: string) => {
      const box = el("input", { type: "checkbox" });
      box.addEventListener("change", () => void ctx.send("switch", { which, on: box.checked }));
      return el("label", {}, box, label);
    };
    const b = (label: string, kind: string, id: string, cls = "") => {
      const x = button(label, () => void ctx.send(kind), cls);
      x.dataset.testid = id;
      return x;
    };
    const lineInput = el("input", { type: "number", min: "1", step: "1", class: "line" });
    lineInput.dataset.testid = "from-line";
    document.addEventListener("line-chosen", (e) => {
      lineInput.value = String((e as CustomEvent<number>).detail);
    });
    const runFromLine = async () => {
      const line = Number(lineInput.value);
      if (!Number.isInteger(line) || line < 1) return ctx.message("give the line to start at (1 or more)", "warning");
      const o = await ctx.api.command("run-from-line", { line });
      report.replaceChildren(el("p", { class: o.accepted ? "note" : "error" }, `run from line ${line}: ${o.message ?? o.error ?? ""}`));
      if (!o.accepted) ctx.message(`run from line ${line}: ${o.message ?? o.error}`, "warning");
    };
    const fromButton = button("Run from line", () => void runFromLine(), "go");
    fromButton.dataset.testid = "run-from-line";
    const openButton = button("Open and check", () => void open(), "go");
    openButton.dataset.testid = "open";
    root.append(
      el("h2", {}, "File machining"),
      el("div", { class: "row" }, list, el("div", {}, openButton, button("Refresh", () => void refresh()))),
      report,
      el("div", { class: "row" }, b("Cycle start", "cycle-start", "cycle-start", "go"), b("Feed hold", "feed-hold", "feed-hold"),
        b("Resume", "resume", "resume"), b("Abort", "abort", "abort", "danger")),
      el("div", { class: "row" }, sw("single-block", "single block"), sw("optional-stop", "optional stop (M1)"),
        sw("block-delete", "block delete (/)")),
      el("div", { class: "row" }, el("span", { class: "label" }, "Line"), lineInput, fromButton,
        el("span", { class: "hint" }, "click a line of the listing to choose it; the machine goes there (up, across, down), then runs on")),
    );
    void refresh().catch((e) => ctx.message(String(e), "error"));
  },
  shown(ctx: Context) {
    void ctx;
  },
});
