// Raycast picking on tube meshes and screen projection helpers.
import { Raycaster, Vector2, Vector3 } from 'three';
import { screenPoint } from './scene.js';
import { tubeCentre } from './tubes.js';

const raycaster = new Raycaster();
raycaster.params.Points.threshold = 0.004; // m: a cloud point within 4 mm of the ray is hit

function aim(view, clientX, clientY) {
  const r = view.renderer.domElement.getBoundingClientRect();
  const ndc = new Vector2(((clientX - r.left) / r.width) * 2 - 1, -((clientY - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(ndc, view.camera);
}

/** Tube id under a page CSS pixel, or null. */
export function pickTube(view, tubesGroup, clientX, clientY) {
  if (!tubesGroup || !tubesGroup.visible) return null;
  aim(view, clientX, clientY);
  const hit = raycaster.intersectObjects(tubesGroup.children, true).find((h) => h.object.userData.tubeId != null);
  return hit ? hit.object.userData.tubeId : null;
}

/** Nearest cloud point along the ray under a page CSS pixel: {index, p: Vector3 (bin frame)}, or null. */
export function pickCloudPoint(view, cloud, clientX, clientY) {
  if (!cloud || !cloud.visible) return null;
  aim(view, clientX, clientY);
  const hit = raycaster.intersectObject(cloud, false)[0];
  if (!hit) return null;
  const a = cloud.userData.xyz, i = hit.index;
  return { index: i, p: new Vector3(a[3 * i], a[3 * i + 1], a[3 * i + 2]) };
}

function insideCanvas(view, s) {
  const r = view.renderer.domElement.getBoundingClientRect();
  return s && s.x > r.left + 2 && s.x < r.right - 2 && s.y > r.top + 2 && s.y < r.bottom - 2;
}

/** Screen point of a tube: the cylinder midpoint nearest its centre that is visibly this tube, else the centre. */
export function screenPointOfTube(view, tubesGroup, tube) {
  if (!tube) return null;
  view.scene.updateMatrixWorld();
  const centre = tubeCentre(tube);
  const candidates = tube.cylinders
    .map((c) => new Vector3().addVectors(c.start, c.end).multiplyScalar(0.5))
    .sort((a, b) => a.distanceTo(centre) - b.distanceTo(centre));
  for (const p of [centre, ...candidates]) {
    const s = screenPoint(view, p);
    if (insideCanvas(view, s) && pickTube(view, tubesGroup, s.x, s.y) === tube.id) return s;
  }
  return screenPoint(view, centre);
}
