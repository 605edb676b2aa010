#!/usr/bin/env node
// Headless-Chromium check of a tubepick viewer page (file path, file:// or http URL), or of a call list page.
//   node viewer/test/check-page.mjs --page PATH_OR_URL --screenshot OUT.png [--list]
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

/** Expected per-frame counts, computed independently from the page's embedded JSON. */
function expectedFrames(html) {
  const m = html.match(/<script type="application\/json" id="tubepick-data">([\s\S]*?)<\/script>/);
  if (!m) throw new Error('no <script type="application/json" id="tubepick-data"> in the page');
  const data = JSON.parse(m[1]);
  return data.frames.map((f) => {
    const tubes = f.plan ? nonEmpty(f.plan.tubes) || nonEmpty(f.plan.modeling?.tubes) || [] : nonEmpty(f.modeling?.tubes) || [];
    const plans = Array.isArray(f.plan?.plans) ? f.plan.plans : [];
    return { tubeIds: tubes.map((t) => num(t.id)), planTubeIds: plans.map((p) => num(p.tubeId)) };
  });
}

const api = (page, expr) => page.evaluate(`(() => { const v = window.tubepickViewer; return ${expr}; })()`);
const settle = (page) => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

async function checkCanvas(page) {
  const png = await page.locator('#view canvas').screenshot();
  const stats = await page.evaluate(async ({ b64, bg }) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const ctx = c.getContext('2d', { willReadFrequently: true });
    ctx.drawImage(img, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
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

async function checkFrame(page, f, i) {
  await api(page, `v.showFrame(${i})`);
  await settle(page);
  const got = await page.evaluate(() => {
    const v = window.tubepickViewer;
    return { idx: v.frameIndex, tubes: v.tubeCount(), plans: v.planCount(),
      tubeRows: document.querySelectorAll('#tubes tr[data-tube-id]').length,
      planRows: document.querySelectorAll('#plans tr[data-plan-index]').length };
  });
  const nt = f.tubeIds.length, np = f.planTubeIds.length;
  check(got.idx === i && got.tubes === nt && got.tubeRows === nt && got.plans === np && got.planRows === np,
    `frame ${i + 1}: counts`, `tubeCount ${got.tubes}, tube rows ${got.tubeRows} (JSON ${nt}); planCount ${got.plans}, plan rows ${got.planRows} (JSON ${np})`);
  const planIdx = [...new Set([0, np - 1])].filter((k) => k >= 0 && k < np);
  for (const k of planIdx) await checkPlanClick(page, f, k);
  const tubeIds = [f.tubeIds[0], f.planTubeIds[0], f.tubeIds[nt - 1]].filter((x) => x !== undefined && f.tubeIds.includes(x));
  for (const id of new Set(tubeIds)) await checkTubeClick(page, f, id);
  if (nt) await checkCanvasPick(page, np ? f.planTubeIds[0] : f.tubeIds[0]);
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

async function checkViewerPage(page, url, consoleErrors) {
  const frames = expectedFrames(await fetchText(url));
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
    for (let i = 0; i < frames.length; i++) await checkFrame(page, frames[i], i);
    await exercise(page, frames);
  }
  check(consoleErrors.length === 0, 'no console or page errors', consoleErrors.length ? consoleErrors.join(' | ') : '0 errors');
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
    args = parseArgs({ options: { page: { type: 'string' }, screenshot: { type: 'string' }, list: { type: 'boolean' } } }).values;
  } catch (e) { args = {}; console.error(e.message); }
  if (!args.page || !args.screenshot) {
    console.error('usage: node viewer/test/check-page.mjs --page PATH_OR_URL --screenshot OUT.png [--list]');
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
      await checkViewerPage(page, url, consoleErrors);
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
