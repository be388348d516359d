// SPDX-License-Identifier: GPL-3.0-or-later
// The shapes of the server's JSON (docs/api.md).
import type { Alarm, Edm, Features, Load, Power } from "./types_features";

export type Axes = Record<string, number>;

export interface Location {
  file: string;
  line: number;
  calls: string[];
}

/** The offsets of the move at the commanded position. */
export interface Offsets {
  system: string;
  g5x: Axes;
  g92: Axes;
  tool: Axes;
  xy_rotation_deg: number;
}

export interface Status {
  tick: number;
  time_s: number;
  state: string;
  mode: string;
  activity: string;
  wait: string;
  stop_reason: string;
  wait_text: string;
  machine: Axes;
  commanded: Axes;
  /** machine − offsets (docs/api.md) */
  work: Axes;
  distance_to_go: Axes;
  offsets: Offsets;
  following_error: Axes;
  homed: Record<string, boolean>;
  all_homed: boolean;
  /** The seeks of limit switches: the phase while one runs, and what the last one found. */
  seek: Record<string, LimitSeek>;
  path_velocity: number;
  feed_override: number;
  rapid_override: number;
  spindle_override: number;
  single_block: boolean;
  optional_stop: boolean;
  /** torque_nm: the drive's torque, null where the drive reports none. */
  spindle: {rpm: number; rpm_actual: number; at_speed: boolean; torque_nm: number | null; direction: string};
  flood: boolean;
  mist: boolean;
  tool: number;
  prepared_tool: number;
  fault: string;
  program: { name: string; moves: number; length_mm: number };
  job: {
    kind: string;
    id: number;
    name: string;
    active: boolean;
    segment: number;
    progress: number;
    location: Location;
    interpreter: Location;
  };
  sync_wait: string;
  runs_finished: number;
  /** Counts the machine parameters' changes: the soft-limit box is read again when it changes. */
  limits_version: number;
  /** The process side and the features (types_features.ts); each present when the machine has it. */
  power?: Power;
  load?: Load;
  alarms?: Alarm[];
  edm?: Edm;
  features?: Features;
}

export interface ControllerEvent {
  seq: number;
  tick: number;
  kind: string;
  severity: string;
  code: string;
  text: string;
  accepted?: boolean;
  end?: string;
}

export interface LimitSeek {
  phase: string;
  direction: "+" | "-";
  found: boolean;
  tripped_at: number;
  rest_at: number;
}

export interface MachineAxis {
  axis: string;
  rotary: boolean;
  manual: boolean;
  min_limit: number;
  max_limit: number;
  max_velocity: number;
  homing: boolean;
  /** The limit switches the axis can seek ("-", "+"). */
  seek: string[];
}

export interface Machine {
  name: string;
  description: string;
  servo_period_s: number;
  axes: MachineAxis[];
  spindle_max_rpm: number;
  tool_changer: boolean;
  handwheel: number[] | null;
}

export interface Outcome {
  id?: number;
  accepted?: boolean;
  code?: string;
  message?: string;
  error?: string;
  diagnostics?: { severity: string; text: string; code: string }[];
}
