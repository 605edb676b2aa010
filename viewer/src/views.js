// Camera view presets (3/4, top, front, side): fit a box in the view, corner buttons, shortcut keys.
import { Vector3 } from 'three';
import { el } from './dom.js';

/** dir: from the target towards the camera (bin frame, z up). */
export const PRESETS = [
  { name: '3/4', label: '3/4', key: '1', dir: [0.55, -1.0, 0.95], title: '3/4 view' },
  { name: 'top', label: 'Top', key: '2', dir: [0, -1e-3, 1], title: 'top view: looking down −z, x right, y up' },
  { name: 'front', label: 'Front', key: '3', dir: [0, -1, 0], title: 'front view: looking along +y' },
  { name: 'side', label: 'Side', key: '4', dir: [1, 0, 0], title: 'side view: looking along −x' },
];
const MARGIN = 1.1; // free space around the framed box
const FOCUS_PULL = 0.35; // centre: from the focus (bin) towards the centre of the whole box

export const presetByName = (name) => PRESETS.find((p) => p.name === name) || null;
export const presetByKey = (key) => PRESETS.find((p) => p.key === key) || null;

function corners(box) {
  const { min: a, max: b } = box;
  return [0, 1, 2, 3, 4, 5, 6, 7].map((i) => new Vector3(i & 1 ? b.x : a.x, i & 2 ? b.y : a.y, i & 4 ? b.z : a.z));
}

/** Camera distance from centre along dir at which every corner of box is inside the view frustum. */
function fitDistance(camera, box, centre, dir) {
  const right = new Vector3().crossVectors(camera.up, dir).normalize();
  const up = new Vector3().crossVectors(dir, right);
  const tanV = Math.tan((camera.fov * Math.PI) / 360) / MARGIN;
  const tanH = tanV * camera.aspect;
  let dist = 0.1;
  for (const c of corners(box)) {
    const d = c.sub(centre);
    const z = d.dot(dir);
    dist = Math.max(dist, z + Math.abs(d.dot(right)) / tanH, z + Math.abs(d.dot(up)) / tanV);
  }
  return dist;
}

/** Put the camera on preset `name`, framing box (bin + placement) around a centre pulled towards focus (bin). */
export function applyPreset(view, name, box, focus = box) {
  const preset = presetByName(name);
  if (!preset) throw new Error(`unknown camera preset ${name}`);
  const centre = focus.getCenter(new Vector3()).lerp(box.getCenter(new Vector3()), FOCUS_PULL);
  const dir = new Vector3(...preset.dir).normalize();
  view.camera.position.copy(centre).addScaledVector(dir, fitDistance(view.camera, box, centre, dir));
  view.controls.target.copy(centre);
  view.controls.update();
  view.requestRender();
}

/** Button group for the view's corner; bar.setActive(name | null) marks the active preset. */
export function presetBar(onPick) {
  const buttons = PRESETS.map((p) => el('button', {
    'data-preset': p.name, title: `${p.title} (${p.key})`, onclick: (e) => { onPick(p.name); e.currentTarget.blur(); },
  }, p.label));
  const bar = el('div', { id: 'view-presets', class: 'overlay' }, el('span', { class: 'presets-label' }, 'view'), buttons);
  bar.setActive = (name) => buttons.forEach((b) => b.classList.toggle('active', b.dataset.preset === name));
  return bar;
}
