// Parallel gripper model in the TCP frame (z down along the approach, y closing, x along the tube).
import { Group, Mesh, BoxGeometry, MeshStandardMaterial } from 'three';
import { num } from './data.js';
import { axes } from './cell.js';

export function gripperDims(g) {
  const f = (g?.finger_size || [0.022, 0.01, 0.05]).map(num);
  const h = (g?.housing_size || [0.06, 0.13, 0.09]).map(num);
  return { finger: f, housing: h, tip: num(g?.finger_tip_depth ?? 0.005), gap: num(g?.housing_gap ?? 0.02) };
}

function box(size, at, mat) {
  const m = new Mesh(new BoxGeometry(...size), mat);
  m.position.set(...at);
  return m;
}

/** Small translucent grasp marker: the two pads and a stem along the approach axis. */
export function buildMarker(dims, openingWidth, colour) {
  const { finger: [fx, fy, fz], tip } = dims;
  const mat = new MeshStandardMaterial({ color: colour, transparent: true, opacity: 0.45, depthWrite: false });
  const group = new Group();
  const yPad = (num(openingWidth) + fy) / 2;
  for (const s of [1, -1]) group.add(box([fx, fy, fz], [0, s * yPad, tip - fz / 2], mat));
  group.add(box([fx * 0.8, 2 * yPad + fy, fy], [0, 0, tip - fz - fy / 2], mat));
  group.add(box([fy * 0.6, fy * 0.6, 0.05], [0, 0, tip - fz - fy - 0.025], mat));
  group.name = 'grasp-marker';
  return group;
}

/** Gripper group in the TCP frame; opacity < 1 gives a translucent version. */
export function buildGripper(dims, openingWidth, { opacity = 1, colour = null } = {}) {
  const { finger: [fx, fy, fz], housing: [hx, hy, hz], tip, gap } = dims;
  const translucent = opacity < 1;
  const common = { transparent: translucent, opacity, depthWrite: !translucent, roughness: 0.5, metalness: 0.3 };
  const padMat = new MeshStandardMaterial({ color: colour ?? 0xf0a030, ...common });
  const bodyMat = new MeshStandardMaterial({ color: colour ?? 0x9aa3b0, ...common });
  const group = new Group();
  const yPad = (num(openingWidth) + fy) / 2;
  const zPad = tip - fz / 2;
  const zBottom = tip - fz - gap;
  for (const s of [1, -1]) {
    group.add(box([fx, fy, fz], [0, s * yPad, zPad], padMat));
    if (gap > 0) group.add(box([fx * 0.6, fy * 0.7, gap], [0, s * yPad, zBottom + gap / 2], bodyMat));
  }
  group.add(box([hx, hy, hz], [0, 0, zBottom - hz / 2], bodyMat));
  if (!translucent) group.add(axes(0.04, 0.9));
  group.name = translucent ? 'grasp-marker' : 'gripper';
  return group;
}
