// Boot: read the embedded data, build the layout, 3-D view and panel, expose window.tubepickViewer.
import { injectStyle } from './style.js';
import { el } from './dom.js';
import { parseData, frameModel, num, vec3 } from './data.js';
import { createView, boxOf, screenPoint } from './scene.js';
import { applyPreset, presetBar, presetByKey } from './views.js';
import { buildBin, buildPlacement } from './cell.js';
import { gripperDims } from './gripper.js';
import { colourCloud, HEIGHT_STOPS, labelledCount } from './cloud.js';
import { styleTubes, partCounts } from './tubes.js';
import { buildFrameObjects, showPlan, clearPlan, dispose } from './frame.js';
import { pickTube, screenPointOfTube } from './picking.js';
import { createHover } from './hover.js';
import { renderPlanDetails } from './details.js';
import { buildHeader, buildStepper, buildControls, buildFrameSection, markSelection, legend, LAYERS } from './panel.js';
import { createPlayerBar } from './playerbar.js';

const state = {
  ready: false, errors: [], data: null, models: [], frameIndex: 0, model: null, objs: null,
  selectedPlan: null, selectedTubeId: null, hoverId: null, ghost: false, cameraPreset: null,
  layers: Object.fromEntries(LAYERS.map((l) => [l, true])), colourMode: 'height', pointSize: 3, byOcclusion: false,
};
const ui = {};

/** Broken data or viewer failure: message in the page, errors[], console. */
function report(message, fatal = false) {
  state.errors.push(message);
  console.error(`tubepick viewer: ${message}`);
  const box = fatal ? ui.message : ui.banner;
  if (box) { box.textContent = message; box.classList.add('show'); }
}

function banner() {
  const m = state.model;
  const text = [m.error && `Call failed: ${m.error}`, ...m.problems.map((p) => `Data problem: ${p}`)].filter(Boolean).join('\n');
  ui.banner.textContent = text;
  ui.banner.classList.toggle('show', !!text);
}

function layout() {
  ui.message = el('div', { id: 'message' });
  ui.legend = el('div', { id: 'legend', class: 'overlay' });
  ui.tooltip = el('div', { id: 'tooltip' });
  ui.banner = el('div', { id: 'banner' });
  ui.presets = presetBar((name) => setCameraPreset(name));
  ui.viewEl = el('div', { id: 'view' }, ui.legend, ui.presets, ui.tooltip, ui.banner, ui.message);
  ui.panel = el('aside', { id: 'panel' });
  document.body.append(el('div', { id: 'app' }, ui.viewEl, ui.panel));
}

function readData() {
  const script = document.getElementById('tubepick-data');
  return parseData(script ? script.textContent : '');
}

function model(i) {
  if (!state.models[i]) state.models[i] = frameModel(state.data.frames[i]);
  return state.models[i];
}

function showFrame(i) {
  const n = state.data?.frames.length || 0;
  if (!n) return;
  i = Math.max(0, Math.min(n - 1, Math.trunc(Number(i)) || 0));
  if (state.objs) { clearPlan(state.objs); ui.view.root.remove(state.objs.group); dispose(state.objs.group); }
  state.frameIndex = i;
  state.model = model(i);
  state.model.problems.forEach((p) => { if (!state.model.reported) report(`frame ${i + 1}: ${p}`); });
  state.model.reported = true;
  state.objs = buildFrameObjects(state.model, ui.dims, state.pointSize);
  ui.view.root.add(state.objs.group);
  ui.stepper?.update(i);
  ui.frameSection.replaceChildren(buildFrameSection(state.model, handlers));
  banner();
  state.selectedPlan = null; state.selectedTubeId = null;
  recolourCloud();
  ui.hover.leave();
  const chosen = state.model.chosenPlan;
  selectPlan(chosen != null && state.model.plans[chosen] ? chosen : state.model.plans.length ? 0 : null);
}

function recolourCloud() {
  if (state.objs?.cloud) colourCloud(state.objs.cloud, state.colourMode, state.model.tubes);
  applyLayers();
  refresh();
}

function selectPlan(i) {
  const plan = i == null ? null : state.model?.plans[Number(i)];
  renderPlanDetails(ui.panel, state.model, plan);
  if (!plan) { state.selectedPlan = null; clearPlan(state.objs); ui.bar.setPlayer(null); refresh(); return; }
  state.selectedPlan = plan.index;
  state.selectedTubeId = plan.tubeId;
  const tube = state.model.tubes.find((t) => t.id === plan.tubeId);
  const player = showPlan(state.objs, plan, tube, ui.dims, ui.binHeight, onPlayerUpdate);
  ui.bar.setPlayer(player, `plan #${plan.index + 1} · tube ${plan.tubeId}`);
  refresh();
}

function onPlayerUpdate(player) {
  ui.bar.update();
  const ghost = player.t > 0;
  if (ghost !== state.ghost) { state.ghost = ghost; refresh(); }
  applyLayers();
  ui.view.requestRender();
}

function selectTube(id) {
  if (id == null) { state.selectedTubeId = null; selectPlan(null); return; }
  id = num(id);
  const best = state.model?.plans.find((p) => p.tubeId === id);
  if (best) { selectPlan(best.index); return; }
  selectPlan(null);
  state.selectedTubeId = state.model?.tubes.some((t) => t.id === id) ? id : null;
  refresh();
}

function applyLayers() {
  const o = state.objs, L = state.layers;
  ui.bin.visible = L.bin;
  ui.placement.visible = L.placement;
  if (!o) return;
  if (o.cloud) o.cloud.visible = L.cloud;
  o.tubes.visible = L.tubes;
  o.markers.visible = L.grasps;
  const s = o.selection.userData;
  if (s.gripper) s.gripper.visible = L.grasps;
  if (s.path) s.path.visible = L.trajectory;
  if (s.carried) s.carried.visible = L.trajectory && (o.player?.t ?? 0) > 0;
}

function refresh() {
  if (!state.objs) return;
  styleTubes(state.objs.tubes, { selectedId: state.selectedTubeId, hoverId: state.hoverId, byOcclusion: state.byOcclusion,
    ghost: state.ghost && state.selectedPlan != null && state.layers.trajectory });
  markSelection(ui.panel, state.model, state.selectedPlan, state.selectedTubeId);
  const range = state.objs.cloud?.userData.range || [0, 1];
  ui.legend.replaceChildren(...legend(state, state.model, range, HEIGHT_STOPS, state.objs.cloud ? labelledCount(state.objs.cloud) : null));
  applyLayers();
  ui.view.requestRender();
}

const handlers = {
  current: () => state.frameIndex,
  onFrame: (i) => showFrame(i),
  onSelectPlan: (i) => selectPlan(i),
  onSelectTube: (id) => selectTube(id),
  onLayer: (name, on) => { state.layers[name] = on; refresh(); },
  onColourMode: (m) => setColourMode(m),
  onPointSize: (mm) => { state.pointSize = mm; if (state.objs?.cloud) state.objs.cloud.material.size = mm / 1000; ui.view.requestRender(); },
  onOcclusion: (on) => { state.byOcclusion = on; refresh(); },
};

function setColourMode(m) {
  if (!['height', 'segment', 'tube'].includes(m)) throw new Error(`unknown colour mode ${m}`);
  state.colourMode = m;
  const sel = document.getElementById('colour-mode');
  if (sel) sel.value = m;
  recolourCloud();
}

function installPointer() {
  const canvas = ui.view.renderer.domElement;
  let down = null;
  canvas.addEventListener('pointerdown', (e) => { down = { x: e.clientX, y: e.clientY, b: e.button }; });
  canvas.addEventListener('pointerup', (e) => {
    if (!down || down.b !== 0 || Math.hypot(e.clientX - down.x, e.clientY - down.y) > 5) { down = null; return; }
    down = null;
    const id = pickTube(ui.view, state.objs?.tubes, e.clientX, e.clientY);
    if (id != null) selectTube(id);
  });
  canvas.addEventListener('pointermove', (e) => { if (!e.buttons) ui.hover.move(e); });
  canvas.addEventListener('pointerleave', () => ui.hover.leave());
}

function setHoverTube(id) {
  if (id !== state.hoverId) { state.hoverId = id; refresh(); }
}

/** Camera preset '3/4' | 'top' | 'front' | 'side', framing the bin and the placement frame. */
function setCameraPreset(name) {
  applyPreset(ui.view, name, ui.frameBox, ui.binBox);
  state.cameraPreset = name;
  ui.presets.setActive(name);
}

function onUserCamera() {
  state.cameraPreset = null;
  ui.presets.setActive(null);
}

function installKeys() {
  window.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
    if (e.key === 'ArrowLeft') showFrame(state.frameIndex - 1);
    else if (e.key === 'ArrowRight') showFrame(state.frameIndex + 1);
    else if (e.key === 'Escape') selectTube(null);
    else if (e.key === ' ') { ui.bar.toggle(); e.preventDefault(); } else if (presetByKey(e.key) && !e.ctrlKey && !e.metaKey && !e.altKey) {
      setCameraPreset(presetByKey(e.key).name);
    }
  });
}

/** A tube's graph as the viewer read it, and what it drew of it: {nodes, branches, junctions, drawn: {joint, link, junction, end}}. */
function tubeGraph(id) {
  const t = state.model?.tubes.find((x) => x.id === id);
  const g = state.objs?.tubes.children.find((x) => x.userData.tubeId === id);
  if (!t || !g) return null;
  return { nodes: t.nodes.length, branches: t.branches.length, junctions: t.junctions, drawn: partCounts(g) };
}

function buildPanel() {
  const d = state.data;
  ui.frameSection = el('div');
  ui.stepper = d.frames.length > 1 ? buildStepper(d.frames, handlers) : null;
  ui.panel.append(buildHeader(d), ui.stepper || el('div', { class: 'meta', style: 'margin-top:8px' }, d.frames[0].label || ''),
    ui.frameSection, el('h2', {}, 'Display'), buildControls(state, handlers),
    el('div', { class: 'hint' }, 'drag: orbit · right-drag: pan · wheel: zoom · click a tube or a row to select · ',
      el('kbd', {}, 'Esc'), ' clear · ', el('kbd', {}, 'space'), ' play · ', el('kbd', {}, '1'), '–', el('kbd', {}, '4'), ' views', d.frames.length > 1 ? [' · ', el('kbd', {}, '←'), el('kbd', {}, '→'), ' frames'] : ''));
}

function buildCell() {
  const cell = state.data.cell || {};
  ui.dims = gripperDims(cell.gripper);
  ui.bin = buildBin(cell.bin);
  ui.binHeight = ui.bin.userData.size[2];
  ui.placement = buildPlacement(cell.X_BinPlace);
  ui.view.scene.add(ui.bin, ui.placement);
  ui.frameBox = boxOf([ui.bin, ui.placement]);
  ui.binBox = boxOf([ui.bin]);
  setCameraPreset('3/4');
  ui.view.controls.addEventListener('start', onUserCamera);
}

function boot() {
  injectStyle();
  layout();
  try {
    state.data = readData();
    document.title = document.title || state.data.title || 'tubepick viewer';
  } catch (e) {
    ui.panel.append(el('h1', {}, 'tubepick viewer'), el('div', { class: 'frame-error data-problem' }, e.message));
    report(e.message, true);
    state.ready = true;
    return;
  }
  try {
    ui.view = createView(ui.viewEl);
    ui.bar = createPlayerBar(ui.viewEl, () => ui.view.requestRender());
    ui.view.onFrame.push((t) => ui.bar.tick(t));
    ui.hover = createHover(ui, state, setHoverTube);
    buildCell();
    buildPanel();
    installPointer();
    installKeys();
    showFrame(0);
  } catch (e) {
    report(`viewer failed: ${e.message}`, true);
  }
  requestAnimationFrame(() => requestAnimationFrame(() => { state.ready = true; }));
}

window.tubepickViewer = {
  get ready() { return state.ready; },
  get errors() { return state.errors; },
  get frameCount() { return state.data?.frames.length || 0; },
  get frameIndex() { return state.frameIndex; },
  get selectedPlan() { return state.selectedPlan; },
  get selectedTubeId() { return state.selectedTubeId; },
  get colourMode() { return state.colourMode; },
  get cameraPreset() { return state.cameraPreset; },
  showFrame, selectPlan, selectTube, setColourMode, setCameraPreset,
  camera: () => ({ position: ui.view.camera.position.toArray(), target: ui.view.controls.target.toArray() }),
  screenPoint: (p) => screenPoint(ui.view, vec3(p)),
  tubeCount: () => state.model?.tubes.length || 0,
  planCount: () => state.model?.plans.length || 0,
  tubeGraph: (id) => tubeGraph(num(id)),
  screenPointOfTube: (id) => screenPointOfTube(ui.view, state.objs?.tubes, state.model?.tubes.find((t) => t.id === num(id))),
  playTrajectory: () => ui.bar?.play(),
};

window.addEventListener('error', (e) => state.errors.push(`uncaught: ${e.message}`));
if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', boot);
else boot();
