#!/usr/bin/env node
// Assemble a viewer page exactly like the C++ side does:
//   node viewer/scripts/make-page.mjs --bundle JS --data DATA.json --out PAGE.html [--title T]
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { parseArgs } from 'node:util';

function usage(msg) {
  console.error(`${msg}\nusage: node viewer/scripts/make-page.mjs --bundle JS --data DATA.json --out PAGE.html [--title T]`);
  process.exit(2);
}

export function escapeHtml(s) {
  return String(s).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;').replace(/"/g, '&quot;');
}

/** The page text; jsonText must already be JSON (it is embedded with every "<" written as "\u003c", as the C++ writer does). */
export function makePage(bundle, jsonText, title) {
  if (/<\/script/i.test(bundle)) throw new Error('bundle contains "</script"');
  const json = jsonText.replace(/</g, '\\u003c');
  return '<!DOCTYPE html>\n'
    + '<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">'
    + `<title>${escapeHtml(title)}</title></head>\n`
    + '<body>\n'
    + `<script type="application/json" id="tubepick-data">${json}</script>\n`
    + `<script>${bundle}</script>\n`
    + '</body></html>\n';
}

let args;
try {
  args = parseArgs({ options: { bundle: { type: 'string' }, data: { type: 'string' }, out: { type: 'string' }, title: { type: 'string' } } }).values;
} catch (e) { usage(e.message); }
if (!args.bundle || !args.data || !args.out) usage('missing --bundle, --data or --out');
const bundle = readFileSync(resolve(args.bundle), 'utf8');
const jsonText = readFileSync(resolve(args.data), 'utf8').trim();
let title = args.title;
if (title == null) {
  try { title = JSON.parse(jsonText).title; } catch { /* broken data is allowed: the page shows the error */ }
}
const out = resolve(args.out);
mkdirSync(dirname(out), { recursive: true });
writeFileSync(out, makePage(bundle, jsonText, title || 'tubepick viewer'));
console.log(`make-page.mjs: wrote ${out}`);
