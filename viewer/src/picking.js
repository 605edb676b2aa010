// Raycast picking on tube meshes and screen projection helpers.
import { Raycaster, Vector2, Vector3 } from 'three';
import { screenPoint } from './scene.js';
import { tubeCentre } from './tubes.js';

const raycaster = new Raycaster();

/** Tube id under a page CSS pixel, or null. */
export function pickTube(view, tubesGroup, clientX, clientY) {
  if (!tubesGroup || !tubesGroup.visible) return null;
  const r = view.renderer.domElement.getBoundingClientRect();
  const ndc = new Vector2(((clientX - r.left) / r.width) * 2 - 1, -((clientY - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(ndc, view.camera);
  const hit = raycaster.intersectObjects(tubesGroup.children, true).find((h) => h.object.userData.tubeId != null);
  return hit ? hit.object.userData.tubeId : null;
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
