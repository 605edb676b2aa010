#!/usr/bin/env node
// Headless-Chromium check of a tubepick viewer page (file path, file:// or http URL), or of a call list page.
//   node viewer/test/check-page.mjs --page PATH_OR_URL --screenshot OUT.png [--list] [--expect-warning CODE]
import { chromium } from 'playwright-core';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL, fileURLToPath } from 'node:url';
import { parseArgs } from 'node:util';

const BACKGROUND = [0x16, 0x1a, 0x21]; // scene.js BACKGROUND
const LAUNCH_ARGS = ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox'];

let failures = 0;
function check(ok, name, detail = '') {
  if (!ok) failures++;
  console.log(`${ok ? 'PASS' : 'FAIL'} ${name}${detail ? ` — ${detail}` : ''}`);
  return ok;
}

function toUrl(p) {
  return /^[a-z][a-z0-9+.-]*:\/\//i.test(p) ? p : pathToFileURL(resolve(p)).href;
}

async function fetchText(url) {
  if (url.startsWith('file:')) return readFileSync(fileURLToPath(url), 'utf8');
  const r = await fetch(url);
  if (!r.ok) throw new Error(`GET ${url}: HTTP ${r.status}`);
  return r.text();
}

const num = (v) => (Number.isFinite(Number(v)) ? Number(v) : 0);
const nonEmpty = (a) => (Array.isArray(a) && a.length ? a : null);

function pageData(html) {
  const m = html.match(/<script type="application\/json" id="tubepick-data">([\s\S]*?)<\/script>/);
  if (!m) throw new Error('no <script type="application/json" id="tubepick-data"> in the page');
  return JSON.parse(m[1]);
}

/**
 * A tube's graph from its JSON: branch and junction (node of ≥ 3 branches) counts and the junction positions.
 * proto3 JSON omits zeros (a missing fromNode is node 0); a tube with no branches is linear: 1 branch, 2 free ends.
 */
function tubeGraph(t) {
  const cylinders = Array.isArray(t.cylinders) ? t.cylinders.length : 0;
  if (!nonEmpty(t.branches)) return { branches: cylinders ? 1 : 0, junctions: 0, junctionPoints: [] };
  const degree = new Map();
  const bump = (i) => degree.set(num(i), (degree.get(num(i)) || 0) + 1);
  for (const b of t.branches) { bump(b.fromNode); bump(b.toNode); }
  const at = [...degree].filter(([, d]) => d >= 3).map(([i]) => i);
  const pos = (i) => ['x', 'y', 'z'].map((k) => num(t.nodes?.[i]?.position?.[k]));
  return { branches: t.branches.length, junctions: at.length, junctionPoints: at.map(pos) };
}

/** Expected per-frame counts and grasp positions, computed independently from the page's embedded JSON. */
function expectedFrames(data) {
  return data.frames.map((f) => {
    const tubes = f.plan ? nonEmpty(f.plan.tubes) || nonEmpty(f.plan.modeling?.tubes) || [] : nonEmpty(f.modeling?.tubes) || [];
    const plans = Array.isArray(f.plan?.plans) ? f.plan.plans : [];
    const warnings = ((f.plan ? f.plan.modeling : f.modeling)?.warnings || []).map((w) => w.code || '');
    const grasp = (p) => ['x', 'y', 'z'].map((k) => num(p.grasp?.tcpPose?.position?.[k]));
    return { tubeIds: tubes.map((t) => num(t.id)), planTubeIds: plans.map((p) => num(p.tubeId)), grasps: plans.map(grasp),
      certainties: plans.map((p) => String(p.certainty || '').replace(/^PLAN_CERTAINTY_/, '').toLowerCase() || '–'),
      graphs: tubes.map(tubeGraph), warnings };
  });
}

/** Bin inner size [L, W, H] (viewer default when absent). */
const binSize = (data) => (data.cell?.bin?.inner_size || [0.8, 0.6, 0.2]).map(num);

const api = (page, expr) => page.evaluate(`(() => { const v = window.tubepickViewer; return ${expr}; })()`);
const settle = (page) => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

const canvasPng = (page) => page.locator('#view canvas').screenshot();

/** Defines window.__checkPixels(b64) in the page: the RGBA bytes of a PNG, decoded by the browser itself. */
async function installPixelDecoder(page) {
  await page.evaluate(() => {
    window.__checkPixels = async (b64) => {
      const img = new Image();
      img.src = `data:image/png;base64,${b64}`;
      await img.decode();
      const c = document.createElement('canvas');
      c.width = img.width; c.height = img.height;
      const ctx = c.getContext('2d', { willReadFrequently: true });
      ctx.drawImage(img, 0, 0);
      return { data: ctx.getImageData(0, 0, c.width, c.height).data, width: c.width, height: c.height };
    };
  });
}

/** Percentage of pixels whose RGB differs by more than 24 (sum of abs) between two PNGs of equal size. */
async function pixelDiff(page, a, b) {
  await installPixelDecoder(page);
  return page.evaluate(async ([ba, bb]) => {
    const [da, db] = [(await window.__checkPixels(ba)).data, (await window.__checkPixels(bb)).data];
    if (da.length !== db.length) return 100;
    let n = 0;
    for (let i = 0; i < da.length; i += 4) if (Math.abs(da[i] - db[i]) + Math.abs(da[i + 1] - db[i + 1]) + Math.abs(da[i + 2] - db[i + 2]) > 24) n++;
    return (100 * n) / (da.length / 4);
  }, [a.toString('base64'), b.toString('base64')]);
}

async function checkCanvas(page) {
  const png = await canvasPng(page);
  await installPixelDecoder(page);
  const stats = await page.evaluate(async ({ b64, bg }) => {
    const c = await window.__checkPixels(b64);
    const d = c.data;
    const colours = new Set();
    let differ = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) differ++;
      colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
    }
    return { w: c.width, h: c.height, differ, total: d.length / 4, colours: colours.size };
  }, { b64: png.toString('base64'), bg: BACKGROUND });
  const pct = (100 * stats.differ) / stats.total;
  check(pct >= 2 && stats.colours >= 20, 'canvas not blank',
    `${stats.w}x${stats.h} px, ${pct.toFixed(1)} % differ from background, ${stats.colours} distinct colours (need ≥ 2 %, ≥ 20)`);
}

async function rowClass(page, sel) {
  return page.locator(sel).evaluate((e) => e.className).catch(() => null);
}

async function checkPlanClick(page, f, k) {
  await page.locator(`#plans tr[data-plan-index="${k}"]`).click();
  const [sp, st] = await Promise.all([api(page, 'v.selectedPlan'), api(page, 'v.selectedTubeId')]);
  const want = f.planTubeIds[k];
  const cls = await rowClass(page, `#tubes tr[data-tube-id="${want}"]`);
  const planCls = await rowClass(page, `#plans tr[data-plan-index="${k}"]`);
  check(sp === k && st === want && /\bselected\b/.test(cls || '') && /\bselected\b/.test(planCls || ''),
    `  click plan row ${k}`, `selectedPlan=${sp} selectedTubeId=${st} (want ${k}, ${want}); tube row class "${cls}"`);
  await checkPlanDetails(page, f, k);
}

const GRASP_TOL = 0.0005; // m: the box shows 3 decimals

async function checkPlanDetails(page, f, k) {
  const shown = await page.evaluate(() => ['x', 'y', 'z'].map((a) => document.querySelector(`#plan-details [data-field="grasp-${a}"]`)?.textContent ?? null));
  const want = f.grasps[k];
  const err = Math.max(...shown.map((t, i) => (t == null ? Infinity : Math.abs(Number(t) - want[i]))));
  check(err <= GRASP_TOL, `  plan ${k} details: grasp x/y/z`,
    `shown (${shown.join(', ')}) vs JSON (${want.map((v) => v.toFixed(4)).join(', ')}), max error ${Number.isFinite(err) ? err.toFixed(5) : 'missing'} m (≤ ${GRASP_TOL})`);
  const certainty = await page.evaluate(() => document.querySelector('#plan-details [data-field="certainty"]')?.textContent ?? null);
  check(certainty === f.certainties[k], `  plan ${k} details: certainty`, `shown "${certainty}" vs JSON "${f.certainties[k]}"`);
}

async function checkTubeClick(page, f, id) {
  await page.locator(`#tubes tr[data-tube-id="${id}"]`).click();
  const st = await api(page, 'v.selectedTubeId');
  const cls = await rowClass(page, `#tubes tr[data-tube-id="${id}"]`);
  const marked = await page.locator('#plans tr.of-tube').count();
  const want = f.planTubeIds.filter((t) => t === id).length;
  check(st === id && /\bselected\b/.test(cls || '') && marked === want, `  click tube row ${id}`,
    `selectedTubeId=${st}, row class "${cls}", plans marked ${marked} (want ${want})`);
}

async function checkCanvasPick(page, id) {
  await page.keyboard.press('Escape');
  const cleared = await api(page, 'v.selectedTubeId');
  const pt = await api(page, `v.screenPointOfTube(${JSON.stringify(id)})`);
  if (!check(pt && Number.isFinite(pt.x) && cleared === null, `  3-D pick tube ${id}: screen point`,
    `Esc cleared selection: ${cleared === null}; point ${pt ? `${pt.x.toFixed(0)},${pt.y.toFixed(0)}` : 'none'}`)) return;
  await page.mouse.move(pt.x, pt.y);
  await page.mouse.click(pt.x, pt.y);
  await settle(page);
  const st = await api(page, 'v.selectedTubeId');
  const exact = st === id;
  check(st !== null, `  3-D pick tube ${id}`, `clicked (${pt.x.toFixed(0)}, ${pt.y.toFixed(0)}) → selectedTubeId=${st}${exact ? '' : ' (occluded: another tube picked)'}`);
}

/** The shape cell of a tube row: "linear" → 1 branch, 0 junctions; "5 br, 2 jn"; "–" (no cylinders) → 0, 0. */
function parseGraphCell(text) {
  const t = (text || '').trim();
  if (t === 'linear') return { branches: 1, junctions: 0 };
  if (t === '–') return { branches: 0, junctions: 0 };
  const m = t.match(/^(\d+) br, (\d+) jn$/);
  return m ? { branches: Number(m[1]), junctions: Number(m[2]) } : null;
}

/** Per tube: branches and junctions in its table row and in tubeGraph(id) (read and drawn) equal the JSON's. */
async function checkGraphs(page, f, i) {
  const got = await page.evaluate((ids) => ids.map((id) => ({
    cell: document.querySelector(`#tubes tr[data-tube-id="${id}"] [data-field="graph"]`)?.textContent ?? null,
    api: window.tubepickViewer.tubeGraph?.(id) ?? null, // a bundle without it fails below, not the run
  })), f.tubeIds);
  const bad = [], badDrawn = [];
  got.forEach((g, k) => {
    const want = f.graphs[k], id = f.tubeIds[k], shown = parseGraphCell(g.cell);
    const same = (x) => x && x.branches === want.branches && x.junctions === want.junctions;
    if (!same(shown) || !same(g.api)) {
      bad.push(`tube ${id}: row ${g.cell == null ? 'cell missing' : `"${g.cell}"`}, tubeGraph ${g.api ? `${g.api.branches}/${g.api.junctions}` : 'missing'}, JSON ${want.branches}/${want.junctions}`);
    }
    if (g.api?.drawn.junction !== want.junctions) badDrawn.push(`tube ${id}: ${g.api ? g.api.drawn.junction : 'no'} spheres, JSON ${want.junctions}`);
  });
  const branched = f.graphs.filter((g) => g.branches > 1);
  const sum = (key) => f.graphs.reduce((s, g) => s + g[key], 0);
  const some = (list) => list.slice(0, 6).join('; ') + (list.length > 6 ? `; + ${list.length - 6} more` : '');
  check(!bad.length, `frame ${i + 1}: branches and junctions per tube`, bad.length ? some(bad)
    : `${f.tubeIds.length} tube rows and tubeGraph() match the JSON: ${!f.tubeIds.length ? 'no tubes' : branched.length
      ? `${branched.length} branched (${sum('branches')} branches, ${sum('junctions')} junctions in all)` : 'all linear'}`);
  check(!badDrawn.length, `frame ${i + 1}: a junction sphere per junction`, badDrawn.length ? some(badDrawn)
    : `${sum('junctions')} drawn`);
}

/** A click on a junction node (projected from the JSON) selects its tube; the first unoccluded one of up to 12 counts. */
async function checkJunctionPick(page, f) {
  const tries = f.graphs.flatMap((g, k) => g.junctionPoints.map((p) => ({ id: f.tubeIds[k], p }))).slice(0, 12);
  if (!tries.length) return;
  for (const { id, p } of tries) {
    const s = await api(page, `v.screenPoint(${JSON.stringify(p)})`);
    const onCanvas = await page.evaluate(([x, y]) => document.elementFromPoint(x, y)?.tagName === 'CANVAS', [s.x, s.y]);
    if (!onCanvas) continue;
    await page.keyboard.press('Escape');
    await page.mouse.click(s.x, s.y);
    await settle(page);
    if (await api(page, 'v.selectedTubeId') !== id) continue;
    check(true, `  3-D pick at a junction of tube ${id}`, `clicked (${s.x.toFixed(0)}, ${s.y.toFixed(0)}) → selectedTubeId=${id}`);
    return;
  }
  check(false, '  3-D pick at a junction', `none of ${tries.length} junction nodes selected its tube (all occluded or off the canvas)`);
}

async function checkFrame(page, f, i) {
  await api(page, `v.showFrame(${i})`);
  await settle(page);
  const got = await page.evaluate(() => {
    const v = window.tubepickViewer;
    return { idx: v.frameIndex, tubes: v.tubeCount(), plans: v.planCount(),
      tubeRows: document.querySelectorAll('#tubes tr[data-tube-id]').length,
      planRows: document.querySelectorAll('#plans tr[data-plan-index]').length,
      warnings: [...document.querySelectorAll('#frame-section .frame-warning')].map((e) => e.dataset.code) };
  });
  check(got.warnings.join(',') === f.warnings.join(','), `frame ${i + 1}: modeling warnings shown`,
    `page [${got.warnings}], JSON [${f.warnings}]`);
  const nt = f.tubeIds.length, np = f.planTubeIds.length;
  check(got.idx === i && got.tubes === nt && got.tubeRows === nt && got.plans === np && got.planRows === np,
    `frame ${i + 1}: counts`, `tubeCount ${got.tubes}, tube rows ${got.tubeRows} (JSON ${nt}); planCount ${got.plans}, plan rows ${got.planRows} (JSON ${np})`);
  await checkGraphs(page, f, i);
  const planIdx = [...new Set([0, np - 1])].filter((k) => k >= 0 && k < np);
  for (const k of planIdx) await checkPlanClick(page, f, k);
  const tubeIds = [f.tubeIds[0], f.planTubeIds[0], f.tubeIds[nt - 1]].filter((x) => x !== undefined && f.tubeIds.includes(x));
  for (const id of new Set(tubeIds)) await checkTubeClick(page, f, id);
  if (nt) await checkCanvasPick(page, np ? f.planTubeIds[0] : f.tubeIds[0]);
  await checkJunctionPick(page, f);
}

const PRESETS = ['top', 'front', 'side', '3/4'];
const PRESET_DIFF = 5; // % of canvas pixels that must change between consecutive presets

const camera = (page) => api(page, 'v.camera()');
const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);

async function checkTopView(page, [L, W, H]) {
  const { position: p, target: t } = await camera(page);
  const d = [t[0] - p[0], t[1] - p[1], t[2] - p[2]];
  const down = d[2] / Math.hypot(...d);
  check(p[2] > H && Math.abs(p[0]) <= L / 4 && Math.abs(p[1]) <= W / 4 && down < -0.999, '  preset top: camera above the bin',
    `camera (${p.map((v) => v.toFixed(3)).join(', ')}) m: z > wall height ${H}, |x| ≤ ${L / 4}, |y| ≤ ${W / 4}; view direction z ${down.toFixed(4)} (< −0.999)`);
}

/** Preset buttons: each changes the canvas; top looks straight down at the bin; keys and orbiting afterwards work. */
async function checkPresets(page, bin) {
  await page.mouse.move(1590, 890); // off the canvas: no hover tooltip or marker in the screenshots
  const boot = await camera(page);
  const first = await api(page, 'v.cameraPreset');
  check(first === '3/4', 'camera preset at boot', `cameraPreset=${first}`);
  let prev = await canvasPng(page);
  for (const name of PRESETS) {
    await page.locator(`#view-presets button[data-preset="${name}"]`).click();
    await settle(page);
    const png = await canvasPng(page);
    const diff = await pixelDiff(page, prev, png);
    const [now, cls] = [await api(page, 'v.cameraPreset'), await rowClass(page, `#view-presets button[data-preset="${name}"]`)];
    check(now === name && /\bactive\b/.test(cls || '') && diff >= PRESET_DIFF, `  preset ${name}`,
      `cameraPreset=${now}, button class "${cls}", ${diff.toFixed(1)} % of pixels changed (need ≥ ${PRESET_DIFF} %)`);
    if (name === 'top') await checkTopView(page, bin);
    prev = png;
  }
  const back = dist((await camera(page)).position, boot.position);
  check(back < 1e-6, '  preset 3/4 restores the boot framing', `camera ${back.toExponential(1)} m from the boot position`);
  await checkPresetKeysAndOrbit(page);
}

async function checkPresetKeysAndOrbit(page) {
  await page.keyboard.press('2');
  const key = await api(page, 'v.cameraPreset');
  const before = (await camera(page)).position;
  const box = await page.locator('#view canvas').boundingBox();
  const [x, y] = [box.x + box.width * 0.5, box.y + box.height * 0.85];
  await page.mouse.move(x, y);
  await page.mouse.down();
  await page.mouse.move(x + 120, y - 40, { steps: 6 });
  await page.mouse.up();
  await settle(page);
  const moved = dist((await camera(page)).position, before);
  const after = await api(page, 'v.cameraPreset');
  check(key === 'top' && moved > 0.05 && after === null, '  key 2 → top, then orbit by mouse drag',
    `cameraPreset after key ${key}; drag moved the camera ${moved.toFixed(3)} m (> 0.05), cameraPreset then ${after}`);
  await page.keyboard.press('1');
  check(await api(page, 'v.cameraPreset') === '3/4', '  key 1 → 3/4', `cameraPreset=${await api(page, 'v.cameraPreset')}`);
}

/** Hover the cloud on a grid until the tooltip shows a point; that point must project under the mouse. */
async function checkCloudHover(page) {
  const box = await page.locator('#view canvas').boundingBox();
  for (let i = 0; i < 25; i++) {
    const x = box.x + box.width * (0.3 + 0.1 * (i % 5)), y = box.y + box.height * (0.3 + 0.1 * Math.floor(i / 5));
    await page.mouse.move(x, y);
    await page.waitForTimeout(90);
    const tip = await page.evaluate(() => { const t = document.getElementById('tooltip'); return { point: t.dataset.point, text: t.textContent, shown: t.style.display }; });
    if (!tip.point) continue;
    const p = tip.point.split(',').map(Number);
    const s = await api(page, `v.screenPoint(${JSON.stringify(p)})`);
    const off = Math.hypot(s.x - x, s.y - y);
    check(off <= 8 && tip.shown === 'block' && /x -?\d+\.\d{3}/.test(tip.text), 'cloud hover: point coordinates in the tooltip',
      `mouse (${x.toFixed(0)}, ${y.toFixed(0)}) → "${tip.text}"; the point projects ${off.toFixed(1)} px from the mouse (≤ 8)`);
    await page.mouse.move(1590, 890);
    return;
  }
  check(false, 'cloud hover: point coordinates in the tooltip', 'no cloud point found under 25 grid positions');
}

async function exercise(page, frames) {
  for (const m of ['segment', 'tube', 'height']) await api(page, `v.setColourMode('${m}')`);
  await settle(page);
  const withPlan = frames.findIndex((f) => f.planTubeIds.length);
  if (withPlan >= 0) {
    await api(page, `v.showFrame(${withPlan})`);
    await page.click('#play');
    await page.waitForTimeout(700);
    await settle(page);
  }
  if (frames.length > 1) {
    await api(page, 'v.showFrame(0)');
    await page.locator('#view canvas').click({ position: { x: 5, y: 5 } });
    await page.keyboard.press('ArrowRight');
    const idx = await api(page, 'v.frameIndex');
    check(idx === 1, 'keyboard → steps to the next frame', `frameIndex=${idx}`);
  }
}

async function checkViewerPage(page, url, consoleErrors, expectWarning) {
  const data = pageData(await fetchText(url));
  const frames = expectedFrames(data);
  if (page.url() !== url) await page.goto(url, { waitUntil: 'load' });
  const t0 = Date.now();
  const ready = await page.waitForFunction(() => window.tubepickViewer && window.tubepickViewer.ready === true, null, { timeout: 20000 })
    .then(() => true, () => false);
  check(ready, 'viewer ready', ready ? `after ${Date.now() - t0} ms` : 'not within 20 s');
  if (!ready) return;
  const errs = await api(page, 'v.errors.slice()');
  check(errs.length === 0, 'tubepickViewer.errors empty', errs.join(' | '));
  const fc = await api(page, 'v.frameCount');
  check(fc === frames.length, 'frame count', `page ${fc}, JSON ${frames.length}`);
  const canvases = await page.locator('#view canvas').count();
  if (check(canvases === 1, 'WebGL canvas in #view', `${canvases} canvas element(s)`)) {
    await settle(page);
    await checkCanvas(page);
    await checkPresets(page, binSize(data));
    if (data.frames[0]?.cloud?.xyz) await checkCloudHover(page);
    for (let i = 0; i < frames.length; i++) await checkFrame(page, frames[i], i);
    await exercise(page, frames);
  }
  if (expectWarning) {
    const shown = frames.filter((f) => f.warnings.includes(expectWarning)).length;
    check(shown > 0, `the page carries warning ${expectWarning}`, `${shown} frame(s)`);
  }
  const branched = frames.reduce((s, f) => s + f.graphs.filter((g) => g.branches > 1).length, 0);
  check(consoleErrors.length === 0, 'no console or page errors', (consoleErrors.length ? consoleErrors.join(' | ') : '0 errors')
    + (branched ? ` (the page has ${branched} branched tube(s))` : ''));
}

async function followList(page, url, consoleErrors) {
  await page.goto(url, { waitUntil: 'load' });
  const ids = await page.$$eval('a[data-call-id]', (as) => as.map((a) => a.getAttribute('data-call-id')));
  const nums = ids.map(Number);
  const sorted = nums.every((v, i) => i === 0 || (Number.isFinite(v) && v < nums[i - 1]));
  check(ids.length >= 1, 'list: call links', `${ids.length} a[data-call-id] links`);
  check(sorted, 'list: newest first', `ids ${ids.slice(0, 8).join(', ')}${ids.length > 8 ? ', …' : ''}`);
  check(consoleErrors.length === 0, 'list: no console errors', consoleErrors.length ? consoleErrors.join(' | ') : '0 errors');
  consoleErrors.length = 0;
  if (!ids.length) return null;
  await Promise.all([page.waitForEvent('load'), page.locator('a[data-call-id]').first().click()]);
  console.log(`list: opened call ${ids[0]} → ${page.url()}`);
  return page.url();
}

async function main() {
  let args;
  try {
    args = parseArgs({ options: { page: { type: 'string' }, screenshot: { type: 'string' }, list: { type: 'boolean' },
      'expect-warning': { type: 'string' } } }).values;
  } catch (e) { args = {}; console.error(e.message); }
  if (!args.page || !args.screenshot) {
    console.error('usage: node viewer/test/check-page.mjs --page PATH_OR_URL --screenshot OUT.png [--list] [--expect-warning CODE]');
    process.exit(2);
  }
  const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', args: LAUNCH_ARGS });
  try {
    const page = await browser.newPage({ viewport: { width: 1600, height: 900 } });
    const consoleErrors = [];
    page.on('console', (m) => {
      if (m.type() !== 'error') return;
      const where = m.location()?.url || '';
      // The browser's own automatic /favicon.ico request is not the page's doing.
      if (/\/favicon\.ico$/.test(where)) { console.log(`note: ignored ${m.text()} for ${where}`); return; }
      consoleErrors.push(`console: ${m.text()}${where ? ` (${where})` : ''}`);
    });
    page.on('pageerror', (e) => consoleErrors.push(`pageerror: ${e.message}`));
    const requests = [];
    page.on('request', (r) => requests.push(r.url()));
    let url = toUrl(args.page);
    if (args.list) url = await followList(page, url, consoleErrors);
    if (url) {
      requests.length = 0;
      await checkViewerPage(page, url, consoleErrors, args['expect-warning']);
      const extra = requests.filter((r) => r !== url && !r.startsWith('data:') && !r.startsWith('blob:') && !/\/favicon\.ico$/.test(r));
      check(extra.length === 0, 'self-contained (no requests besides the page)', extra.length ? extra.slice(0, 5).join(' ') : `${requests.length} request(s), all the page itself`);
      await api(page, 'v.showFrame(0)').catch(() => {});
      await settle(page);
      await page.screenshot({ path: resolve(args.screenshot) });
      console.log(`screenshot: ${resolve(args.screenshot)}`);
    }
  } catch (e) {
    check(false, 'check run', e.stack || String(e));
  } finally {
    await browser.close();
  }
  console.log(failures ? `${failures} check(s) FAILED` : 'all checks passed');
  process.exit(failures ? 1 : 0);
}

main();
