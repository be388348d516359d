// SPDX-License-Identifier: GPL-3.0-or-later
// The process side of the status and the features' state (docs/api.md, "GET /api/v1/status").

export interface Power {
  monitor: boolean;
  mains_ok: boolean;
  on_battery: boolean;
  dc_link_v: number;
}

/** The broach's load cell and its guard. */
export interface Load {
  kn: number;
  action: string;
  hold_kn: number | null;
  retract_kn: number | null;
}

export interface Alarm {
  name: string;
  active: boolean;
  reaction: string;
  low: number | null;
  high: number | null;
  unit: string;
  /** The input as read now, in `unit`. */
  value: number;
}

/** The EDM gap servo's live values. */
export interface Edm {
  on: boolean;
  generator: boolean;
  condition: number;
  reference_v: number | null;
  gap_state: string;
  gap_voltage_v: number;
  filtered_voltage_v: number;
  path_speed_mm_s: number;
  backlog_mm: number;
  retract_limit: boolean;
  jumping: boolean;
  jump_lift_mm: number;
  jumps: number;
  orbit_radius_mm: number;
}

export interface BreakpointRecord {
  valid: boolean;
  stage: string;
  program: string;
  file: string;
  line: number;
  segment: number;
  segment_offset_mm: number;
  move_remaining_mm: number;
  actual: Record<string, number>;
  tool: number;
  spindle_rpm: number;
  coupled: boolean;
  signal_time_s: number;
  summary: string;
}

export interface JournalState {
  record: BreakpointRecord | null;
  phase: string;
  recovery_error: string;
  write_error: string;
  can_resume: boolean;
  can_retract: boolean;
  mains_ok: boolean;
  /** The resume's values from the profile, offered in the dialog (the operator may change them). */
  resume_defaults?: { tolerance_mm: number; tolerance_deg: number; run_in_mm: number; run_in_speed_mm_min: number };
}

export interface RetraceState {
  phase: string;
  retraces: number;
  last: { a: number[] | null; b: number[]; c: number[]; line: string; segment: number; distance_mm: number; candidates: number } | null;
}

/** The plasma torch (`features.cutting`, docs/cutting.md). */
export interface CuttingState {
  phase: string;
  thc: string;
  torch_on: boolean;
  arc_ok: boolean;
  sensor: boolean;
  arc_voltage_v: number;
  target_voltage_v: number;
  thc_offset_mm: number;
  correction_mm: number;
  plate_z_mm: number;
  pierces: number;
  arc_losses: number;
  /** Why the torch stage holds the run: "arc-lost", "failed" (starts or no plate), "" otherwise. */
  hold_reason?: string;
  /** "plasma" or "oxy-fuel" (absent: plasma). */
  process?: string;
  /** Oxy-fuel: the cutting oxygen output. */
  cut_oxygen?: boolean;
  /** Oxy-fuel: the preheat waits for the operator's start ("start-cut"). */
  waiting_start?: boolean;
  /** Oxy-fuel: the capacitive sensor's height (mm). */
  sensor_height_mm?: number;
  /** Oxy-fuel: this (or the last) preheat so far (s), and preheats begun. */
  preheat_s?: number;
  preheats?: number;
}

export interface ElectrodeResult {
  ok: boolean;
  code: string;
  message: string;
  tool: number;
  touches: number;
  previous: number[];
  offset: number[];
  rms_residual_mm: number;
  max_residual_mm: number;
  written: boolean;
}

export interface ElectrodeState {
  phase: string;
  last: ElectrodeResult | null;
  stopped_program: boolean;
}

export interface ToolGuardState {
  store: string;
  holding: boolean;
  /** While holding: the check of the live table against the backup. */
  check: { ok: boolean; error: string; backup: { id: number; taken: string } | null; differences: string[];
    /** The tool of each difference (the dialog lists the program's tools first). */
    difference_tools?: number[]; report: string } | null;
}

export interface Features {
  installed: string[];
  journal?: JournalState;
  retrace?: RetraceState;
  electrode?: ElectrodeState;
  tool_guard?: ToolGuardState;
  edm?: { depth_mm: number; burning: boolean };
  cutting?: CuttingState;
}
