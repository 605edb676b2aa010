// Tube models: a chain of cylinders plus joint spheres per tube, with selection styling.
import {
  Group, Mesh, CylinderGeometry, SphereGeometry, MeshStandardMaterial, Vector3, Quaternion, Color,
} from 'three';

export const PALETTE = [
  '#4e9af1', '#f28e2b', '#59c26b', '#e15759', '#b07aa1', '#edc948', '#76b7b2',
  '#ff9da7', '#9c755f', '#8fd14f', '#5a6ff0', '#d37295', '#2fb5c9', '#c9a227',
];
export const OCCLUSION_COLOURS = { none: '#3fb950', weak: '#e3a21a', strong: '#f0524f' };

export function tubeColour(id) {
  const n = PALETTE.length;
  return PALETTE[((Math.round(id) % n) + n) % n];
}

const UNIT_CYL = new CylinderGeometry(1, 1, 1, 20, 1, true);
const UNIT_SPHERE = new SphereGeometry(1, 16, 12);
const Y = new Vector3(0, 1, 0);

function cylinderMesh(c, mat) {
  const dir = new Vector3().subVectors(c.end, c.start);
  const len = dir.length();
  const mesh = new Mesh(UNIT_CYL, mat);
  mesh.position.addVectors(c.start, c.end).multiplyScalar(0.5);
  if (len > 1e-9) mesh.quaternion.copy(new Quaternion().setFromUnitVectors(Y, dir.divideScalar(len)));
  mesh.scale.set(c.radius, len, c.radius);
  return mesh;
}

function sphereMesh(p, r, mat) {
  const mesh = new Mesh(UNIT_SPHERE, mat);
  mesh.position.copy(p);
  mesh.scale.setScalar(r);
  return mesh;
}

/** Group of one tube; every mesh carries userData.tubeId for picking. */
export function buildTube(tube) {
  const mat = new MeshStandardMaterial({ color: tubeColour(tube.id), roughness: 0.45, metalness: 0.1 });
  const group = new Group();
  group.userData = { tubeId: tube.id, tube, material: mat };
  for (const c of tube.cylinders) {
    group.add(cylinderMesh(c, mat));
    group.add(sphereMesh(c.start, c.radius, mat), sphereMesh(c.end, c.radius, mat));
  }
  group.traverse((o) => { o.userData.tubeId = tube.id; });
  return group;
}

export function buildTubes(tubes) {
  const group = new Group();
  group.name = 'tubes';
  for (const t of tubes) group.add(buildTube(t));
  return group;
}

/** Apply colour mode and selection/hover highlighting to every tube. */
export function styleTubes(group, { selectedId, hoverId, byOcclusion, ghost }) {
  for (const g of group.children) {
    const { tube, material: m } = g.userData;
    const base = new Color(byOcclusion ? OCCLUSION_COLOURS[tube.occlusion] : tubeColour(tube.id));
    const dim = selectedId != null && (tube.id !== selectedId || ghost);
    m.color.copy(dim ? base.clone().lerp(new Color(0x6b7280), 0.55) : base);
    m.transparent = dim;
    m.opacity = dim ? 0.45 : 1;
    m.depthWrite = !dim;
    const glow = tube.id === selectedId && !ghost ? 0.55 : tube.id === hoverId ? 0.3 : 0;
    m.emissive.copy(base).multiplyScalar(glow);
    m.needsUpdate = true;
  }
}

/** A copy of a tube for carrying along a trajectory (own, bright material). */
export function carriedTube(tube) {
  const g = buildTube(tube);
  g.userData.material.emissive.set(tubeColour(tube.id)).multiplyScalar(0.35);
  g.traverse((o) => { o.userData.tubeId = undefined; });
  g.name = 'carried';
  return g;
}

export function tubeCentre(tube) {
  const pts = tube.cylinders.flatMap((c) => [c.start, c.end]);
  const s = new Vector3();
  pts.forEach((p) => s.add(p));
  return pts.length ? s.divideScalar(pts.length) : s;
}
