// Hover in the 3-D view: the tube under the mouse (priority), else the cloud point with its
// bin-frame coordinates, in the tooltip. Raycasts are throttled (the last position always runs).
import { BufferGeometry, Float32BufferAttribute, Points, PointsMaterial } from 'three';
import { el, fmt } from './dom.js';
import { pickTube, pickCloudPoint } from './picking.js';
import { graphText } from './data.js';

const INTERVAL = 50; // ms between raycasts: 200 k points stay smooth

/** Bright dot drawn on top of everything at the hovered cloud point. */
function hoverMarker() {
  const geo = new BufferGeometry();
  geo.setAttribute('position', new Float32BufferAttribute([0, 0, 0], 3));
  const dot = new Points(geo, new PointsMaterial({ color: 0xffffff, size: 7, sizeAttenuation: false, depthTest: false, transparent: true }));
  dot.renderOrder = 12;
  dot.visible = false;
  dot.name = 'hover-point';
  return dot;
}

function tubeText(m, id) {
  const t = m.tubes.find((x) => x.id === id);
  const best = m.plans.find((p) => p.tubeId === id);
  return `tube ${id} · ${graphText(t)} · ${t.occlusion} occlusion · ${t.length.toFixed(3)} m · ${best ? `best plan #${best.index + 1} (G ${best.cost.G.toFixed(3)})` : 'no plan'}`;
}

function pointContent(cloud, hit) {
  const l = cloud.userData.labels;
  const ci = l ? l.label[hit.index] : -1;
  return [el('span', { class: 'tip-muted' }, 'point'), ['x', 'y', 'z'].map((k) => [el('span', { class: 'tip-muted' }, ` ${k} `), fmt(hit.p[k])]),
    el('span', { class: 'tip-muted' }, ' m · bin frame'), ci >= 0 ? ` · tube ${l.cyl[ci].tubeId}` : ''];
}

/** Returns {move(event), leave()}; onTube(id | null) restyles the hovered tube. */
export function createHover(ui, state, onTube) {
  const marker = hoverMarker();
  ui.view.scene.add(marker);
  let last = 0, timer = null, pending = null;
  const show = (content, at, point = null) => {
    const tip = ui.tooltip;
    tip.style.display = content ? 'block' : 'none';
    ui.view.renderer.domElement.style.cursor = point ? 'crosshair' : content ? 'pointer' : '';
    if (point) tip.dataset.point = [point.x, point.y, point.z].join(','); else delete tip.dataset.point;
    if (marker.visible !== !!point || point) { marker.visible = !!point; if (point) marker.position.copy(point); ui.view.requestRender(); }
    if (!content) return;
    tip.replaceChildren(...[content].flat(3));
    const r = ui.viewEl.getBoundingClientRect();
    tip.style.left = `${at.x - r.left + 14}px`;
    tip.style.top = `${at.y - r.top + 14}px`;
  };
  const update = (at) => {
    const id = pickTube(ui.view, state.objs?.tubes, at.x, at.y);
    onTube(id);
    if (id != null) { show(tubeText(state.model, id), at); return; }
    const cloud = state.objs?.cloud;
    const hit = cloud && state.layers.cloud ? pickCloudPoint(ui.view, cloud, at.x, at.y) : null;
    show(hit ? pointContent(cloud, hit) : null, at, hit?.p);
  };
  const run = () => { timer = null; last = performance.now(); if (pending) update(pending); };
  return {
    move(e) {
      pending = { x: e.clientX, y: e.clientY };
      if (timer) return;
      const wait = INTERVAL - (performance.now() - last);
      if (wait <= 0) run(); else timer = setTimeout(run, wait);
    },
    leave() { clearTimeout(timer); timer = null; pending = null; show(null); onTube(null); },
  };
}
