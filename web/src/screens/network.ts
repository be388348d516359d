// SPDX-License-Identifier: GPL-3.0-or-later
// Network settings: where the server listens, who may reach it, the stream's rate and clients.
import { registerScreen } from "../registry";
import { el } from "../ui";

registerScreen({
  id: "network",
  title: "Network",
  mount(root) {
    root.append(el("h2", {}, "Network"), el("dl", { id: "network" }));
  },
  shown(ctx) {
    void ctx.api.get<Record<string, unknown>>("server").then((s) => {
      const dl = document.getElementById("network");
      if (!dl) return;
      dl.replaceChildren(...Object.entries(s).flatMap(([k, v]) => [el("dt", {}, k), el("dd", {}, String(v))]));
      dl.append(el("dt", {}, "note"), el("dd", {}, "The address is set at start: opencnc serve --listen ADDRESS:PORT (any other address than loopback needs a token for every call)."));
    });
  },
});
