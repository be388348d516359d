// SPDX-License-Identifier: GPL-3.0-or-later
// The server's API for the screens: queries, commands (with the answer), and the status stream
// with its events, reconnecting when the connection drops.
import type { ControllerEvent, Outcome, Status } from "./types";

export class Api {
  constructor(readonly token: string) {}

  private headers(): HeadersInit {
    return { Authorization: `Bearer ${this.token}`, "Content-Type": "application/json" };
  }

  /** GET a query; throws with the server's message on an error status. */
  async get<T>(path: string): Promise<T> {
    const res = await fetch(`/api/v1/${path}`, { headers: this.headers() });
    const body = await res.json();
    if (!res.ok) throw new Error(body.error ?? `${res.status}`);
    return body as T;
  }

  /** POSTs a command; resolves with the answer (accepted or the refusal's message). */
  async command(kind: string, fields: Record<string, unknown> = {}): Promise<Outcome & { status: number }> {
    const res = await fetch("/api/v1/commands", {
      method: "POST",
      headers: this.headers(),
      body: JSON.stringify({ kind, ...fields }),
    });
    const body = (await res.json()) as Outcome;
    return { ...body, status: res.status };
  }

  /** Follows /api/v1/stream: status at the server's rate, events as they come. */
  stream(onStatus: (s: Status) => void, onEvents: (e: ControllerEvent[]) => void, onLink: (up: boolean) => void) {
    // A browser cannot give a WebSocket headers: a single-use ticket, asked for with the token in
    // the header, opens the stream, so the token never travels in a URL.
    const open = async () => {
      let ticket = "";
      try {
        const res = await fetch("/api/v1/stream-ticket", { method: "POST", headers: this.headers() });
        if (res.ok) ticket = ((await res.json()) as { ticket: string }).ticket;
      } catch {
        /* the server is away: try again below */
      }
      if (!ticket) {
        onLink(false);
        setTimeout(() => void open(), 1000);
        return;
      }
      const proto = location.protocol === "https:" ? "wss" : "ws";
      const ws = new WebSocket(`${proto}://${location.host}/api/v1/stream?ticket=${encodeURIComponent(ticket)}`);
      ws.onopen = () => onLink(true);
      ws.onmessage = (m) => {
        const msg = JSON.parse(m.data as string);
        if (msg.type === "status") onStatus(msg.status as Status);
        else if (msg.type === "events") onEvents(msg.events as ControllerEvent[]);
      };
      ws.onclose = () => {
        onLink(false);
        setTimeout(() => void open(), 1000);
      };
    };
    void open();
  }
}
