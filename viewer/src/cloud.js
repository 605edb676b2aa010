// Point cloud: THREE.Points with per-vertex colours by height, segment or tube label.
import { BufferGeometry, Float32BufferAttribute, Points, PointsMaterial, Color } from 'three';
import { tubeColour } from './tubes.js';

export const HEIGHT_STOPS = ['#30123b', '#4669db', '#1fc8de', '#5bfb72', '#d2e935', '#fe9b2d', '#d23105', '#7a0403'];
export const UNLABELLED = '#6b7280';
const MARGIN = 0.006; // a point belongs to a cylinder within radius + 6 mm of its axis segment
const CELL = 0.04;

export function buildCloud(xyz, sizeMm) {
  const geo = new BufferGeometry();
  geo.setAttribute('position', new Float32BufferAttribute(xyz, 3));
  geo.setAttribute('color', new Float32BufferAttribute(new Float32Array(xyz.length), 3));
  const mat = new PointsMaterial({ size: sizeMm / 1000, vertexColors: true, sizeAttenuation: true });
  const points = new Points(geo, mat);
  points.name = 'cloud';
  points.userData = { xyz, range: heightRange(xyz), labels: null };
  return points;
}

/** Robust z range (0.5 / 99.5 percentile of a subsample). */
export function heightRange(xyz) {
  const n = xyz.length / 3;
  const step = Math.max(1, Math.floor(n / 20000));
  const zs = [];
  for (let i = 0; i < n; i += step) zs.push(xyz[3 * i + 2]);
  zs.sort((a, b) => a - b);
  if (!zs.length) return [0, 1];
  const lo = zs[Math.floor(zs.length * 0.005)], hi = zs[Math.floor((zs.length - 1) * 0.995)];
  return hi > lo ? [lo, hi] : [lo, lo + 1e-3];
}

function flattenCylinders(tubes) {
  const cyl = [];
  for (const t of tubes) {
    for (const c of t.cylinders) cyl.push({ a: c.start, b: c.end, lim: c.radius + MARGIN, tubeId: t.id, segmentId: c.segmentId });
  }
  return cyl;
}

/** Uniform grid over the union of cylinder boxes; each cell lists the cylinders that may reach it. */
function buildGrid(cyl) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  const boxes = cyl.map((c) => {
    const b = ['x', 'y', 'z'].map((k) => [Math.min(c.a[k], c.b[k]) - c.lim, Math.max(c.a[k], c.b[k]) + c.lim]);
    b.forEach(([l, h], i) => { lo[i] = Math.min(lo[i], l); hi[i] = Math.max(hi[i], h); });
    return b;
  });
  const dim = lo.map((l, i) => Math.max(1, Math.ceil((hi[i] - l) / CELL)));
  const cells = new Map();
  boxes.forEach((b, ci) => {
    const r = b.map(([l, h], i) => [Math.floor((l - lo[i]) / CELL), Math.min(dim[i] - 1, Math.floor((h - lo[i]) / CELL))]);
    for (let x = r[0][0]; x <= r[0][1]; x++) for (let y = r[1][0]; y <= r[1][1]; y++) for (let z = r[2][0]; z <= r[2][1]; z++) {
      const key = (x * dim[1] + y) * dim[2] + z;
      if (!cells.has(key)) cells.set(key, []);
      cells.get(key).push(ci);
    }
  });
  return { lo, hi, dim, cells };
}

function segDist2(px, py, pz, c) {
  const dx = c.b.x - c.a.x, dy = c.b.y - c.a.y, dz = c.b.z - c.a.z;
  const wx = px - c.a.x, wy = py - c.a.y, wz = pz - c.a.z;
  const L2 = dx * dx + dy * dy + dz * dz;
  const t = L2 > 0 ? Math.min(1, Math.max(0, (wx * dx + wy * dy + wz * dz) / L2)) : 0;
  const ex = wx - t * dx, ey = wy - t * dy, ez = wz - t * dz;
  return ex * ex + ey * ey + ez * ez;
}

/** Index of the nearest containing cylinder per point (-1 if none) and the cylinder list. */
export function labelPoints(xyz, tubes) {
  const cyl = flattenCylinders(tubes);
  const n = xyz.length / 3;
  const label = new Int32Array(n).fill(-1);
  if (!cyl.length) return { label, cyl };
  const { lo, hi, dim, cells } = buildGrid(cyl);
  for (let i = 0; i < n; i++) {
    const x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
    if (x < lo[0] || y < lo[1] || z < lo[2] || x > hi[0] || y > hi[1] || z > hi[2]) continue;
    const gx = Math.min(dim[0] - 1, Math.floor((x - lo[0]) / CELL));
    const gy = Math.min(dim[1] - 1, Math.floor((y - lo[1]) / CELL));
    const gz = Math.min(dim[2] - 1, Math.floor((z - lo[2]) / CELL));
    const list = cells.get((gx * dim[1] + gy) * dim[2] + gz);
    if (!list) continue;
    let best = -1, bestD = Infinity;
    for (const ci of list) {
      const d = segDist2(x, y, z, cyl[ci]);
      if (d <= cyl[ci].lim * cyl[ci].lim && d < bestD) { bestD = d; best = ci; }
    }
    label[i] = best;
  }
  return { label, cyl };
}

export function heightColour(s, out = new Color()) {
  const f = Math.min(Math.max(s, 0), 1) * (HEIGHT_STOPS.length - 1);
  const i = Math.min(Math.floor(f), HEIGHT_STOPS.length - 2);
  return out.set(HEIGHT_STOPS[i]).lerp(new Color(HEIGHT_STOPS[i + 1]), f - i);
}

export function segmentColour(segmentId) {
  const hue = ((Math.round(segmentId) * 0.61803398875) % 1 + 1) % 1;
  return new Color().setHSL(hue, 0.72, 0.58);
}

/** Recolour the cloud for mode 'height' | 'segment' | 'tube'. */
export function colourCloud(points, mode, tubes) {
  const { xyz, range } = points.userData;
  const col = points.geometry.getAttribute('color');
  const arr = col.array;
  const c = new Color();
  if (mode === 'height') {
    const [lo, hi] = range;
    for (let i = 0; i < xyz.length / 3; i++) {
      heightColour((xyz[3 * i + 2] - lo) / (hi - lo), c).toArray(arr, 3 * i);
    }
  } else {
    if (!points.userData.labels) points.userData.labels = labelPoints(xyz, tubes);
    const { label, cyl } = points.userData.labels;
    const grey = new Color(UNLABELLED);
    const colours = cyl.map((k) => (mode === 'segment' ? segmentColour(k.segmentId) : new Color(tubeColour(k.tubeId))));
    for (let i = 0; i < label.length; i++) (label[i] < 0 ? grey : colours[label[i]]).toArray(arr, 3 * i);
  }
  col.needsUpdate = true;
}

export function labelledCount(points) {
  const l = points.userData.labels?.label;
  if (!l) return null;
  let n = 0;
  for (let i = 0; i < l.length; i++) if (l[i] >= 0) n++;
  return n;
}
