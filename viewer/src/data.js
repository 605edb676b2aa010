// Decoding of the embedded tubepick-view/1 JSON and small pose helpers.
import { Quaternion, Vector3, Matrix4 } from 'three';

export const FORMAT = 'tubepick-view/1';

/** Number from a proto3 JSON value (uint64 arrive as strings); default 0. */
export function num(v) {
  const n = typeof v === 'string' ? Number(v) : v;
  return Number.isFinite(n) ? n : 0;
}

export function vec3(v) {
  if (Array.isArray(v)) return new Vector3(num(v[0]), num(v[1]), num(v[2]));
  return new Vector3(num(v?.x), num(v?.y), num(v?.z));
}

function quat(q) {
  const r = Array.isArray(q)
    ? new Quaternion(num(q[0]), num(q[1]), num(q[2]), num(q[3]))
    : new Quaternion(num(q?.x), num(q?.y), num(q?.z), num(q?.w));
  return r.lengthSq() < 1e-12 ? new Quaternion() : r.normalize();
}

/** {position, orientation} (proto or array form) -> {p: Vector3, q: Quaternion}. */
export function pose(src) {
  return { p: vec3(src?.position), q: quat(src?.orientation) };
}

export function poseMatrix(ps) {
  return new Matrix4().compose(ps.p, ps.q, new Vector3(1, 1, 1));
}

/** Read the JSON text of the page's data script; throws with a readable message. */
export function parseData(text) {
  if (!text || !text.trim()) throw new Error('no data: the page has no tubepick-data script content');
  let data;
  try { data = JSON.parse(text); } catch (e) { throw new Error(`data is not valid JSON: ${e.message}`); }
  if (!data || typeof data !== 'object') throw new Error('data is not a JSON object');
  if (data.format !== FORMAT) {
    throw new Error(`unsupported data format "${data.format}" (expected "${FORMAT}")`);
  }
  if (!Array.isArray(data.frames) || data.frames.length === 0) throw new Error('data has no frames');
  return data;
}

/** Base64 -> Float32Array of xyz triples (little-endian float32). */
export function decodeXyz(b64) {
  let bin;
  try { bin = atob(String(b64).replace(/\s+/g, '')); } catch { throw new Error('cloud.xyz is not valid base64'); }
  if (bin.length % 12 !== 0) throw new Error(`cloud.xyz has ${bin.length} bytes, not a multiple of 12 (x,y,z float32)`);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  const view = new DataView(bytes.buffer);
  const out = new Float32Array(bin.length / 4);
  for (let i = 0; i < out.length; i++) out[i] = view.getFloat32(i * 4, true);
  return out;
}

/** The tubes of a frame: plan.tubes, else plan.modeling.tubes, else modeling.tubes. */
export function frameTubes(frame) {
  const plan = frame?.plan;
  if (plan) return nonEmpty(plan.tubes) || nonEmpty(plan.modeling?.tubes) || [];
  return nonEmpty(frame?.modeling?.tubes) || [];
}

function nonEmpty(a) { return Array.isArray(a) && a.length ? a : null; }

export function framePlans(frame) {
  return Array.isArray(frame?.plan?.plans) ? frame.plan.plans : [];
}

/** The linear reading of a tube without a graph: one branch over all cylinders, first start to last end. */
function linearGraph(cylinders) {
  if (!cylinders.length) return { nodes: [], branches: [] };
  const nodes = [cylinders[0].start.clone(), cylinders[cylinders.length - 1].end.clone()];
  return { nodes, branches: [{ from: 0, to: 1, first: 0, count: cylinders.length }] };
}

/** Why a branch does not fit its tube (node or cylinder index out of range), or null. */
function branchProblem(b, nodeCount, cylinderCount) {
  if (b.from >= nodeCount || b.to >= nodeCount) return `node ${Math.max(b.from, b.to)} of ${nodeCount}`;
  if (b.count < 1 || b.first + b.count > cylinderCount) return `cylinders [${b.first}, ${b.first + b.count}) of ${cylinderCount}`;
  return null;
}

/**
 * The tube's graph: nodes (Vector3) and branches {from, to, first, count} (proto3 JSON omits zeros);
 * without branches the linear reading. Branches that do not fit are dropped with a problem each.
 */
function tubeGraph(t, id, cylinders, problems) {
  if (!nonEmpty(t.branches)) return linearGraph(cylinders);
  const nodes = (t.nodes || []).map((n) => vec3(n?.position));
  const branches = [];
  t.branches.forEach((b, i) => {
    const br = { from: num(b?.fromNode), to: num(b?.toNode), first: num(b?.firstCylinder), count: num(b?.cylinderCount) };
    const bad = branchProblem(br, nodes.length, cylinders.length);
    if (bad) problems.push(`tube ${id}: branch ${i} ignored: ${bad}`); else branches.push(br);
  });
  return { nodes, branches };
}

/** Branches per node (a node's degree). */
function nodeDegrees(nodeCount, branches) {
  const deg = new Array(nodeCount).fill(0);
  for (const b of branches) { deg[b.from]++; deg[b.to]++; }
  return deg;
}

function normTube(t, problems) {
  const cylinders = (t.cylinders || []).map((c) => ({
    start: vec3(c.start), end: vec3(c.end), radius: num(c.radius),
    segmentId: num(c.segmentId), inlierCount: num(c.inlierCount),
  }));
  const sum = cylinders.reduce((s, c) => s + c.start.distanceTo(c.end), 0);
  const id = num(t.id);
  const { nodes, branches } = tubeGraph(t, id, cylinders, problems);
  const degrees = nodeDegrees(nodes.length, branches);
  return {
    id, cylinders, length: t.length != null ? num(t.length) : sum,
    occlusion: occlusionClass(t.occlusion), occludedJointCount: num(t.occludedJointCount),
    nodes, branches, degrees, junctions: degrees.filter((d) => d >= 3).length,
  };
}

const plural = (k, one, many) => `${k} ${k === 1 ? one : many}`;

/** Branches and junctions in words: "linear" (one branch, no junction), "5 branches, 2 junctions", short "5 br, 2 jn". */
export function graphText(tube, short = false) {
  const b = tube.branches.length, j = tube.junctions;
  if (!b) return '–';
  if (b === 1 && !j) return 'linear';
  return short ? `${b} br, ${j} jn` : `${plural(b, 'branch', 'branches')}, ${plural(j, 'junction', 'junctions')}`;
}

export function occlusionClass(s) {
  const v = String(s || 'OCCLUSION_NONE').replace(/^OCCLUSION_/, '').toLowerCase();
  return ['none', 'weak', 'strong'].includes(v) ? v : 'none';
}

export function kindName(s) {
  return String(s || 'TRAJECTORY_KIND_UPWARD').replace(/^TRAJECTORY_KIND_/, '').toLowerCase().replace(/_/g, ' ');
}

/** "sure", "simulated", "unsure", or "–" for an answer without one (older servers). */
export function certaintyName(s) {
  const v = String(s || '').replace(/^PLAN_CERTAINTY_/, '').toLowerCase();
  return ['sure', 'simulated', 'unsure'].includes(v) ? v : '–';
}

function normPlan(p, index) {
  const g = p.grasp || {};
  return {
    index, tubeId: num(p.tubeId),
    tcp: pose(g.tcpPose), approach: vec3(g.approach), openingWidth: num(g.openingWidth), tilt: num(g.tilt),
    waypoints: (p.waypoints || []).map(vec3), kind: kindName(p.trajectoryKind),
    cost: { H: num(p.cost?.height), C: num(p.cost?.centre), T: num(p.cost?.trajectory), G: num(p.cost?.total) },
    displacement: num(p.simulatedDisplacement), certainty: certaintyName(p.certainty),
    place: p.placeTcpPose ? pose(p.placeTcpPose) : null,
  };
}

/** Normalised view model of one frame; decoding problems go to model.problems. */
export function frameModel(frame) {
  const problems = [];
  const plan = frame.plan || null;
  const modeling = plan ? plan.modeling || null : frame.modeling || null;
  let xyz = null;
  if (frame.cloud?.xyz) {
    try { xyz = decodeXyz(frame.cloud.xyz); } catch (e) { problems.push(e.message); }
  }
  return {
    label: String(frame.label ?? ''), note: frame.note ? String(frame.note) : '',
    error: frame.error ? String(frame.error) : '',
    chosenPlan: frame.chosen_plan == null ? null : num(frame.chosen_plan),
    cloud: xyz ? { xyz, points: num(frame.cloud.points) || xyz.length / 3, total: num(frame.cloud.total_points) } : null,
    tubes: frameTubes(frame).map((t) => normTube(t, problems)), plans: framePlans(frame).map(normPlan),
    hasPlan: !!plan, plan, modeling, problems,
  };
}
