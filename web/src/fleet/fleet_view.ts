// SPDX-License-Identifier: GPL-3.0-or-later
// The fleet view's rows as the page shows them: `GET /api/v1/fleet` (connect::Fleet's JSON) turned
// into words and looks, without the DOM (tested in fleet_view.test.ts).

export interface FleetAlarm {
  item: string;
  level: 'Warning'|'Fault';
  nativeCode: string;
  message: string;
}

export interface FleetMachine {
  uuid: string;
  name: string;
  hmi: string;
  availability: string;
  execution: string;
  mode: string;
  program: string;
  line: string;
  partCount: string;
  tool: string;
  emergencyStop: string;
  feed: string;
  spindleSpeed: string;
  spindleLoad: string;
  progress: number|null;
  alarms: FleetAlarm[];
  lastSeenMs: number;
}

export interface Fleet {
  machines: FleetMachine[];
  now: number;
  malformed: number;
  broker?: {url: string; connected: boolean};
}

/** One row of the table. `look` is a CSS class: the state at a glance. */
export interface FleetRow {
  uuid: string;
  name: string;
  link: string|null;
  state: string;
  look: 'off'|'fault'|'warning'|'running'|'waiting'|'idle';
  program: string;
  progress: string;
  alarms: string;
  spindle: string;
  lastSeen: string;
}

const unknown = (v: string) => v === '' || v === 'UNAVAILABLE';

/** "just now", "12 s ago", "3 min ago", "2 h ago" from the fleet's clock. */
export function ago(then: number, now: number): string {
  if (then <= 0) return 'never';
  const s = Math.max(0, Math.round((now - then) / 1000));
  if (s < 2) return 'just now';
  if (s < 120) return `${s} s ago`;
  if (s < 7200) return `${Math.round(s / 60)} min ago`;
  return `${Math.round(s / 3600)} h ago`;
}

/** The machine's state in words, and its look. */
export function state(m: FleetMachine): Pick<FleetRow, 'state'|'look'> {
  if (m.availability !== 'AVAILABLE') return {state: 'unavailable', look: 'off'};
  if (m.emergencyStop === 'TRIGGERED') return {state: 'e-stop', look: 'fault'};
  const faults = m.alarms.filter((a) => a.level === 'Fault').length;
  const execution = unknown(m.execution) ? 'unknown' : m.execution.toLowerCase().replaceAll('_', ' ');
  if (faults > 0) return {state: execution === 'unknown' ? 'fault' : `${execution}, fault`, look: 'fault'};
  const look = m.execution === 'ACTIVE' ? 'running' :
      ['WAIT', 'FEED_HOLD', 'INTERRUPTED', 'PROGRAM_STOPPED', 'OPTIONAL_STOP'].includes(m.execution) ?
                                          'waiting' :
      m.alarms.length > 0 ? 'warning' :
                            'idle';
  return {state: execution, look};
}

/** The table's rows, by name. */
export function rows(fleet: Fleet): FleetRow[] {
  return [...fleet.machines].sort((a, b) => a.name.localeCompare(b.name)).map((m) => {
    const program =
        unknown(m.program) ? '—' : m.program.split('/').pop() + (unknown(m.line) ? '' : ` : ${m.line}`);
    const spindle = [
      unknown(m.spindleSpeed) ? '' : `${Number(m.spindleSpeed).toFixed(0)} rpm`,
      unknown(m.spindleLoad) ? '' : `${Number(m.spindleLoad).toFixed(0)} %`
    ].filter((t) => t).join(', ');
    return {
      uuid: m.uuid,
      name: m.name,
      link: m.hmi ? m.hmi : null,
      ...state(m),
      program,
      progress: m.progress === null || unknown(m.program) ? '' : `${Math.round(m.progress * 100)} %`,
      alarms: m.alarms.map((a) => `${a.level}: ${a.message || a.nativeCode}`).join('; '),
      spindle: spindle || '—',
      lastSeen: ago(m.lastSeenMs, fleet.now),
    };
  });
}

/** A line of counts for the header: "3 machines: 2 running, 1 unavailable". */
export function summary(list: FleetRow[]): string {
  const count = new Map<string, number>();
  for (const r of list) count.set(r.look, (count.get(r.look) ?? 0) + 1);
  const words: Record<FleetRow['look'], string> = {
    running: 'running',
    waiting: 'waiting',
    idle: 'idle',
    warning: 'with warnings',
    fault: 'faulted',
    off: 'unavailable',
  };
  const parts = (Object.keys(words) as FleetRow['look'][])
                    .filter((k) => count.has(k))
                    .map((k) => `${count.get(k)} ${words[k]}`);
  const n = list.length;
  return `${n} machine${n === 1 ? '' : 's'}${parts.length ? ': ' + parts.join(', ') : ''}`;
}
