// Tiny DOM and number-formatting helpers.
export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v == null || v === false) continue;
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (k === 'class') e.className = v;
    else if (k === 'style') e.style.cssText = v;
    else e.setAttribute(k, v === true ? '' : String(v));
  }
  for (const c of children.flat()) if (c != null && c !== false) e.append(c instanceof Node ? c : String(c));
  return e;
}

export function fmt(v, d = 3) {
  if (!Number.isFinite(v)) return '–';
  const s = v.toFixed(d);
  return /^-0\.?0*$/.test(s) ? s.slice(1) : s;
}

export function seconds(s) {
  if (!Number.isFinite(s)) return '–';
  if (s < 1e-3) return `${(s * 1e6).toFixed(0)} µs`;
  if (s < 1) return `${(s * 1e3).toFixed(1)} ms`;
  return `${s.toFixed(2)} s`;
}

export const int = (v) => (Number.isFinite(v) ? Math.round(v).toLocaleString('en-US') : '–');

export function table(id, headers, rows) {
  const head = el('tr', {}, headers.map((h) => el('th', { class: h.num ? 'num' : null, title: h.title }, h.label)));
  return el('table', { id }, el('thead', {}, head), el('tbody', {}, rows));
}

/** Two-column key/value table. */
export function kvTable(pairs, id) {
  return el('table', { class: 'kv', id }, el('tbody', {}, pairs.map(([k, v]) => el('tr', {}, el('td', {}, k), el('td', {}, v)))));
}
