// Static cell geometry: the bin (floor and four walls) and the placement frame.
import {
  Group, Mesh, BoxGeometry, MeshStandardMaterial, EdgesGeometry, LineSegments,
  LineBasicMaterial, BufferGeometry, Float32BufferAttribute, Sprite, SpriteMaterial,
  CanvasTexture, SRGBColorSpace,
} from 'three';
import { num, pose } from './data.js';

const WALL = 0.008;

export function buildBin(bin) {
  const [L, W, H] = (bin?.inner_size || [0.8, 0.6, 0.2]).map(num);
  const group = new Group();
  group.name = 'bin';
  const mat = new MeshStandardMaterial({
    color: 0x8a96a8, transparent: true, opacity: 0.16, depthWrite: false, roughness: 0.9,
  });
  const floorMat = new MeshStandardMaterial({ color: 0x4a5262, roughness: 1, transparent: true, opacity: 0.55, depthWrite: false });
  addBox(group, [L + 2 * WALL, W + 2 * WALL, WALL], [0, 0, -WALL / 2], floorMat);
  addBox(group, [WALL, W + 2 * WALL, H], [L / 2 + WALL / 2, 0, H / 2], mat);
  addBox(group, [WALL, W + 2 * WALL, H], [-L / 2 - WALL / 2, 0, H / 2], mat);
  addBox(group, [L, WALL, H], [0, W / 2 + WALL / 2, H / 2], mat);
  addBox(group, [L, WALL, H], [0, -W / 2 - WALL / 2, H / 2], mat);
  group.userData.size = [L, W, H];
  return group;
}

function addBox(group, size, at, mat) {
  const geo = new BoxGeometry(...size);
  const mesh = new Mesh(geo, mat);
  mesh.position.set(...at);
  mesh.renderOrder = 2;
  const edges = new LineSegments(new EdgesGeometry(geo), new LineBasicMaterial({ color: 0x9aa6b8, transparent: true, opacity: 0.45 }));
  mesh.add(edges);
  group.add(mesh);
}

/** RGB axes (x red, y green, z blue) of the given length as line segments. */
export function axes(length, opacity = 1) {
  const g = new BufferGeometry();
  g.setAttribute('position', new Float32BufferAttribute([0, 0, 0, length, 0, 0, 0, 0, 0, 0, length, 0, 0, 0, 0, 0, 0, length], 3));
  const c = [[1, 0.25, 0.25], [0.3, 0.9, 0.3], [0.3, 0.5, 1]];
  g.setAttribute('color', new Float32BufferAttribute(c.flatMap((x) => [...x, ...x]), 3));
  const line = new LineSegments(g, new LineBasicMaterial({ vertexColors: true, transparent: opacity < 1, opacity, depthTest: false }));
  line.renderOrder = 10;
  return line;
}

export function textSprite(text, colour = '#e8edf5', height = 0.03) {
  const canvas = document.createElement('canvas');
  const ctx = canvas.getContext('2d');
  const font = '600 44px system-ui, sans-serif';
  ctx.font = font;
  const w = Math.ceil(ctx.measureText(text).width) + 24;
  canvas.width = w; canvas.height = 64;
  ctx.font = font;
  ctx.fillStyle = 'rgba(20,24,31,0.75)';
  ctx.fillRect(0, 0, w, 64);
  ctx.fillStyle = colour;
  ctx.textBaseline = 'middle';
  ctx.fillText(text, 12, 34);
  const tex = new CanvasTexture(canvas);
  tex.colorSpace = SRGBColorSpace;
  const sprite = new Sprite(new SpriteMaterial({ map: tex, depthTest: false, transparent: true }));
  sprite.scale.set((height * w) / 64, height, 1);
  sprite.renderOrder = 11;
  return sprite;
}

export function buildPlacement(X_BinPlace) {
  const group = new Group();
  group.name = 'placement';
  if (!X_BinPlace) return group;
  const ps = pose(X_BinPlace);
  const frame = axes(0.1);
  frame.position.copy(ps.p);
  frame.quaternion.copy(ps.q);
  const label = textSprite('place');
  label.position.copy(ps.p).add({ x: 0, y: 0, z: 0.05 });
  label.center.set(0, 0);
  group.add(frame, label);
  return group;
}
