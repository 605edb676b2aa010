// Pick trajectory: keyframes from grasp pose, waypoints and place pose; sampling and playback.
import {
  BufferGeometry, Line, LineDashedMaterial, Float32BufferAttribute, Group, Points, PointsMaterial, Vector3,
} from 'three';
import { poseMatrix } from './data.js';

const SPEED = 0.35; // m/s of displayed motion
const TURN = 1.5; // rad/s of displayed rotation

/** TCP keyframes: grasp, grasp + waypoints, then lift / travel / descend to the place pose. */
export function keyframes(plan, binHeight) {
  const keys = [{ p: plan.tcp.p.clone(), q: plan.tcp.q.clone(), tag: 'grasp' }];
  for (const w of plan.waypoints) {
    if (w.lengthSq() < 1e-12) continue;
    keys.push({ p: plan.tcp.p.clone().add(w), q: plan.tcp.q.clone(), tag: 'waypoint' });
  }
  const place = plan.place;
  if (!place) return timeKeys(keys);
  const last = keys[keys.length - 1];
  const safeZ = Math.max(binHeight + 0.1, last.p.z, place.p.z + 0.12);
  if (last.p.z < safeZ - 1e-6) keys.push({ p: new Vector3(last.p.x, last.p.y, safeZ), q: last.q.clone(), tag: 'lift' });
  keys.push({ p: new Vector3(place.p.x, place.p.y, safeZ), q: place.q.clone(), tag: 'travel' });
  keys.push({ p: place.p.clone(), q: place.q.clone(), tag: 'place' });
  return timeKeys(keys);
}

function timeKeys(keys) {
  keys[0].t = 0;
  for (let i = 1; i < keys.length; i++) {
    const d = keys[i].p.distanceTo(keys[i - 1].p);
    const a = keys[i].q.angleTo(keys[i - 1].q);
    keys[i].t = keys[i - 1].t + Math.max(0.25, d / SPEED, a / TURN);
  }
  return keys;
}

/** Interpolated TCP pose at time t (linear position, slerp orientation). */
export function sample(keys, t) {
  if (t <= 0 || keys.length === 1) return { p: keys[0].p.clone(), q: keys[0].q.clone() };
  for (let i = 1; i < keys.length; i++) {
    if (t <= keys[i].t) {
      const a = keys[i - 1], b = keys[i];
      const s = (t - a.t) / (b.t - a.t);
      return { p: a.p.clone().lerp(b.p, s), q: a.q.clone().slerp(b.q, s) };
    }
  }
  const z = keys[keys.length - 1];
  return { p: z.p.clone(), q: z.q.clone() };
}

export function pathObject(keys) {
  const group = new Group();
  group.name = 'trajectory';
  const geo = new BufferGeometry();
  geo.setAttribute('position', new Float32BufferAttribute(keys.flatMap((k) => [k.p.x, k.p.y, k.p.z]), 3));
  const line = new Line(geo, new LineDashedMaterial({ color: 0x7dd3fc, dashSize: 0.02, gapSize: 0.012, transparent: true, opacity: 0.9 }));
  line.computeLineDistances();
  const dots = new Points(geo, new PointsMaterial({ color: 0xe0f2fe, size: 6, sizeAttenuation: false }));
  group.add(line, dots);
  return group;
}

/** Playback state for one plan: moves the gripper and the carried tube. */
export function createPlayer(keys, gripper, carried, onUpdate) {
  const X0inv = poseMatrix(keys[0]).invert();
  const player = { keys, duration: keys[keys.length - 1].t, t: 0, playing: false };
  player.set = (t) => {
    player.t = Math.min(Math.max(t, 0), player.duration);
    const x = sample(keys, player.t);
    gripper.position.copy(x.p);
    gripper.quaternion.copy(x.q);
    carried.matrixAutoUpdate = false;
    carried.matrix.multiplyMatrices(poseMatrix(x), X0inv);
    carried.matrixWorldNeedsUpdate = true;
    carried.visible = player.t > 0;
    onUpdate(player);
  };
  let last = null;
  player.tick = (time) => {
    if (!player.playing) { last = null; return false; }
    if (last != null) player.set(player.t + (time - last) / 1000);
    last = time;
    if (player.t >= player.duration) player.playing = false;
    return player.playing;
  };
  player.set(0);
  return player;
}
