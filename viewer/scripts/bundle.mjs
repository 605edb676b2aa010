#!/usr/bin/env node
// Bundle viewer/src/main.js into one minified IIFE file: node viewer/scripts/bundle.mjs --out PATH
import { build } from 'esbuild';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseArgs } from 'node:util';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');

function usage(msg) {
  console.error(`${msg}\nusage: node viewer/scripts/bundle.mjs --out PATH [--no-minify] [--metafile]  (--metafile: print the largest inputs)`);
  process.exit(2);
}

let args;
try {
  args = parseArgs({ options: { out: { type: 'string' }, 'no-minify': { type: 'boolean' }, metafile: { type: 'boolean' } } }).values;
} catch (e) { usage(e.message); }
if (!args.out) usage('missing --out');
const out = resolve(process.cwd(), args.out);

const result = await build({
  entryPoints: [resolve(root, 'src/main.js')],
  absWorkingDir: root,
  bundle: true,
  format: 'iife',
  platform: 'browser',
  target: ['es2020'],
  minify: !args['no-minify'],
  legalComments: 'none',
  charset: 'utf8',
  write: false,
  metafile: !!args.metafile,
  logLevel: 'warning',
});
const code = result.outputFiles[0].text;
if (/<\/script/i.test(code)) {
  console.error('bundle.mjs: output contains "</script", which would end the inline <script> element');
  process.exit(1);
}
if (/<!--/.test(code)) {
  console.error('bundle.mjs: output contains "<!--", which would confuse the inline <script> parser');
  process.exit(1);
}
mkdirSync(dirname(out), { recursive: true });
writeFileSync(out, code);
if (args.metafile) {
  const inputs = Object.entries(Object.values(result.metafile.outputs)[0].inputs);
  inputs.sort((a, b) => b[1].bytesInOutput - a[1].bytesInOutput);
  for (const [file, info] of inputs.slice(0, 12)) console.log(`${String(info.bytesInOutput).padStart(8)}  ${file}`);
}
console.log(`bundle.mjs: wrote ${out} (${readFileSync(out).length} bytes)`);
