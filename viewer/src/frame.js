// Per-frame 3-D content: cloud, tubes, grasp markers; and the selected plan's gripper, carried tube, path.
import { Group } from 'three';
import { buildCloud } from './cloud.js';
import { buildTubes, carriedTube, tubeColour } from './tubes.js';
import { buildGripper, buildMarker } from './gripper.js';
import { keyframes, pathObject, createPlayer } from './trajectory.js';

const MAX_MARKERS = 20;

export function buildFrameObjects(model, dims, pointSize) {
  const group = new Group();
  group.name = 'frame';
  const cloud = model.cloud ? buildCloud(model.cloud.xyz, pointSize) : null;
  const tubes = buildTubes(model.tubes);
  const markers = new Group();
  markers.name = 'grasps';
  for (const p of model.plans.slice(0, MAX_MARKERS)) {
    const g = buildMarker(dims, p.openingWidth, tubeColour(p.tubeId));
    g.position.copy(p.tcp.p);
    g.quaternion.copy(p.tcp.q);
    g.userData.planIndex = p.index;
    markers.add(g);
  }
  const selection = new Group();
  selection.name = 'selection';
  group.add(...[cloud, tubes, markers, selection].filter(Boolean));
  return { group, cloud, tubes, markers, selection, player: null };
}

/** Gripper + carried tube + path for one plan; returns the player. */
export function showPlan(objs, plan, tube, dims, binHeight, onUpdate) {
  clearPlan(objs);
  const keys = keyframes(plan, binHeight);
  const gripper = buildGripper(dims, plan.openingWidth);
  const carried = tube ? carriedTube(tube) : new Group();
  const path = pathObject(keys);
  const sel = objs.selection;
  sel.add(gripper, carried, path);
  sel.userData = { gripper, carried, path };
  objs.markers.children.forEach((m) => { m.visible = m.userData.planIndex !== plan.index; });
  objs.player = createPlayer(keys, gripper, carried, onUpdate);
  return objs.player;
}

export function clearPlan(objs) {
  objs.player = null;
  objs.markers.children.forEach((m) => { m.visible = true; });
  for (const o of [...objs.selection.children]) { objs.selection.remove(o); dispose(o); }
  objs.selection.userData = {};
}

export function dispose(obj) {
  obj.traverse((o) => {
    o.geometry?.dispose(); // shared unit geometries are simply re-uploaded on next use
    const mats = Array.isArray(o.material) ? o.material : o.material ? [o.material] : [];
    mats.forEach((m) => { m.map?.dispose(); m.dispose(); });
  });
}
