// SPDX-License-Identifier: GPL-3.0-or-later
import {describe, expect, it} from 'vitest';
import {ago, rows, state, summary, type Fleet, type FleetMachine} from './fleet_view';

const base: FleetMachine = {
  uuid: 'opencnc-mill-1',
  name: 'mill-1',
  hmi: 'http://10.0.0.5:8080/',
  availability: 'AVAILABLE',
  execution: 'ACTIVE',
  mode: 'AUTOMATIC',
  program: '/shop/parts/bracket.ngc',
  line: '42',
  partCount: '3',
  tool: '2',
  emergencyStop: 'ARMED',
  feed: '20.000',
  spindleSpeed: '1200.0',
  spindleLoad: 'UNAVAILABLE',
  progress: 0.426,
  alarms: [],
  lastSeenMs: 99_000,
};

describe('the fleet view', () => {
  it('says how long ago a machine was heard from', () => {
    expect(ago(0, 5000)).toBe('never');
    expect(ago(99_000, 100_000)).toBe('just now');
    expect(ago(40_000, 100_000)).toBe('60 s ago');
    expect(ago(0 + 1, 600_001)).toBe('10 min ago');
    expect(ago(1, 3 * 3600_000 + 1)).toBe('3 h ago');
  });

  it('puts the state first: unavailable, e-stop and faults before the execution', () => {
    expect(state(base)).toEqual({state: 'active', look: 'running'});
    expect(state({...base, availability: 'UNAVAILABLE'})).toEqual({state: 'unavailable', look: 'off'});
    expect(state({...base, emergencyStop: 'TRIGGERED'})).toEqual({state: 'e-stop', look: 'fault'});
    const fault =
        {item: 'system', level: 'Fault' as const, nativeCode: 'control.fault.x', message: 'X stalled'};
    expect(state({...base, execution: 'STOPPED', alarms: [fault]}))
        .toEqual({state: 'stopped, fault', look: 'fault'});
    expect(state({...base, execution: 'FEED_HOLD'})).toEqual({state: 'feed hold', look: 'waiting'});
    const warning = {item: 'system', level: 'Warning' as const, nativeCode: 'power.on-battery', message: ''};
    expect(state({...base, execution: 'READY', alarms: [warning]}))
        .toEqual({state: 'ready', look: 'warning'});
  });

  it('makes rows by name with the program, its progress, the alarms and a link to the HMI', () => {
    const fleet: Fleet = {
      now: 100_000,
      malformed: 0,
      machines: [
        {
          ...base,
          uuid: 'opencnc-mill-2',
          name: 'mill-2',
          hmi: '',
          program: 'UNAVAILABLE',
          progress: 0,
          alarms: [{
            item: 'x_travel',
            level: 'Fault',
            nativeCode: 'control.fault.soft-limit',
            message: 'X beyond its soft limit'
          }]
        },
        base,
      ],
    };
    const r = rows(fleet);
    expect(r.map((x) => x.name)).toEqual(['mill-1', 'mill-2']);
    expect(r[0]).toMatchObject({
      link: 'http://10.0.0.5:8080/',
      program: 'bracket.ngc : 42',
      progress: '43 %',
      spindle: '1200 rpm',
      lastSeen: 'just now',
      alarms: ''
    });
    expect(r[1]).toMatchObject(
        {link: null, program: '—', progress: '', alarms: 'Fault: X beyond its soft limit', look: 'fault'});
    expect(summary(r)).toBe('2 machines: 1 running, 1 faulted');
    expect(summary([])).toBe('0 machines');
  });
});
