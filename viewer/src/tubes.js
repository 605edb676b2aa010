// Tube models: per tube its cylinders (with end spheres), the thin joints between consecutive cylinders of a
// branch, the thin links from a branch to its nodes, and a sphere at each junction (T/Y piece), with selection styling.
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

const JOINT_SCALE = 0.6; // joint and link radius / tube radius: thinner than the tube, so a joint reads as one
const JUNCTION_SCALE = 1.3; // junction sphere radius / tube radius: a T/Y piece stands out of its branches
const GAP = 1e-5; // m: cylinder ends closer than this need no joint

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

/** Thin cylinder a → b (a joint or a link) tagged with its part, or null when a and b (nearly) coincide. */
function thinMesh(a, b, radius, part, mat) {
  if (a.distanceTo(b) < GAP) return null;
  const mesh = cylinderMesh({ start: a, end: b, radius: radius * JOINT_SCALE }, mat);
  mesh.userData.part = part;
  return mesh;
}

/** Joints between consecutive cylinders of a branch, and links from its ends to its nodes. */
function branchMeshes(tube, b, mat) {
  const cyl = tube.cylinders.slice(b.first, b.first + b.count);
  const out = [];
  for (let k = 0; k + 1 < cyl.length; k++) {
    out.push(thinMesh(cyl[k].end, cyl[k + 1].start, Math.min(cyl[k].radius, cyl[k + 1].radius), 'joint', mat));
  }
  const [first, last] = [cyl[0], cyl[cyl.length - 1]];
  out.push(thinMesh(tube.nodes[b.from], first.start, first.radius, 'link', mat));
  out.push(thinMesh(last.end, tube.nodes[b.to], last.radius, 'link', mat));
  return out.filter(Boolean);
}

/** Radius of the thickest cylinder whose branch starts or ends at node i (0 when none). */
function nodeRadius(tube, i) {
  let r = 0;
  for (const b of tube.branches) {
    if (b.from === i) r = Math.max(r, tube.cylinders[b.first].radius);
    if (b.to === i) r = Math.max(r, tube.cylinders[b.first + b.count - 1].radius);
  }
  return r;
}

/** Spheres at nodes: a junction (degree ≥ 3) larger than the tube; a linked free end as round as its link. */
function nodeMeshes(tube, linked, mat) {
  const out = [];
  tube.nodes.forEach((p, i) => {
    const junction = tube.degrees[i] >= 3;
    if (!junction && !linked.has(i)) return;
    const mesh = sphereMesh(p, nodeRadius(tube, i) * (junction ? JUNCTION_SCALE : JOINT_SCALE), mat);
    mesh.userData.part = junction ? 'junction' : 'end';
    out.push(mesh);
  });
  return out;
}

/** Nodes a link reaches (their branch's end cylinder does not touch them). */
function linkedNodes(tube) {
  const s = new Set();
  for (const b of tube.branches) {
    if (tube.nodes[b.from].distanceTo(tube.cylinders[b.first].start) >= GAP) s.add(b.from);
    if (tube.nodes[b.to].distanceTo(tube.cylinders[b.first + b.count - 1].end) >= GAP) s.add(b.to);
  }
  return s;
}

/** Group of one tube; every mesh carries userData.tubeId for picking, joints/links/node spheres userData.part. */
export function buildTube(tube) {
  const mat = new MeshStandardMaterial({ color: tubeColour(tube.id), roughness: 0.45, metalness: 0.1 });
  const group = new Group();
  group.userData = { tubeId: tube.id, tube, material: mat };
  for (const c of tube.cylinders) {
    group.add(cylinderMesh(c, mat));
    group.add(sphereMesh(c.start, c.radius, mat), sphereMesh(c.end, c.radius, mat));
  }
  // one by one: Object3D.add() with no argument logs an error
  const graph = [...tube.branches.flatMap((b) => branchMeshes(tube, b, mat)), ...nodeMeshes(tube, linkedNodes(tube), mat)];
  for (const m of graph) group.add(m);
  group.traverse((o) => { o.userData.tubeId = tube.id; });
  return group;
}

/** Meshes of a tube group per part: {joint, link, junction, end} counts. */
export function partCounts(group) {
  const n = { joint: 0, link: 0, junction: 0, end: 0 };
  group.traverse((o) => { if (o.userData.part in n) n[o.userData.part]++; });
  return n;
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
