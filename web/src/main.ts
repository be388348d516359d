// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI's main screen (the seed controller's layout): the information display (positions,
// program with its current line, state, alarms), the process parameters with their adjustment,
// the 3D view, and the function keys to the sub-screens; the dialogs over it.
import "./style.css";
import { Api } from "./api";
import { renderDialog } from "./dialog_view";
// The feature dialogs first: the first registered dialog a status wants is shown.
import "./dialogs/recovery";
import "./dialogs/toolcheck";
import "./dialogs/torch_hold";
import { dialogFor } from "./dialogs/waits";
import "./panels/process";
import "./panels/retrace";
import "./panels/cutting";
import { programInfo } from "./program_info";
import { panels, screens, type Context } from "./registry";
import "./screens/jog";
import "./screens/mdi";
import "./screens/file";
import "./screens/history";
import "./screens/params";
import "./screens/network";
import "./screens/electrode";
import "./screens/compensation";
import "./screens/conditions";
import "./screens/cut_charts";
import type { ControllerEvent, Machine, Status } from "./types";
import { button, coord, el, offsetsText, outsideWindow, percent, topBarLooks, windowStart } from "./ui";
import { View3d, type Preview } from "./view3d";

function token(): string {
  const m = /token=([^&]+)/.exec(location.hash);
  if (m) {
    sessionStorage.setItem("opencnc-token", decodeURIComponent(m[1]));
    history.replaceState(null, "", location.pathname);
  }
  return sessionStorage.getItem("opencnc-token") ?? "";
}

function login(app: HTMLElement) {
  const input = el("input", { type: "password", placeholder: "operator token", class: "token" });
  app.replaceChildren(el("div", { class: "login" }, el("h1", {}, "opencnc"), el("p", {}, "The token is printed by opencnc serve."), input,
    button("Sign in", () => {
      sessionStorage.setItem("opencnc-token", input.value.trim());
      location.reload();
    }, "go")));
}

async function start() {
  const app = document.getElementById("app")!;
  const api = new Api(token());
  let machine: Machine;
  try {
    machine = await api.get<Machine>("machine");
  } catch {
    return login(app);
  }
  let status: Status | undefined;
  const messages = el("ul", { class: "messages" });
  messages.dataset.testid = "messages";
  const message = (text: string, severity: "note" | "warning" | "error" = "note") => {
    messages.prepend(el("li", { class: severity }, `${new Date().toLocaleTimeString()} ${text}`));
    while (messages.children.length > 200) messages.lastChild?.remove();
  };
  const ctx: Context = {
    api,
    machine,
    status: () => status,
    async send(kind, fields = {}) {
      const o = await api.command(kind, fields);
      if (o.status >= 300) message(`${kind}: ${o.message || o.error || o.code}`, "error");
      for (const d of o.diagnostics ?? []) message(d.text, d.severity === "error" ? "error" : "warning");
      return o.status < 300;
    },
    message,
  };

  // Top bar: state, mode, machine power.
  const state = el("span", { class: "state" });
  state.dataset.testid = "state";
  const mode = el("span", { class: "mode" });
  const link = el("span", { class: "link" }, "…");
  // The power and mode buttons show the state they are in (topBarLooks).
  const topButtons: Record<string, HTMLButtonElement> = {
    estop: button("E-STOP", () => void ctx.send("estop"), "estop"),
    reset: button("Reset", () => void ctx.send("reset")),
    "machine-on": Object.assign(button("Machine on", () => void ctx.send("machine-on"), "go"), { id: "machine-on" }),
    "machine-off": button("Machine off", () => void ctx.send("machine-off")),
  };
  for (const m of ["manual", "mdi", "auto"]) topButtons[m] = button(m.toUpperCase(), () => void ctx.send("mode", { mode: m }));
  for (const [k, b] of Object.entries(topButtons)) b.dataset.testid = `top-${k}`;
  const top = el("header", {},
    el("strong", {}, `opencnc · ${machine.name}`), state, mode, link, ...Object.values(topButtons));

  // Information display: the DRO.
  const dro = el("tbody");
  const cells: Record<string, HTMLElement[]> = {};
  for (const a of machine.axes) {
    const c = [el("td", { class: "pos" }), el("td", {}), el("td", {}), el("td", {}), el("td", {})];
    c[0].dataset.testid = `work-${a.axis}`;
    c[1].dataset.testid = `pos-${a.axis}`;
    c[2].dataset.testid = `togo-${a.axis}`;
    cells[a.axis] = c;
    dro.append(el("tr", {}, el("th", {}, a.axis), ...c));
  }
  const workHead = el("th", {}, "work");
  const droTable = el("table", { class: "dro" },
    el("thead", {}, el("tr", {}, el("th", {}), workHead, ...["machine", "to go", "following error", "homed"].map((h) => el("th", {}, h)))), dro);

  // The program with its current line.
  const progName = el("div", { class: "progname" });
  const progress = el("progress", { max: "1", value: "0" });
  const listing = el("ol", { class: "listing" });
  let listingOf = "";
  // A window of the program around the current line (a program may have millions of lines).
  const kWindow = 2000;
  let windowFrom = 1, windowLines = 0, windowMore = false, windowWanted = 0;
  const loadListing = async (around = 1) => {
    const from = windowStart(around, kWindow);
    windowWanted = from;
    try {
      const t = await api.get<{ from: number; lines: string[]; more: boolean }>(`program/text?from=${from}&count=${kWindow}`);
      if (windowWanted !== from) return;  // a newer window was asked for meanwhile
      windowFrom = t.from;
      windowLines = t.lines.length;
      windowMore = t.more;
      listing.start = t.from;
      listing.replaceChildren(...t.lines.map((l, i) => {
        const li = el("li", {}, l || " ");
        li.addEventListener("click", () => document.dispatchEvent(new CustomEvent("line-chosen", { detail: t.from + i })));
        return li;
      }));
    } catch {
      listing.replaceChildren();
      windowFrom = from;
      windowLines = 0;
    }
  };

  // Process parameters: overrides with their adjustment, spindle, tool, coolant.
  const override = (which: string, label: string, max: number) => {
    const slider = el("input", { type: "range", min: "0", max: `${max * 100}`, value: "100", step: "5" });
    const value = el("span", {}, "100 %");
    slider.addEventListener("change", () => void ctx.send("override", { which, value: Number(slider.value) / 100 }));
    const nudge = (d: number) => button(d > 0 ? "+" : "−", () => {
      const v = Math.min(max, Math.max(0, (status ? (status as unknown as Record<string, number>)[`${which}_override`] : 1) + d));
      void ctx.send("override", { which, value: Math.round(v * 100) / 100 });
    });
    return { row: el("div", { class: "row" }, el("span", { class: "label" }, label), nudge(-0.1), slider, nudge(0.1), value), slider, value };
  };
  const feed = override("feed", "Feed", 2), spindle = override("spindle", "Spindle", 2), rapid = override("rapid", "Rapid", 1);
  const process = el("div", { class: "process" });
  const panelRoots = panels.map((p) => {
    const root = el("div", { class: `panel ${p.id}` });
    root.dataset.testid = `panel-${p.id}`;
    root.hidden = true;
    p.mount(root, ctx);
    return root;
  });

  // The 3D view and the sub-screens behind the function keys.
  const view = el("div", { class: "view3d" });
  const sub = el("section", { class: "sub" });
  const keys = el("nav", { class: "fkeys" });
  const roots = new Map<string, HTMLElement>();
  let shownId = "";
  const show = (id: string) => {
    shownId = id;
    for (const [k, r] of roots) r.hidden = k !== id;
    keys.querySelectorAll("button").forEach((b) => b.classList.toggle("on", b.dataset.screen === id));
    screens.find((s) => s.id === id)?.shown?.(ctx);
  };
  screens.forEach((s, i) => {
    const root = el("div", {});
    root.dataset.screenRoot = s.id;
    root.hidden = true;
    s.mount(root, ctx);
    roots.set(s.id, root);
    sub.append(root);
    const key = button(`F${i + 1} ${s.title}`, () => show(s.id));
    key.dataset.screen = s.id;
    key.dataset.testid = `key-${s.id}`;
    keys.append(key);
  });

  const dialog = el("dialog", { class: "prompt" });
  dialog.dataset.testid = "dialog";
  let dialogKey = "";

  app.replaceChildren(top,
    el("main", {},
      el("div", { class: "info" }, droTable, progName, progress, listing),
      el("div", { class: "center" }, view),
      el("div", { class: "params" }, el("h3", {}, "Process"), feed.row, spindle.row, rapid.row, process, ...panelRoots, el("h3", {}, "Alarms and messages"), messages)),
    keys, sub, dialog);
  const v3 = new View3d(view);
  v3.setMachine(machine);
  const loadPreview = async () => {
    try {
      const p = await api.get<Preview>("program/preview");
      programInfo.tools = p.tools ?? [];
      v3.setPreview(p);
    } catch {
      /* no program open */
    }
  };
  document.addEventListener("program-opened", () => void loadPreview());
  // The soft limits changed (an admin's parameter change, from any page): the box follows.
  let limitsSeen = -1;
  const followLimits = async (version: number) => {
    const first = limitsSeen < 0;
    limitsSeen = version;
    if (first) return;
    Object.assign(machine, await api.get<Machine>("machine"));
    v3.setMachine(machine);
  };
  show(screens[0].id);

  const render = (s: Status) => {
    status = s;
    state.textContent = s.state + (s.wait_text ? ` — waiting for ${s.wait_text}` : "");
    state.className = `state ${s.state}`;
    mode.textContent = s.mode.toUpperCase();
    for (const [k, look] of Object.entries(topBarLooks(s.state, s.mode))) {
      const b = topButtons[k];
      if (k !== "estop") b.disabled = look.disabled;  // the e-stop is never disabled
      b.classList.toggle("on", look.on);
      b.setAttribute("aria-pressed", String(look.on));
      b.title = look.title;
    }
    for (const a of machine.axes) {
      const c = cells[a.axis];
      c[0].textContent = coord(s.work[a.axis]);
      c[1].textContent = coord(s.machine[a.axis]);
      c[2].textContent = coord(s.distance_to_go[a.axis]);
      const fe = s.following_error[a.axis] ?? 0;
      c[3].textContent = (Math.abs(fe) < 0.00005 ? 0 : fe).toFixed(4);
      c[4].textContent = s.homed[a.axis] ? "●" : "○";
    }
    workHead.textContent = `work ${s.offsets.system}`;
    workHead.title = offsetsText(s.offsets, machine.axes.map((a) => a.axis));
    progName.textContent = s.program.name ? `${s.program.name.split("/").pop()} — ${s.program.moves} moves, ${s.program.length_mm.toFixed(1)} mm` : "no program open";
    progress.value = s.job.progress;
    if (typeof s.limits_version === "number" && s.limits_version !== limitsSeen) void followLimits(s.limits_version);
    if (s.program.name !== listingOf) {
      listingOf = s.program.name;
      programInfo.tools = [];
      void loadListing();
      void loadPreview();
    }
    const line = s.job.active ? s.job.location.line : 0;
    if (outsideWindow(line, windowFrom, windowLines, windowMore) && windowWanted === windowFrom) void loadListing(line);
    listing.querySelectorAll("li.current").forEach((li) => li.classList.remove("current"));
    if (line > 0 && listing.children[line - windowFrom]) {
      const li = listing.children[line - windowFrom] as HTMLElement;
      li.classList.add("current");
      li.scrollIntoView({ block: "nearest" });
    }
    feed.value.textContent = percent(s.feed_override);
    spindle.value.textContent = percent(s.spindle_override);
    rapid.value.textContent = percent(s.rapid_override);
    const torque = s.spindle.torque_nm === null ? "" : ` ${s.spindle.torque_nm.toFixed(1)} N·m`;
    process.textContent = `Spindle ${s.spindle.direction} ${Math.round(s.spindle.rpm_actual)} rpm${torque} · ` +
      `tool T${s.tool} · ${s.flood ? "flood " : ""}${s.mist ? "mist" : ""} · feed ${(s.path_velocity * 60).toFixed(0)} mm/min`;
    panels.forEach((p, i) => (panelRoots[i].hidden = !p.update(s, panelRoots[i], ctx)));
    v3.setTool(s.machine.X ?? 0, s.machine.Y ?? 0, s.machine.Z ?? 0, s.job.active && s.job.kind === "program");
    const d = dialogFor(s);
    // Drawn again when what it says or offers changes (not at every status: its inputs keep their values).
    const key = d ? `${d.id}|${d.text(s)}|${d.more?.(s)?.text ?? ""}|${d.actions(s).map((a) => a.label).join(",")}` : "";
    if (key !== dialogKey) {
      dialogKey = key;
      if (!d) {
        dialog.close();
      } else {
        renderDialog(dialog, d, s, (kind, fields) => ctx.send(kind, fields));
        if (!dialog.open) dialog.showModal();
      }
    }
    // A screen whose feature the machine lacks has no key.
    for (const sc of screens) {
      if (sc.requires) (keys.querySelector(`[data-screen="${sc.id}"]`) as HTMLElement).hidden = !s.features?.installed.includes(sc.requires);
    }
    screens.find((x) => x.id === shownId)?.update?.(s, ctx);
  };
  const onEvents = (events: ControllerEvent[]) => {
    for (const e of events) {
      if (e.kind === "note" || (e.kind === "servo" && e.severity !== "note")) message(e.text, e.severity as "note");
      if (e.kind === "job-ended") message(e.text, e.end === "finished" ? "note" : "warning");
      if (e.kind === "job-started") v3.clearTrail();
    }
  };
  api.stream(render, onEvents, (up) => {
    link.textContent = up ? "● linked" : "○ no link";
    link.className = up ? "link up" : "link down";
  });
}

void start();
