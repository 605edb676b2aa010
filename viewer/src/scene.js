// three.js renderer, camera, orbit controls, lights and an on-demand render loop.
import {
  WebGLRenderer, Scene, PerspectiveCamera, Color, AmbientLight, DirectionalLight,
  HemisphereLight, Group, Box3, GridHelper,
} from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

export const BACKGROUND = 0x161a21;

export function createView(container) {
  const renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.setClearColor(BACKGROUND, 1);
  container.appendChild(renderer.domElement);

  const scene = new Scene();
  scene.background = new Color(BACKGROUND);
  const camera = new PerspectiveCamera(40, 1, 0.005, 50);
  camera.up.set(0, 0, 1);
  addLights(scene);
  scene.add(floorGrid());

  const controls = new OrbitControls(camera, renderer.domElement);
  controls.enableDamping = false;
  controls.screenSpacePanning = true;

  const view = { renderer, scene, camera, controls, container, root: new Group(), onFrame: [] };
  scene.add(view.root);
  view.requestRender = makeLoop(view);
  controls.addEventListener('change', view.requestRender);
  const resize = () => resizeView(view);
  new ResizeObserver(resize).observe(container);
  resize();
  return view;
}

function addLights(scene) {
  scene.add(new HemisphereLight(0xdde6ff, 0x303030, 1.4));
  scene.add(new AmbientLight(0xffffff, 0.35));
  const key = new DirectionalLight(0xffffff, 1.8);
  key.position.set(1.5, -2, 3);
  scene.add(key);
  const fill = new DirectionalLight(0xaabbff, 0.6);
  fill.position.set(-2, 1.5, 1);
  scene.add(fill);
}

function floorGrid() {
  const grid = new GridHelper(3, 30, 0x3a4250, 0x262c36);
  grid.rotation.x = Math.PI / 2; // GridHelper lies in xz; the bin frame is z-up
  grid.position.z = -0.001;
  grid.name = 'grid';
  return grid;
}

function resizeView(view) {
  const { clientWidth: w, clientHeight: h } = view.container;
  if (!w || !h) return;
  view.renderer.setSize(w, h, false);
  view.renderer.domElement.style.width = '100%';
  view.renderer.domElement.style.height = '100%';
  view.camera.aspect = w / h;
  view.camera.updateProjectionMatrix();
  view.requestRender();
}

/** Render only when something changed; onFrame callbacks may keep it going (animation). */
function makeLoop(view) {
  let pending = false;
  const tick = (time) => {
    pending = false;
    let again = false;
    for (const f of view.onFrame) again = f(time) || again;
    view.renderer.render(view.scene, view.camera);
    if (again) request();
  };
  const request = () => {
    if (!pending) { pending = true; requestAnimationFrame(tick); }
  };
  return request;
}

export function boxOf(objects) {
  const box = new Box3();
  for (const o of objects) if (o) box.expandByObject(o);
  return box;
}

/** Page CSS pixel of a bin-frame point, or null when behind the camera. */
export function screenPoint(view, p) {
  const v = p.clone().project(view.camera);
  if (v.z > 1) return null;
  const r = view.renderer.domElement.getBoundingClientRect();
  return { x: r.left + ((v.x + 1) / 2) * r.width, y: r.top + ((1 - v.y) / 2) * r.height };
}
