// Side panel: header, frame stepper, summary, tables (tubes, plans, counts, timings), display controls.
import { el, fmt, seconds, int, table, kvTable } from './dom.js';
import { num, graphText } from './data.js';
import { tubeColour, OCCLUSION_COLOURS } from './tubes.js';

export const LAYERS = ['cloud', 'bin', 'tubes', 'grasps', 'trajectory', 'placement'];

export function buildHeader(data) {
  const links = Array.isArray(data.links) && data.links.length
    ? el('div', { class: 'links' }, data.links.map((l) => el('a', { href: l.href }, l.label || l.href))) : null;
  return el('div', {}, links,
    el('h1', {}, data.title || 'tubepick viewer'),
    data.source ? el('div', { class: 'meta' }, 'source ', el('b', {}, data.source)) : null,
    data.generated ? el('div', { class: 'meta' }, 'generated ', el('b', {}, data.generated)) : null);
}

export function buildStepper(frames, h) {
  const prev = el('button', { title: 'previous frame (←)', onclick: () => h.onFrame(h.current() - 1) }, '‹');
  const next = el('button', { title: 'next frame (→)', onclick: () => h.onFrame(h.current() + 1) }, '›');
  const select = el('select', { id: 'frame-select', onchange: (e) => h.onFrame(Number(e.target.value)) },
    frames.map((f, i) => el('option', { value: i }, `${i + 1} / ${frames.length} · ${f.label || 'frame'}`)));
  const box = el('div', { class: 'stepper', id: 'stepper' }, prev, select, next);
  box.update = (i) => { select.value = String(i); prev.disabled = i <= 0; next.disabled = i >= frames.length - 1; };
  return box;
}

export function buildControls(state, h) {
  const layers = el('div', { class: 'layers' }, LAYERS.map((name) => el('label', {},
    el('input', { type: 'checkbox', id: `layer-${name}`, checked: state.layers[name], onchange: (e) => h.onLayer(name, e.target.checked) }),
    ` ${name}`)));
  const mode = el('select', { id: 'colour-mode', onchange: (e) => h.onColourMode(e.target.value) },
    ['height', 'segment', 'tube'].map((m) => el('option', { value: m, selected: m === state.colourMode }, m)));
  const size = el('input', { type: 'range', id: 'point-size', min: 1, max: 10, step: 0.5, value: state.pointSize,
    oninput: (e) => h.onPointSize(Number(e.target.value)) });
  const occl = el('input', { type: 'checkbox', id: 'tube-occlusion', checked: state.byOcclusion, onchange: (e) => h.onOcclusion(e.target.checked) });
  return el('div', {}, layers, el('div', { class: 'controls' },
    'cloud colour', mode, 'point size', size,
    'tube colour', el('label', {}, occl, ' by occlusion class')));
}

/** Frame-specific content: note, error, summary, tables. */
export function buildFrameSection(m, h) {
  return el('div', { id: 'frame-section' },
    m.note ? el('div', { class: 'note' }, m.note) : null,
    m.error ? el('div', { class: 'frame-error', id: 'frame-error' }, m.error) : null,
    m.problems.map((p) => el('div', { class: 'frame-error data-problem' }, p)),
    (m.modeling?.warnings || []).map((w) => el('div', { class: 'frame-warning', 'data-code': w.code || '' }, w.message || w.code)),
    el('h2', {}, 'Summary'), summary(m),
    el('h2', {}, `Tubes (${m.tubes.length})`), tubesTable(m, h),
    m.plans.length ? [el('h2', {}, 'Selected plan'), el('div', { id: 'plan-details', class: 'plan-details' })] : null,
    el('h2', {}, `Plans (${m.plans.length})`), plansTable(m, h),
    countsSection(m), timingsSection(m));
}

function summary(m) {
  const p = m.plan || {};
  const pairs = [
    ['tubes modelled', int(m.tubes.length)],
    ['plans', m.hasPlan ? int(m.plans.length) : m.error ? '–' : 'modeling only'],
    ['bin empty', m.hasPlan ? (p.binEmpty ? 'yes' : 'no') : '–'],
    ['simulation used', m.hasPlan ? (p.usedSimulation ? 'yes' : 'no') : '–'],
    ['modeling time', m.modeling ? seconds(num(m.modeling.totalSeconds)) : '–'],
    ['planning time', m.hasPlan ? seconds(num(p.totalSeconds)) : '–'],
    ['cloud points shown', m.cloud ? `${int(m.cloud.points)}${m.cloud.total ? ` of ${int(m.cloud.total)}` : ''}` : 'none'],
  ];
  if (m.modeling?.profile) pairs.push(['modeling profile', `${m.modeling.profile} (seed ${m.modeling.seed ?? 0})`]);
  return kvTable(pairs, 'summary');
}

function tubesTable(m, h) {
  if (!m.tubes.length) return el('div', { class: 'empty' }, 'no tubes');
  const planCount = (id) => m.plans.filter((p) => p.tubeId === id).length;
  const rows = m.tubes.map((t) => el('tr', { 'data-tube-id': t.id, onclick: () => h.onSelectTube(t.id) },
    el('td', {}, el('span', { class: 'swatch', style: `background:${tubeColour(t.id)}` }), t.id),
    el('td', { class: 'num' }, fmt(t.length)),
    graphCell(t),
    el('td', {}, el('span', { class: `badge occ-${t.occlusion}` }, t.occlusion)),
    el('td', { class: 'num' }, t.occludedJointCount),
    el('td', { class: 'num' }, planCount(t.id))));
  return table('tubes', [{ label: 'tube' }, { label: 'length m', num: 1 },
    { label: 'shape', title: 'branches (br) and junctions (jn: T/Y pieces) of the tube; linear: one branch' }, { label: 'occlusion' },
    { label: 'occl. joints', num: 1, title: 'occluded joints' }, { label: 'plans', num: 1 }], rows);
}

/** "linear" (muted) or "5 br, 2 jn"; the title spells it out. */
function graphCell(t) {
  const text = graphText(t, true);
  return el('td', { class: text === 'linear' ? 'graph linear' : 'graph', 'data-field': 'graph', title: graphText(t) }, text);
}

function plansTable(m, h) {
  if (!m.hasPlan && m.error) return el('div', { class: 'empty', id: 'plans-empty' }, 'no plan — the call failed');
  if (!m.hasPlan) return el('div', { class: 'empty', id: 'plans-empty' }, 'modeling only — no planning in this frame');
  if (!m.plans.length) return el('div', { class: 'empty', id: 'plans-empty' }, 'no feasible plan');
  const rows = m.plans.map((p) => el('tr', { 'data-plan-index': p.index, onclick: () => h.onSelectPlan(p.index) },
    el('td', { class: 'num' }, p.index + 1),
    el('td', {}, el('span', { class: 'swatch', style: `background:${tubeColour(p.tubeId)}` }), p.tubeId),
    el('td', {}, p.kind),
    ['H', 'C', 'T', 'G'].map((k) => el('td', { class: 'num' }, fmt(p.cost[k]))),
    el('td', { class: 'num' }, fmt(p.displacement)),
    el('td', {}, m.chosenPlan === p.index ? el('span', { class: 'badge exec' }, 'executed') : '')));
  return table('plans', [{ label: '#', num: 1, title: 'rank (best first)' }, { label: 'tube' }, { label: 'trajectory' },
    { label: 'H', num: 1, title: 'height cost' }, { label: 'C', num: 1, title: 'centre cost' },
    { label: 'T', num: 1, title: 'trajectory cost' }, { label: 'G', num: 1, title: 'total cost (lower is better)' },
    { label: 'disp. m', num: 1, title: 'simulated displacement of other tubes' }, { label: '' }], rows);
}

function countsSection(m) {
  const c = m.plan?.counts;
  const out = [];
  if (c) {
    const n = (k) => int(num(c[k]));
    out.push(el('h2', {}, 'Candidates rejected per filter'), kvTable([
      ['grasp candidates', n('graspCandidates')], ['rejected: section', n('rejectedSection')],
      ['rejected: workspace', n('rejectedWorkspace')], ['rejected: tool', n('rejectedTool')],
      ['rejected: fingers', n('rejectedFingers')], ['rejected: approach', n('rejectedApproach')],
      ['viable with a tilted tool', n('tiltedGrasps')]], 'counts'));
    out.push(el('h2', {}, 'Tubes and trajectories'), kvTable([
      ['tubes', n('tubes')], ['too short', c.shortTubesPlanned ? `${n('tooShort')}, every one: planned as a last resort` : n('tooShort')], ['non-occluded', n('nonOccluded')],
      ['weakly occluded', n('weaklyOccluded')], ['strongly occluded', n('stronglyOccluded')],
      ['trajectories', n('trajectories')], ['trajectories simulated', n('simulatedTrajectories')]], 'tube-counts'));
  }
  const steps = m.modeling?.stepCounts;
  if (Array.isArray(steps) && steps.length) {
    out.push(el('h2', {}, 'Modeling: points per step'), kvTable(steps.map((s) => [s.step, int(num(s.points))]), 'step-counts'));
    out.push(kvTable([['segments', int(num(m.modeling.segmentCount))], ['cylinders', int(num(m.modeling.cylinderCount))],
      ['dropped non-finite', int(num(m.modeling.droppedNonFinite))], ['max height m', fmt(num(m.modeling.maxHeight))]]));
  }
  return out;
}

function timingRows(list) {
  const items = (list || []).map((t) => ({ stage: t.stage, s: num(t.seconds) }));
  const max = Math.max(1e-12, ...items.map((t) => t.s));
  return items.map((t) => el('tr', {}, el('td', {}, t.stage), el('td', { style: 'width:40%' },
    el('div', { class: 'bar', style: `width:${(100 * t.s) / max}%` })), el('td', { class: 'num' }, seconds(t.s))));
}

function timingsSection(m) {
  const out = [];
  const mod = m.modeling?.stageTimings;
  if (mod?.length) out.push(el('h2', {}, `Modeling stages (${seconds(num(m.modeling.totalSeconds))})`), el('table', { class: 'kv' }, el('tbody', {}, timingRows(mod))));
  const pl = m.plan?.stageTimings;
  if (pl?.length) out.push(el('h2', {}, `Planning stages (${seconds(num(m.plan.totalSeconds))})`), el('table', { class: 'kv' }, el('tbody', {}, timingRows(pl))));
  return out;
}

/** Reflect the current selection in the tables. */
export function markSelection(root, m, selectedPlan, selectedTubeId) {
  root.querySelectorAll('#plans tr[data-plan-index]').forEach((tr) => {
    const i = Number(tr.dataset.planIndex);
    tr.classList.toggle('selected', i === selectedPlan);
    tr.classList.toggle('of-tube', selectedTubeId != null && m.plans[i]?.tubeId === selectedTubeId);
  });
  root.querySelectorAll('#tubes tr[data-tube-id]').forEach((tr) => {
    tr.classList.toggle('selected', Number(tr.dataset.tubeId) === selectedTubeId);
  });
  const row = root.querySelector('#plans tr.selected') || root.querySelector('#tubes tr.selected');
  if (row && !isVisible(row)) row.scrollIntoView({ block: 'nearest' });
}

function isVisible(row) {
  const r = row.getBoundingClientRect();
  const p = row.closest('#panel')?.getBoundingClientRect();
  return !p || (r.top >= p.top && r.bottom <= p.bottom);
}

/** Legend overlay for the 3-D view. */
export function legend(state, m, cloudRange, heightStops, labelled) {
  const rows = [];
  rows.push(el('div', { class: 'title' }, 'tubes'));
  if (state.byOcclusion) {
    for (const k of ['none', 'weak', 'strong']) rows.push(el('div', { class: 'row' }, el('span', { class: 'swatch', style: `background:${OCCLUSION_COLOURS[k]}` }), `${k} occlusion`));
  } else {
    rows.push(el('div', { class: 'row' }, m.tubes.length ? m.tubes.map((t) => el('span', { style: 'margin-right:8px;white-space:nowrap' },
      el('span', { class: 'swatch', style: `background:${tubeColour(t.id)}` }), t.id)) : 'none'));
  }
  if (m.cloud && state.layers.cloud) {
    rows.push(el('div', { class: 'title' }, `cloud · ${state.colourMode}`));
    if (state.colourMode === 'height') {
      rows.push(el('div', { class: 'gradient', style: `background:linear-gradient(90deg,${heightStops.join(',')})` }),
        el('div', { class: 'range-labels' }, el('span', {}, `z ${fmt(cloudRange[0])} m`), el('span', {}, `${fmt(cloudRange[1])} m`)));
    } else {
      const pct = labelled == null ? '' : ` (${fmt((100 * labelled) / Math.max(1, m.cloud.xyz.length / 3), 1)} % labelled)`;
      rows.push(el('div', { class: 'row' }, `colour per ${state.colourMode === 'segment' ? 'segment' : 'tube'}; `,
        el('span', { class: 'swatch', style: 'background:#6b7280' }), `unlabelled${pct}`));
    }
  }
  rows.push(el('div', { class: 'title' }, 'frames'), el('div', { class: 'row' },
    el('span', { class: 'swatch', style: 'background:#f0a030' }), 'gripper pads · ',
    el('span', { style: 'color:#7dd3fc' }, '- - path'), ' · axes ', el('span', { style: 'color:#ff5555' }, 'x'),
    el('span', { style: 'color:#55dd55' }, 'y'), el('span', { style: 'color:#6699ff' }, 'z')));
  return rows;
}
