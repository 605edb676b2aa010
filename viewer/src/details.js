// "Selected plan" box: rank, tube, trajectory, grasp pose, opening, waypoints, place pose, costs.
import { Vector3 } from 'three';
import { el, fmt } from './dom.js';
import { tubeColour } from './tubes.js';
import { graphText } from './data.js';

const MAX_WAYPOINTS = 4;

/** Angle of the TCP x axis in the bin xy plane, degrees in (−180, 180]. */
export function yawDeg(q) {
  const x = new Vector3(1, 0, 0).applyQuaternion(q);
  return (Math.atan2(x.y, x.x) * 180) / Math.PI;
}

/** x, y, z cells; with field, each number carries data-field="FIELD-x|y|z". */
function xyz(p, field = null) {
  return el('span', { class: 'xyz' }, ['x', 'y', 'z'].map((k) => el('span', {},
    el('i', {}, k), el('b', { 'data-field': field && `${field}-${k}` }, fmt(p[k])))), el('i', {}, 'm'));
}

function waypointList(ws) {
  if (!ws.length) return 'none';
  const rows = ws.slice(0, MAX_WAYPOINTS).map((w, i) => el('div', {}, el('i', { class: 'wp' }, `Δ${i + 1}`), xyz(w)));
  if (ws.length > MAX_WAYPOINTS) rows.push(el('div', { class: 'meta' }, `+ ${ws.length - MAX_WAYPOINTS} more`));
  return rows;
}

function costs(c) {
  return el('span', { class: 'costs' }, ['H', 'C', 'T', 'G'].map((k) => el('span', { class: k === 'G' ? 'total' : null },
    el('i', {}, k), el('b', { 'data-field': `cost-${k}` }, fmt(c[k])))));
}

/** The plan's tube's branches and junctions when it is not linear (title: in words), else nothing. */
function tubeShape(m, plan) {
  const tube = m.tubes.find((t) => t.id === plan.tubeId);
  const text = tube ? graphText(tube, true) : 'linear';
  return text === 'linear' ? null : el('span', { class: 'pd-graph', 'data-field': 'tube-graph', title: graphText(tube) }, text);
}

function header(m, plan) {
  return el('div', { class: 'pd-head' },
    el('span', { class: 'pd-rank', 'data-field': 'rank' }, `#${plan.index + 1}`),
    el('span', { class: 'meta' }, `of ${m.plans.length}`),
    el('span', { class: 'pd-tube' }, el('span', { class: 'swatch', style: `background:${tubeColour(plan.tubeId)}` }), `tube ${plan.tubeId}`),
    tubeShape(m, plan),
    el('span', { class: 'badge kind' }, plan.kind),
    m.chosenPlan === plan.index ? el('span', { class: 'badge exec', 'data-field': 'executed' }, 'executed') : null);
}

/** Children of #plan-details for the plan (or a hint when none is selected). */
export function planDetails(m, plan) {
  if (!plan) return [el('div', { class: 'empty' }, 'no plan selected — click a plan row or a tube')];
  const rows = [
    ['grasp X_BinTcp', xyz(plan.tcp.p, 'grasp')],
    ['grasp yaw', el('b', { 'data-field': 'grasp-yaw' }, `${fmt(yawDeg(plan.tcp.q), 1)}°`)],
    ['grasp tilt', el('b', { 'data-field': 'grasp-tilt' },
      plan.tilt ? `${fmt(plan.tilt * 180 / Math.PI, 1)}° (a vertical tool would touch a wall)` : 'vertical')],
    ['finger opening', el('b', { 'data-field': 'opening' }, `${fmt(plan.openingWidth)} m`)],
    ['waypoints', waypointList(plan.waypoints)],
    ['place TCP', plan.place ? xyz(plan.place.p, 'place') : '–'],
    ['cost', costs(plan.cost)],
    ['simulated displacement', el('b', { 'data-field': 'displacement' }, `${fmt(plan.displacement)} m`)],
    ['certainty', el('b', { 'data-field': 'certainty', title: 'sure: a free tube nothing lies on, lifted straight up; simulated: its displacement says how safe; unsure: needed luck' }, plan.certainty)],
  ];
  return [header(m, plan), el('div', { class: 'pd-grid' }, rows.flatMap(([k, v]) => [el('div', { class: 'k' }, k), el('div', { class: 'v' }, v)]))];
}

export function renderPlanDetails(root, m, plan) {
  const box = root.querySelector('#plan-details');
  if (box) box.replaceChildren(...planDetails(m, plan));
}
