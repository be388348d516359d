// SPDX-License-Identifier: GPL-3.0-or-later
// The fleet view's page: the table of machines, asked of `opencnc fleet` every second; a machine's
// name opens its own HMI in a new tab.
import '../style.css';
import './fleet.css';

import {el} from '../ui';

import {rows, summary, type Fleet} from './fleet_view';

const root = document.getElementById('fleet')!;
const heading = el('h1', {}, 'Fleet');
const broker = el('span', {class: 'broker', 'data-testid': 'broker'});
const counts = el('span', {class: 'counts', 'data-testid': 'summary'});
const body = el('tbody');
const table =
    el('table', {class: 'fleet'},
       el('thead', {},
          el('tr', {},
             ...['Machine', 'State', 'Program', 'Progress', 'Alarms', 'Spindle', 'Last seen'].map(
                 (h) => el('th', {}, h)))),
       body);
root.replaceChildren(el('header', {}, heading, counts, broker), table);

function render(fleet: Fleet) {
  const list = rows(fleet);
  counts.textContent = summary(list);
  broker.textContent =
      fleet.broker ? `${fleet.broker.url} ${fleet.broker.connected ? 'connected' : 'not connected'}` : '';
  broker.className = `broker${fleet.broker && !fleet.broker.connected ? ' down' : ''}`;
  body.replaceChildren(...list.map((r) => {
    const name =
        r.link ? el('a', {href: r.link, target: '_blank', rel: 'noopener'}, r.name) : el('span', {}, r.name);
    return el(
        'tr', {class: r.look, 'data-testid': `machine-${r.name}`}, el('td', {class: 'name'}, name),
        el('td', {class: 'status', 'data-testid': 'state'}, r.state), el('td', {}, r.program),
        el('td', {}, r.progress), el('td', {class: 'alarms'}, r.alarms),
        el('td', {'data-testid': 'spindle'}, r.spindle), el('td', {'data-testid': 'last-seen'}, r.lastSeen));
  }));
}

async function refresh() {
  try {
    const res = await fetch('/api/v1/fleet', {cache: 'no-store'});
    if (res.ok)
      render(await res.json());
    else
      broker.textContent = `the fleet server answered ${res.status}`;
  } catch {
    broker.textContent = 'the fleet server does not answer';
    broker.className = 'broker down';
  }
}
await refresh();
setInterval(refresh, 1000);
