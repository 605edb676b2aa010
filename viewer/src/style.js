// Page CSS, injected at boot so the bundle is the only asset.
const CSS = `
:root { --bg:#0f1217; --view:#161a21; --panel:#1b2029; --line:#2a313d; --text:#d6dce5; --muted:#8b95a5;
  --accent:#4e9af1; --sel:#243b5c; --sel-line:#4e9af1; --warn:#e3a21a; --bad:#f0524f; --ok:#3fb950; }
* { box-sizing:border-box; }
html,body { margin:0; height:100%; background:var(--bg); color:var(--text);
  font:13px/1.4 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif; }
#app { display:flex; height:100vh; width:100vw; overflow:hidden; }
#view { position:relative; flex:1 1 auto; min-width:0; background:var(--view); }
#view canvas { display:block; width:100%; height:100%; outline:none; }
#panel { flex:0 0 470px; overflow-y:auto; background:var(--panel); border-left:1px solid var(--line); padding:14px 16px 24px; }
#panel h1 { font-size:16px; margin:0 0 4px; font-weight:650; word-break:break-word; }
#panel h2 { font-size:11px; letter-spacing:.08em; text-transform:uppercase; color:var(--muted); margin:18px 0 6px; font-weight:650; }
.meta { color:var(--muted); font-size:12px; word-break:break-all; }
.meta b { color:var(--text); font-weight:500; }
.links a { color:var(--accent); margin-right:12px; text-decoration:none; font-size:12px; }
.links a:hover { text-decoration:underline; }
.stepper { display:flex; gap:6px; align-items:center; margin-top:12px; }
.stepper select { flex:1; min-width:0; }
button, select, input[type=range] { font:inherit; color:var(--text); }
button, select { background:#252c37; border:1px solid #3a4352; border-radius:5px; padding:3px 9px; cursor:pointer; }
button:hover:not(:disabled), select:hover { border-color:var(--accent); }
button:disabled { opacity:.4; cursor:default; }
.note { margin-top:8px; padding:6px 9px; border-radius:5px; background:#212733; border-left:3px solid var(--accent); }
.frame-error { margin-top:8px; padding:8px 10px; border-radius:5px; background:#3a1d1f; border:1px solid var(--bad); color:#ffd0ce; font-weight:600; white-space:pre-wrap; }
.frame-error::before { content:"Call failed: "; color:var(--bad); }
.frame-error.data-problem::before { content:"Data problem: "; }
.frame-warning { margin-top:8px; padding:8px 10px; border-radius:5px; background:#3a321a; border:1px solid #d9a520; color:#ffe8b0; white-space:pre-wrap; }
.frame-warning::before { content:"Check the cell: "; color:#f2c14e; font-weight:600; }
#plans td, #plans th { font-size:12px; padding:3px 4px; }
table { width:100%; border-collapse:collapse; font-variant-numeric:tabular-nums; }
th { text-align:left; color:var(--muted); font-weight:600; font-size:11px; padding:3px 5px; border-bottom:1px solid var(--line); white-space:nowrap; }
td { padding:3px 5px; border-bottom:1px solid #232933; white-space:nowrap; }
td.num, th.num { text-align:right; }
td.graph.linear { color:var(--muted); }
.kv td:first-child { color:var(--muted); }
.kv td:last-child { text-align:right; }
tr[data-plan-index], tr[data-tube-id] { cursor:pointer; }
tr[data-plan-index]:hover, tr[data-tube-id]:hover { background:#232a35; }
tr.of-tube { background:#1f2a38; }
tr.selected, tr.selected:hover { background:var(--sel); box-shadow:inset 3px 0 0 var(--sel-line); }
.empty { color:var(--muted); font-style:italic; padding:4px 0; }
.swatch { display:inline-block; width:10px; height:10px; border-radius:2px; margin-right:6px; vertical-align:-1px; }
.badge { display:inline-block; padding:0 6px; border-radius:9px; font-size:11px; font-weight:600; }
.occ-none { background:#1d3a25; color:#7ee29a; } .occ-weak { background:#3d3016; color:#f3c65c; } .occ-strong { background:#40201f; color:#ff8f8c; }
.exec { background:#1d3350; color:#8cc2ff; }
.controls { display:grid; grid-template-columns:auto 1fr; gap:6px 12px; align-items:center; }
.layers { display:flex; flex-wrap:wrap; gap:4px 14px; margin-bottom:8px; }
label { cursor:pointer; user-select:none; }
input[type=checkbox] { accent-color:var(--accent); vertical-align:-2px; }
input[type=range] { accent-color:var(--accent); width:100%; }
.bar { height:4px; background:var(--accent); border-radius:2px; opacity:.7; }
.overlay { position:absolute; background:rgba(15,18,23,.82); border:1px solid var(--line); border-radius:7px; padding:8px 10px; font-size:12px; pointer-events:auto; }
#legend { top:10px; left:10px; max-width:300px; }
#legend:empty { display:none; }
#legend .row { margin:2px 0; }
#legend .title { color:var(--muted); font-size:10px; letter-spacing:.08em; text-transform:uppercase; margin-top:6px; }
#legend .title:first-child { margin-top:0; }
.gradient { height:8px; border-radius:3px; margin:3px 0 1px; }
.range-labels { display:flex; justify-content:space-between; color:var(--muted); font-variant-numeric:tabular-nums; }
#player { left:50%; transform:translateX(-50%); bottom:12px; display:flex; align-items:center; gap:10px; width:min(620px,90%); }
#player input { flex:1; }
#player .time { font-variant-numeric:tabular-nums; color:var(--muted); min-width:92px; text-align:right; }
#player .phase { color:#7dd3fc; min-width:60px; }
#tooltip { position:absolute; pointer-events:none; display:none; padding:4px 8px; font-size:12px; background:rgba(15,18,23,.92); border:1px solid var(--line); border-radius:5px; white-space:nowrap; }
#message { position:absolute; top:50%; left:50%; transform:translate(-50%,-50%); max-width:70%; display:none;
  background:#3a1d1f; border:1px solid var(--bad); color:#ffd0ce; padding:16px 20px; border-radius:8px; font-size:14px; white-space:pre-wrap; }
#message.show { display:block; }
#banner { position:absolute; top:10px; left:50%; transform:translateX(-50%); max-width:60%; display:none; background:rgba(58,29,31,.95);
  border:1px solid var(--bad); color:#ffd0ce; padding:6px 14px; border-radius:6px; font-weight:600; white-space:pre-wrap; }
#banner.show { display:block; }
#view-presets { top:10px; right:10px; display:flex; align-items:center; gap:4px; padding:5px 6px; }
#view-presets .presets-label { color:var(--muted); font-size:10px; letter-spacing:.08em; text-transform:uppercase; margin:0 4px 0 3px; }
#view-presets button { min-width:44px; padding:3px 8px; font-size:12px; }
#view-presets button.active { background:var(--sel); border-color:var(--sel-line); color:#fff; }
.tip-muted { color:var(--muted); }
.plan-details { background:#212733; border:1px solid var(--line); border-radius:7px; padding:9px 11px; font-variant-numeric:tabular-nums; }
.plan-details .empty { padding:0; }
.pd-head { display:flex; align-items:center; gap:8px; margin-bottom:7px; padding-bottom:7px; border-bottom:1px solid var(--line); }
.pd-rank { font-size:15px; font-weight:700; }
.pd-head .meta { margin-right:auto; margin-left:-3px; }
.pd-tube { font-weight:600; }
.pd-graph { color:var(--muted); font-size:12px; margin-left:-4px; }
.badge.kind { background:#16303a; color:#7dd3fc; }
.pd-grid { display:grid; grid-template-columns:auto 1fr; gap:4px 14px; font-size:12px; }
.pd-grid .k { color:var(--muted); white-space:nowrap; }
.pd-grid .v { text-align:right; }
.pd-grid b { font-weight:600; }
.xyz > span, .costs > span { display:inline-block; min-width:62px; }
.xyz i, .costs i, .wp { font-style:normal; color:var(--muted); margin-right:4px; font-size:11px; }
.xyz > i { margin:0 0 0 4px; }
.costs .total b { color:#8cc2ff; }
.hint { color:var(--muted); font-size:11px; margin-top:10px; }
kbd { background:#252c37; border:1px solid #3a4352; border-radius:3px; padding:0 4px; font-size:11px; }
`;

export function injectStyle() {
  const style = document.createElement('style');
  style.textContent = CSS;
  document.head.appendChild(style);
}
