// The replay page: HTML, styles and a plain script (no libraries) that decode the run's data
// (replay_json) and draw it on canvases. Over 500 lines on purpose: most of it is the page's one
// script, whose parts (decoding the delta-encoded maps, drawing, the timeline, the why panel) share
// its state and must ship as one self-contained file.
#include <string>

#include "viz/html.h"

namespace fleetmap::viz {

std::string_view page_head() {
  return R"HTML(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="fleetmap">
<title>)HTML";
}

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string_view page_style() {
  return R"CSS(<style>
body { font: 14px/1.4 system-ui, sans-serif; margin: 12px 16px; color: #222; background: #fff; }
h1 { font-size: 18px; margin: 0 0 4px; }
.facts { color: #555; margin-bottom: 8px; }
.facts span { margin-right: 14px; }
table { border-collapse: collapse; margin: 6px 0 14px; }
th, td { border: 1px solid #ccc; padding: 2px 8px; text-align: right; }
th { background: #f3f3f3; }
td.text, th.text { text-align: left; }
#tip { position: fixed; pointer-events: none; background: rgba(255,255,255,0.96); border: 1px solid #888;
       padding: 4px 8px; font-size: 12px; white-space: pre; display: none; z-index: 10; box-shadow: 1px 1px 4px #0003; }
</style>
)CSS";
}

namespace {

constexpr std::string_view kStyle = R"HTML(</title>
<style>
.controls { display: flex; align-items: center; gap: 8px; margin: 6px 0; flex-wrap: wrap; }
.controls input[type=range] { flex: 1; min-width: 300px; }
#stepText { font-variant-numeric: tabular-nums; min-width: 180px; }
.views { display: flex; gap: 16px; align-items: flex-start; flex-wrap: wrap; }
.panel { border: 1px solid #ddd; padding: 6px; }
.panel h2 { font-size: 14px; margin: 0 0 4px; font-weight: 600; }
canvas { display: block; image-rendering: pixelated; }
#events { max-height: 220px; overflow-y: auto; border: 1px solid #ddd; font-size: 12px; }
#events div { padding: 1px 6px; cursor: pointer; white-space: nowrap; }
#events div.past { color: #222; }
#events div.future { color: #aaa; }
#events div.now { background: #fff3c4; }
.legend span { display: inline-block; margin-right: 12px; font-size: 12px; }
.legend i { display: inline-block; width: 12px; height: 12px; vertical-align: -2px; margin-right: 4px; border: 1px solid #999; }
.side { max-width: 436px; min-width: 300px; }
#why { font-size: 12px; overflow-x: auto; }
#why th { font-weight: 600; font-size: 11px; }
#why table { margin: 4px 0; }
#why td, #why th { padding: 1px 5px; }
#why tr.chosen td { background: #e3f4e3; font-weight: 600; }
#why tr.taken td { color: #888; }
#why .rule { color: #555; }
body.embedded .controls, body.embedded #chartsPanel, body.embedded #eventsPanel, body.embedded h1, body.embedded .facts { display: none; }
body.only { margin: 0; }
body.only > *:not(#main-wrap) { display: none !important; }
body.only #main-wrap * { display: none; }
body.only #main-wrap, body.only #mainPanel, body.only #main { display: block !important; border: 0; padding: 0; margin: 0; }
</style>
)HTML";

constexpr std::string_view kBody = R"HTML(</head>
<body>
<h1 id="title"></h1>
<div class="facts" id="facts"></div>
<div class="controls">
  <button id="play" title="play / pause (space)">&#9654; play</button>
  <button id="prev" title="one step back (left arrow)">&#9664;</button>
  <button id="next" title="one step on (right arrow)">&#9654;</button>
  <label>speed <select id="speed">
    <option value="2">2</option><option value="5">5</option><option value="10">10</option>
    <option value="20" selected>20</option><option value="50">50</option><option value="100">100</option>
    <option value="250">250</option></select> steps/s</label>
  <input type="range" id="slider" min="0" max="0" value="0" aria-label="step">
  <span id="stepText"></span>
  <label><input type="checkbox" id="overlays" checked> robots, paths, frontiers</label>
</div>
<div id="main-wrap" class="views">
  <div class="panel" id="mainPanel"><h2>Merged map (the world frame)</h2><canvas id="main"></canvas>
    <div class="legend" id="legend"></div></div>
  <div class="side"><div class="panel" id="ownPanel"><h2>Own map of <select id="robot"></select> (its own frame)</h2><canvas id="own"></canvas>
    <div id="ownText" style="font-size:12px;white-space:pre"></div></div>
  <div class="panel" id="whyPanel" style="margin-top:10px"><h2>Why <span id="whyRobot"></span> chose its target</h2><div id="why"></div></div></div>
</div>
<div class="panel" id="chartsPanel" style="margin-top:10px">
  <h2>Coverage of the observable space, and the events (click to go to a step)</h2>
  <canvas id="curve" height="170"></canvas>
  <canvas id="timeline" height="70"></canvas>
</div>
<div class="panel" id="eventsPanel" style="margin-top:10px"><h2>Events</h2><div id="events"></div></div>
<div id="tip"></div>
<script type="application/json" id="data">)HTML";

// The script. Cells are drawn one canvas pixel each on an off-screen canvas, then scaled without
// smoothing; the overlays are drawn in canvas pixels on top.
constexpr std::string_view kScript = R"JS(</script>
<script>
"use strict";
const D = JSON.parse(document.getElementById('data').textContent);
const S = D.coverage.length;            // steps recorded: 0 .. S-1
const N = D.robots.length;
const opts = {};
// A page shown inside the comparison page gets its options through its frame's name ("fleetmap:...").
const framed = window.name.startsWith('fleetmap:') ? window.name.slice(9) : '';
for (const part of (location.hash.replace(/^#/, '') + '&' + framed).split('&')) {
  const kv = part.split('=');
  if (kv[0]) opts[kv[0]] = decodeURIComponent(kv[1] || '');
}
const onlyRobot = opts.only === 'robot';     // tests: a robot's own map alone, its whole grid
const onlyMap = opts.only === 'map' || onlyRobot;
let showOverlays = opts.overlays !== '0';

function b64(s) {
  const bin = atob(s), u = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) u[i] = bin.charCodeAt(i);
  return u;
}
function varints(u, f) {
  let i = 0;
  while (i < u.length) {
    let v = 0, m = 1, b;
    do { b = u[i++]; v += (b & 127) * m; m *= 128; } while (b & 128);
    f(v);
  }
}

// A grid that changes step by step: whole pictures where its geometry changes, cell changes between.
class Layer {
  constructor(L) {
    this.frames = L.frames; this.changes = L.changes;
    this.fi = -1; this.step = -1; this.cells = null; this.geom = null; this.version = 0;
  }
  frameAt(t) { let k = 0; for (let i = 0; i < this.frames.length; ++i) if (this.frames[i].step <= t) k = i; return k; }
  load(fi) {
    const f = this.frames[fi];
    this.cells = new Uint8Array(f.width * f.height);
    let p = 0;
    varints(b64(f.cells), v => { const n = Math.floor(v / 4); this.cells.fill(v % 4, p, p + n); p += n; });
    this.fi = fi; this.step = f.step; this.geom = f;
  }
  apply(t, forward) {
    const s = this.changes[t];
    if (!s) return;
    let p = -1;
    const cells = this.cells;
    varints(b64(s), v => { p += Math.floor(v / 16) + 1; cells[p] = forward ? (v & 3) : ((v >> 2) & 3); });
  }
  seek(t) {
    if (t === this.step) return;
    const fi = this.frameAt(t);
    if (fi !== this.fi) this.load(fi);
    while (this.step < t) { this.step++; this.apply(this.step, true); }
    while (this.step > t) { this.apply(this.step, false); this.step--; }
    this.version++;
  }
  // World (frame) metres to continuous grid cells.
  toGrid(x, y) {
    const g = this.geom, c = Math.cos(g.origin[2]), s = Math.sin(g.origin[2]);
    const dx = x - g.origin[0], dy = y - g.origin[1];
    return [(c * dx + s * dy) / g.resolution, (-s * dx + c * dy) / g.resolution];
  }
  // The cells ever known, [x0, y0, x1, y1) in cells, with a margin; null when none.
  knownBox(margin) {
    const g = this.geom, w = g.width, h = g.height, cells = this.cells, base = g.relative ? merged.cells : null;
    const known = i => { const c = cells[i]; return c === 3 && base ? base[i] !== 0 : c !== 0; };
    let x0 = w, y0 = h, x1 = -1, y1 = -1;
    for (let y = 0; y < h; ++y) {
      const row = y * w;
      let first = -1, last = -1;
      for (let x = 0; x < w; ++x) if (known(row + x)) { first = x; break; }
      if (first < 0) continue;
      for (let x = w - 1; x >= first; --x) if (known(row + x)) { last = x; break; }
      if (first < x0) x0 = first; if (last > x1) x1 = last;
      if (y < y0) y0 = y; y1 = y;
    }
    if (x1 < 0) return null;
    return [Math.max(0, x0 - margin), Math.max(0, y0 - margin), Math.min(w, x1 + 1 + margin), Math.min(h, y1 + 1 + margin)];
  }
}

const COLORS = [[205, 205, 205], [255, 255, 255], [0, 0, 0], [255, 200, 0]];  // unknown, free, occupied, frontier
// A layer stored relative to the merged map takes the merged map's cell where it holds code 3.
function paintCells(layer, off, frontiers) {
  const g = layer.geom, w = g.width, h = g.height, base = g.relative ? merged.cells : null;
  if (off.width !== w || off.height !== h) { off.width = w; off.height = h; }
  const ctx = off.getContext('2d'), img = ctx.createImageData(w, h), px = img.data, cells = layer.cells;
  for (let y = 0; y < h; ++y) {
    const src = (h - 1 - y) * w;  // grid rows go up, image rows down
    for (let x = 0; x < w; ++x) {
      let c = cells[src + x];
      if (c === 3 && base) c = base[src + x];
      if (c === 3 && !frontiers) c = 1;
      const col = COLORS[c], o = 4 * (y * w + x);
      px[o] = col[0]; px[o + 1] = col[1]; px[o + 2] = col[2]; px[o + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
}

function pose(arr, k) { return [arr[3 * k] / 100, arr[3 * k + 1] / 100, arr[3 * k + 2] / 1000]; }
function framePose(r, t) {
  let f = r.frames[0];
  for (const g of r.frames) if (g[0] <= t) f = g;
  return [f[1] / 100, f[2] / 100, f[3] / 1000];
}
function apply(T, x, y) { const c = Math.cos(T[2]), s = Math.sin(T[2]); return [T[0] + c * x - s * y, T[1] + s * x + c * y]; }
function applyInv(T, x, y) { const c = Math.cos(T[2]), s = Math.sin(T[2]), dx = x - T[0], dy = y - T[1]; return [c * dx + s * dy, -s * dx + c * dy]; }
function planAt(r, t) {
  const k = r.plan[t];
  if (k < 0) return [];
  const p = r.plans[k], out = [];
  for (let i = 2 * r.passed[t]; i < p.length; i += 2) out.push([p[i] / 100, p[i + 1] / 100]);
  return out;  // in the robot's map frame
}
function estimateAt(r, t) { return D.estimates ? pose(r.estimate, t) : pose(r.truth, t); }
const fmt = (v, d) => v.toFixed(d === undefined ? 2 : d);
const deg = a => fmt(a * 180 / Math.PI, 0);

// Cumulative distance travelled (true trajectory), per robot and step.
const travelled = D.robots.map(r => {
  const out = new Float64Array(S);
  for (let k = 1; k < S; ++k) {
    const a = pose(r.truth, k - 1), b = pose(r.truth, k);
    out[k] = out[k - 1] + Math.hypot(b[0] - a[0], b[1] - a[1]);
  }
  return out;
});

const merged = new Layer(D.merged);
const own = D.own.map(L => new Layer(L));
const offMain = document.createElement('canvas'), offOwn = document.createElement('canvas');
const main = document.getElementById('main'), ownCanvas = document.getElementById('own');
const slider = document.getElementById('slider');
slider.max = S - 1;
document.getElementById('title').textContent = D.title;
document.getElementById('facts').innerHTML = D.facts.map(f => '<span><b>' + esc(f[0]) + '</b> ' + esc(f[1]) + '</span>').join('');
function esc(s) { return String(s).replace(/[&<>"]/g, c => ({'&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;'})[c]); }

// The merged view shows the cells known at the end (plus a metre), so it does not move while playing.
merged.seek(S - 1);
const margin = Math.ceil(1.0 / merged.geom.resolution);
let mainBox = onlyMap ? [0, 0, merged.geom.width, merged.geom.height]
                      : (merged.knownBox(margin) || [0, 0, merged.geom.width, merged.geom.height]);
function fitScale(box, maxW, maxH) {
  const w = box[2] - box[0], h = box[3] - box[1];
  const s = Math.min(maxW / w, maxH / h);
  return s >= 1 ? Math.floor(s) : s;
}
const mainScale = onlyMap ? Math.max(1, parseInt(opts.scale || '4', 10))
                          : fitScale(mainBox, Math.max(400, Math.min(900, window.innerWidth - 510)), 760);
main.width = Math.round((mainBox[2] - mainBox[0]) * mainScale);
main.height = Math.round((mainBox[3] - mainBox[1]) * mainScale);
document.getElementById('mainPanel').style.maxWidth = Math.max(300, main.width) + 'px';

// Canvas pixels of a world (frame) point on a layer drawn with `box` at `scale`.
function toPx(layer, box, scale, x, y) {
  const g = layer.toGrid(x, y);
  return [(g[0] - box[0]) * scale, (box[3] - g[1]) * scale];
}

let t = Math.min(S - 1, Math.max(0, parseInt(opts.step || '0', 10) || 0));
let robotSel = Math.min(N, Math.max(1, parseInt(opts.robot || '1', 10) || 1)) - 1;
const robotSelect = document.getElementById('robot');
D.robots.forEach((r, i) => { const o = document.createElement('option'); o.value = i; o.textContent = r.name; robotSelect.appendChild(o); });
robotSelect.value = robotSel;
document.getElementById('overlays').checked = showOverlays;

const legend = document.getElementById('legend');
legend.innerHTML = '<span><i style="background:#cdcdcd"></i>unknown</span><span><i style="background:#fff"></i>free</span>' +
  '<span><i style="background:#000"></i>occupied</span><span><i style="background:#ffc800"></i>frontier cells</span>' +
  '<span>solid: true trajectory' + (D.estimates ? ', dotted: estimated' : '') + '; dashed: planned path to the target (&#10005;); ' +
  '&#9675;: start; grey &#10005;: a target given up; numbered circles: the chosen robot\'s candidate frontier targets in its last ' +
  'decision, best first, with their scores (its target: thick ring; dashed: taken by the robot of that colour)</span>';

function drawDisc(ctx, p, r, color, heading, ring) {
  ctx.beginPath(); ctx.arc(p[0], p[1], r, 0, 2 * Math.PI);
  if (ring) { ctx.strokeStyle = color; ctx.lineWidth = 2; ctx.stroke(); return; }
  ctx.fillStyle = color; ctx.fill(); ctx.strokeStyle = '#000'; ctx.lineWidth = 1; ctx.stroke();
  if (heading !== undefined) {
    ctx.beginPath(); ctx.moveTo(p[0], p[1]);
    ctx.lineTo(p[0] + 1.6 * r * Math.cos(heading), p[1] - 1.6 * r * Math.sin(heading));
    ctx.strokeStyle = '#000'; ctx.lineWidth = 2; ctx.stroke();
  }
}
function drawCross(ctx, p, r, color, width) {
  ctx.beginPath(); ctx.moveTo(p[0] - r, p[1] - r); ctx.lineTo(p[0] + r, p[1] + r);
  ctx.moveTo(p[0] - r, p[1] + r); ctx.lineTo(p[0] + r, p[1] - r);
  ctx.strokeStyle = color; ctx.lineWidth = width || 2; ctx.stroke();
}
function polyline(ctx, pts, color, width, dash) {
  if (pts.length < 2) return;
  ctx.beginPath(); ctx.moveTo(pts[0][0], pts[0][1]);
  for (let i = 1; i < pts.length; ++i) ctx.lineTo(pts[i][0], pts[i][1]);
  ctx.strokeStyle = color; ctx.lineWidth = width; ctx.setLineDash(dash || []); ctx.stroke(); ctx.setLineDash([]);
}

let robotPx = [];  // canvas pixels of each robot on the main view, for hovering
function drawMain() {
  merged.seek(t);
  if (onlyRobot) {
    const layer = own[robotSel];
    layer.seek(t);
    paintCells(layer, offMain, false);
    main.width = layer.geom.width * mainScale; main.height = layer.geom.height * mainScale;
    const c = main.getContext('2d');
    c.imageSmoothingEnabled = false;
    c.drawImage(offMain, 0, 0, main.width, main.height);
    return;
  }
  paintCells(merged, offMain, showOverlays);
  const ctx = main.getContext('2d');
  ctx.imageSmoothingEnabled = false;
  ctx.fillStyle = '#eee'; ctx.fillRect(0, 0, main.width, main.height);
  const h = merged.geom.height;
  ctx.drawImage(offMain, mainBox[0], h - mainBox[3], mainBox[2] - mainBox[0], mainBox[3] - mainBox[1], 0, 0, main.width, main.height);
  robotPx = [];
  if (!showOverlays) return;
  const px = (x, y) => toPx(merged, mainBox, mainScale, x, y);
  const rpx = Math.max(4, D.radius / merged.geom.resolution * mainScale);
  D.robots.forEach((r, i) => {
    const truth = [], est = [];
    const every = Math.max(1, Math.floor(t / 4000));
    for (let k = 0; k <= t; k += every) {
      const p = pose(r.truth, k); truth.push(px(p[0], p[1]));
      if (D.estimates) { const e = pose(r.estimate, k); est.push(px(e[0], e[1])); }
    }
    const now = pose(r.truth, t); truth.push(px(now[0], now[1]));
    polyline(ctx, truth, r.color, 2);
    if (D.estimates) polyline(ctx, est, r.color, 1, [2, 3]);
    const start = pose(r.truth, 0);
    drawDisc(ctx, px(start[0], start[1]), rpx, r.color, undefined, true);
  });
  for (const e of D.events) {
    if (e.kind !== 'given up' || e.step > t || !e.at) continue;
    drawCross(ctx, px(e.at[0] / 100, e.at[1] / 100), Math.max(3, rpx * 0.6), '#777', 1.5);
  }
  D.robots.forEach((r, i) => {
    const F = framePose(r, t), plan = planAt(r, t);
    if (plan.length) {
      const e = estimateAt(r, t), pts = [px(e[0], e[1])];
      for (const q of plan) { const w = apply(F, q[0], q[1]); pts.push(px(w[0], w[1])); }
      polyline(ctx, pts, r.color, 2, [6, 4]);
      drawCross(ctx, pts[pts.length - 1], Math.max(4, rpx * 0.8), r.color, 3);
    }
  });
  drawCandidates(ctx, px, rpx);
  D.robots.forEach((r, i) => {
    const p = pose(r.truth, t), q = px(p[0], p[1]);
    drawDisc(ctx, q, rpx, r.color, p[2]);
    robotPx.push(q);
  });
  main.dataset.rpx = rpx;
}

// ---- Why a robot chose its target: the strategy's candidates and their scores (D.scores). ----
// The robot's last decision at or before step k, or null.
function decisionAt(i, k) {
  const ds = D.robots[i].decisions || [];
  let lo = 0, hi = ds.length;
  while (lo < hi) { const m = (lo + hi) >> 1; if (ds[m].s <= k) lo = m + 1; else hi = m; }
  return lo > 0 ? ds[lo - 1] : null;
}
// A candidate row: [frontier x, y, goal x, y (cm), cells, score, taken by, terms...].
function cand(row) {
  return {fx: row[0] / 100, fy: row[1] / 100, gx: row[2] / 100, gy: row[3] / 100, cells: row[4], score: row[5], taken: row[6], terms: row.slice(7)};
}
const num = v => v === null || v === undefined ? '–' : Math.abs(v) >= 100 ? v.toFixed(0) : Math.abs(v) >= 10 ? v.toFixed(1) : v.toFixed(3);
const robotName = i => D.robots[i] ? D.robots[i].name : 'robot ' + (i + 1);
// One sentence on why the chosen candidate won, from the scores alone.
function whyText(i, d) {
  const sc = D.scores || {};
  if (!d) return 'No decision yet: ' + robotName(i) + ' has not asked the strategy for a target by this step.';
  if (!d.r) return 'The strategy “' + (sc.strategy || '?') + '” reports no scores (a strategy registered by a program ' +
    'or in Python may not): only its choice is shown' + (d.goal ? ', the target at ' + fmt(d.goal[0] / 100) + ', ' + fmt(d.goal[1] / 100) + ' m.' : '.');
  if (d.c < 0) return d.kept ? 'No new target from this decision: it keeps driving to the one it has.'
                             : 'No target: nothing it could reach was left for it' + (d.t !== undefined ? ' (' + D.notes[d.t] + ').' : '.');
  const ks = d.k.map(cand), chosen = ks[d.c], better = (a, b) => sc.lower ? a < b : a > b;
  const beaten = ks.filter((c, j) => j !== d.c && c.score !== null && better(c.score, chosen.score));
  const free = ks.filter((c, j) => j !== d.c && c.taken < 0 && c.score !== null);
  let text = 'Chosen: ' + sc.score + ' = ' + num(chosen.score) + ' (' + (sc.lower ? 'lower' : 'higher') + ' is better)';
  if (!beaten.length) {
    text += ', the best of the ' + d.n + ' candidates it weighed';
    if (free.length) {
      const next = free.reduce((a, b) => better(b.score, a.score) ? b : a);
      text += '; the next free one scores ' + num(next.score) + ' (margin ' + num(Math.abs(next.score - chosen.score)) + ')';
    }
    text += '.';
  } else {
    const takers = [...new Set(beaten.filter(c => c.taken >= 0).map(c => robotName(c.taken)))];
    const own = beaten.filter(c => c.taken < 0).length;
    text += ', not its own best: ' + beaten.length + ' candidate' + (beaten.length > 1 ? 's' : '') + ' scored better';
    if (takers.length) text += ', of which ' + (beaten.length - own) + ' went to ' + takers.join(', ') + ' in the same decision';
    if (own) text += (takers.length ? ', and ' : ': ') + own + ' the team’s decision gave to nobody (' + sc.strategy + ' decides for the team, not robot by robot)';
    text += '.';
  }
  return text;
}
function renderWhy() {
  const el = document.getElementById('why'), sc = D.scores || {};
  document.getElementById('whyRobot').textContent = robotName(robotSel);
  const d = decisionAt(robotSel, t);
  const head = [];
  if (d) head.push('Decision at step ' + d.s + (d.s < t ? ' (' + (t - d.s) + ' steps ago)' : '') +
                   (d.g ? ', together with ' + d.g.filter(j => j !== robotSel).map(robotName).join(', ') : ', alone') +
                   ', on ' + robotName(d.l) + '’s map.');
  if (sc.rule) head.push('<span class="rule">Strategy ' + esc(sc.strategy) + ': ' + esc(sc.rule) + '.</span>');
  let html = head.map(h => '<div>' + (h.startsWith('<') ? h : esc(h)) + '</div>').join('');
  html += '<div id="whyText"><b>' + esc(whyText(robotSel, d)) + '</b></div>';
  if (d && d.t !== undefined) html += '<div>' + esc(D.notes[d.t]) + '</div>';
  if (d && d.r && d.k.length) {
    html += '<table id="whyTable"><tr><th>#</th><th class="text">frontier at (m)</th><th>cells</th>' +
            (sc.terms || []).map(n => '<th>' + esc(n) + '</th>').join('') + '<th>' + esc(sc.score) + '</th><th class="text"></th></tr>';
    d.k.forEach((row, j) => {
      const c = cand(row), cls = j === d.c ? 'chosen' : c.taken >= 0 ? 'taken' : '';
      html += '<tr class="' + cls + '" data-score="' + (c.score === null ? '' : c.score) + '" data-taken="' + c.taken + '"><td>' + (j + 1) +
              '</td><td class="text">' + fmt(c.fx, 1) + ', ' + fmt(c.fy, 1) + '</td><td>' + c.cells + '</td>' +
              c.terms.map(v => '<td>' + num(v) + '</td>').join('') + '<td>' + num(c.score) + '</td><td class="text">' +
              (j === d.c ? '✓ chosen' : c.taken >= 0 ? '→ ' + esc(robotName(c.taken)) : '') + '</td></tr>';
    });
    html += '</table>';
    if (d.n > d.k.length) html += '<div>The best ' + d.k.length + ' of ' + d.n + ' candidates are kept in the replay.</div>';
  }
  el.innerHTML = html;
}
// The selected robot's candidates on the merged map, numbered best first, with their scores.
function drawCandidates(ctx, px, rpx) {
  const d = decisionAt(robotSel, t);
  if (!d || !d.r) return;
  ctx.font = 'bold 11px sans-serif';
  const placed = [];  // score labels drawn so far: a label that would cover one is left out (the table has it)
  d.k.forEach((row, j) => {
    const c = cand(row), q = px(c.fx, c.fy), chosen = j === d.c;
    const color = chosen ? D.robots[robotSel].color : c.taken >= 0 ? D.robots[c.taken].color : '#333';
    ctx.beginPath(); ctx.arc(q[0], q[1], Math.max(6, rpx * 0.9), 0, 2 * Math.PI);
    ctx.fillStyle = 'rgba(255,255,255,0.8)'; ctx.fill();
    ctx.setLineDash(c.taken >= 0 && !chosen ? [3, 2] : []);
    ctx.strokeStyle = color; ctx.lineWidth = chosen ? 3 : 1.5; ctx.stroke(); ctx.setLineDash([]);
    ctx.fillStyle = '#000'; ctx.textAlign = 'center'; ctx.textBaseline = 'middle';
    ctx.fillText(String(j + 1), q[0], q[1]);
    ctx.textAlign = 'left';
    ctx.fillStyle = chosen ? '#060' : '#333';
    const label = num(c.score), w = ctx.measureText(label).width, off = Math.max(7, rpx);
    const x = q[0] + off + w > main.width ? q[0] - off - w : q[0] + off, y = q[1] - off;
    if (!chosen && placed.some(b => x < b[0] + b[2] && b[0] < x + w && Math.abs(y - b[1]) < 11)) return;
    placed.push([x, y, w]);
    ctx.fillText(label, x, y);
  });
  ctx.textBaseline = 'alphabetic';
}

let ownBox = null, ownFrame = -1;
function drawOwn() {
  if (!N) return;
  const layer = own[robotSel], r = D.robots[robotSel];
  merged.seek(t);
  layer.seek(t);
  paintCells(layer, offOwn, false);
  // The view grows with the robot's map and never shrinks within one frame of its map.
  const known = layer.knownBox(Math.ceil(1.0 / layer.geom.resolution)) || [0, 0, layer.geom.width, layer.geom.height];
  if (ownFrame !== layer.fi || !ownBox) ownBox = known;
  else ownBox = [Math.min(ownBox[0], known[0]), Math.min(ownBox[1], known[1]), Math.max(ownBox[2], known[2]), Math.max(ownBox[3], known[3])];
  ownFrame = layer.fi;
  const scale = fitScale(ownBox, 420, 420);
  ownCanvas.width = Math.round((ownBox[2] - ownBox[0]) * scale);
  ownCanvas.height = Math.round((ownBox[3] - ownBox[1]) * scale);
  const ctx = ownCanvas.getContext('2d');
  ctx.imageSmoothingEnabled = false;
  const h = layer.geom.height;
  ctx.drawImage(offOwn, ownBox[0], h - ownBox[3], ownBox[2] - ownBox[0], ownBox[3] - ownBox[1], 0, 0, ownCanvas.width, ownCanvas.height);
  const F = framePose(r, t);
  const px = (x, y) => toPx(layer, ownBox, scale, x, y);
  const rpx = Math.max(4, D.radius / layer.geom.resolution * scale);
  if (showOverlays) {
    const pts = [];
    const every = Math.max(1, Math.floor(t / 4000));
    for (let k = 0; k <= t; k += every) { const e = estimateAt(r, k), q = applyInv(F, e[0], e[1]); pts.push(px(q[0], q[1])); }
    polyline(ctx, pts, r.color, 2);
    const e = estimateAt(r, t), q = applyInv(F, e[0], e[1]), plan = planAt(r, t);
    if (plan.length) {
      const pp = [px(q[0], q[1])].concat(plan.map(p => px(p[0], p[1])));
      polyline(ctx, pp, r.color, 2, [6, 4]);
      drawCross(ctx, pp[pp.length - 1], Math.max(4, rpx * 0.8), r.color, 3);
    }
    drawDisc(ctx, px(q[0], q[1]), rpx, r.color, e[2] - F[2]);
  }
  document.getElementById('ownText').textContent = robotState(robotSel);
}

// Text wrapped at spaces into lines of about `width` characters (the tooltip keeps line breaks).
function wrap(text, width) {
  const out = [];
  let line = '';
  for (const w of text.split(' ')) {
    if (line && line.length + w.length + 1 > width) { out.push(line); line = w; } else line = line ? line + ' ' + w : w;
  }
  if (line) out.push(line);
  return out.join('\n  ');
}
function robotState(i, why) {
  const r = D.robots[i], p = pose(r.truth, t), e = estimateAt(r, t), F = framePose(r, t), plan = planAt(r, t);
  const lines = [r.name + ' at step ' + t + (r.finished[t] === '1' ? ': no reachable frontier left' : plan.length ? ': exploring' : ': choosing a target')];
  lines.push('true pose ' + fmt(p[0]) + ', ' + fmt(p[1]) + ' m, ' + deg(p[2]) + ' deg');
  if (D.estimates) lines.push('estimate  ' + fmt(e[0]) + ', ' + fmt(e[1]) + ' m, ' + deg(e[2]) + ' deg (error ' +
                             fmt(Math.hypot(e[0] - p[0], e[1] - p[1]), 3) + ' m)');
  if (plan.length) {
    const goal = apply(F, plan[plan.length - 1][0], plan[plan.length - 1][1]);
    let len = 0, prev = applyInv(F, e[0], e[1]);
    for (const q of plan) { len += Math.hypot(q[0] - prev[0], q[1] - prev[1]); prev = q; }
    lines.push('target    ' + fmt(goal[0]) + ', ' + fmt(goal[1]) + ' m, ' + fmt(len, 1) + ' m of path left');
  }
  lines.push('travelled ' + fmt(travelled[i][t], 1) + ' m');
  let last = null;
  for (const ev of D.events) if (ev.step <= t && (ev.robot === i || ev.other === i) && ev.kind !== 'blocked') last = ev;
  if (last) lines.push('last event: step ' + last.step + ', ' + last.kind + ': ' + eventText(last));
  if (why) lines.push(wrap('why its target: ' + whyText(i, decisionAt(i, t)), 80));
  return lines.join('\n');
}
function eventText(e) {
  const who = (e.robot >= 0 ? D.robots[e.robot].name : '') + (e.other >= 0 ? ' & ' + D.robots[e.other].name : '');
  return who + (e.text ? ' (' + e.text + ')' : '');
}

// Coverage curve and the events' timeline.
const KINDS = ['meeting', 'merge', 'refused merge', 'given up', 'blocked', 'finished'];
const KIND_COLORS = {'meeting': '#1f77b4', 'merge': '#2ca02c', 'refused merge': '#d62728', 'given up': '#7f7f7f', 'blocked': '#ff7f0e', 'finished': '#9467bd'};
const curve = document.getElementById('curve'), timeline = document.getElementById('timeline');
const PAD = 44;
function chartWidth() { return Math.max(500, Math.min(1400, window.innerWidth - 60)); }
function xOf(k) { return PAD + (curve.width - PAD - 10) * (S > 1 ? k / (S - 1) : 0); }
function stepOf(x) { return Math.round(Math.min(S - 1, Math.max(0, (x - PAD) / (curve.width - PAD - 10) * (S - 1)))); }
function drawCurve() {
  const ctx = curve.getContext('2d'), W = curve.width, H = curve.height, top = 8, bottom = H - 22;
  ctx.clearRect(0, 0, W, H);
  const y = v => bottom - (bottom - top) * v;
  ctx.strokeStyle = '#ddd'; ctx.fillStyle = '#555'; ctx.font = '11px sans-serif'; ctx.lineWidth = 1;
  for (const v of [0, 0.25, 0.5, 0.75, 1]) {
    ctx.beginPath(); ctx.moveTo(PAD, y(v)); ctx.lineTo(W - 10, y(v)); ctx.stroke();
    ctx.fillText(Math.round(v * 100) + '%', 6, y(v) + 4);
  }
  ctx.setLineDash([4, 4]); ctx.strokeStyle = '#aaa';
  for (const v of [0.95, 0.99]) { ctx.beginPath(); ctx.moveTo(PAD, y(v)); ctx.lineTo(W - 10, y(v)); ctx.stroke(); }
  ctx.setLineDash([]);
  const ticks = Math.max(1, Math.pow(10, Math.floor(Math.log10(Math.max(1, S - 1) / 2))));
  for (let k = 0; k < S; k += ticks * (S / ticks > 10 ? 2 : 1) * (S / ticks > 25 ? 2.5 : 1)) ctx.fillText(String(Math.round(k)), xOf(k) - 8, H - 6);
  ctx.beginPath();
  for (let k = 0; k < S; ++k) { if (k === 0) ctx.moveTo(xOf(k), y(D.coverage[k])); else ctx.lineTo(xOf(k), y(D.coverage[k])); }
  ctx.strokeStyle = '#1f77b4'; ctx.lineWidth = 2; ctx.stroke();
  ctx.strokeStyle = '#d62728'; ctx.lineWidth = 1.5;
  ctx.beginPath(); ctx.moveTo(xOf(t), top); ctx.lineTo(xOf(t), bottom); ctx.stroke();
  ctx.fillStyle = '#d62728';
  ctx.fillText((D.coverage[t] * 100).toFixed(1) + '%', Math.min(W - 50, xOf(t) + 4), y(D.coverage[t]) - 4);
}
function drawTimeline() {
  const ctx = timeline.getContext('2d'), W = timeline.width, H = timeline.height;
  ctx.clearRect(0, 0, W, H);
  const row = (H - 4) / KINDS.length;
  ctx.font = '10px sans-serif';
  KINDS.forEach((k, i) => { ctx.fillStyle = KIND_COLORS[k]; ctx.fillText(k.replace('refused merge', 'refused').replace('meeting', 'meet'), 0, 2 + row * (i + 0.8)); });
  for (const e of D.events) {
    const i = KINDS.indexOf(e.kind);
    if (i < 0) continue;
    ctx.fillStyle = KIND_COLORS[e.kind];
    ctx.fillRect(xOf(e.step) - 1, 2 + row * i, 2, row - 1);
  }
  ctx.strokeStyle = '#d62728'; ctx.lineWidth = 1.5;
  ctx.beginPath(); ctx.moveTo(xOf(t), 0); ctx.lineTo(xOf(t), H); ctx.stroke();
}

const eventsDiv = document.getElementById('events');
const eventRows = D.events.map(e => {
  const d = document.createElement('div');
  d.textContent = 'step ' + e.step + '  ' + e.kind + ': ' + eventText(e);
  d.style.borderLeft = '4px solid ' + (KIND_COLORS[e.kind] || '#999');
  d.onclick = () => go(e.step);
  eventsDiv.appendChild(d);
  return d;
});
let lastNow = null;
function markEvents() {
  let nowRow = null;
  D.events.forEach((e, i) => {
    const c = e.step < t ? 'past' : e.step === t ? 'now' : 'future';
    if (eventRows[i].className !== c) eventRows[i].className = c;
    if (c === 'now' && !nowRow) nowRow = eventRows[i];
  });
  if (nowRow && nowRow !== lastNow) eventsDiv.scrollTop = nowRow.offsetTop - eventsDiv.offsetTop - 40;
  lastNow = nowRow;
}

function layout() {
  curve.width = timeline.width = chartWidth();
}

function render() {
  slider.value = t;
  const sec = t * D.period;
  document.getElementById('stepText').textContent = 'step ' + t + ' of ' + (S - 1) + ' (' + fmt(sec, 0) + ' s), ' + (D.coverage[t] * 100).toFixed(1) + '%';
  drawMain();
  if (!onlyMap) { drawOwn(); renderWhy(); drawCurve(); drawTimeline(); markEvents(); }
  document.body.dataset.step = t;
  document.body.dataset.ready = '1';
  if (window.parent !== window) window.parent.postMessage({fleetmap: 'shown', name: window.name, step: t, height: document.body.scrollHeight,
                                                           why: (document.getElementById('whyText') || {}).textContent || ''}, '*');
}
function go(k) { t = Math.min(S - 1, Math.max(0, k)); render(); }

// Playing: `speed` steps per second, on animation frames.
let playing = false, lastTime = 0, carry = 0;
const playButton = document.getElementById('play');
function setPlaying(p) {
  playing = p;
  playButton.innerHTML = p ? '&#10074;&#10074; pause' : '&#9654; play';
  if (p) { if (t >= S - 1) go(0); lastTime = performance.now(); carry = 0; requestAnimationFrame(tick); }
}
function tick(now) {
  if (!playing) return;
  carry += (now - lastTime) / 1000 * parseFloat(document.getElementById('speed').value);
  lastTime = now;
  const whole = Math.floor(carry);
  if (whole > 0) { carry -= whole; go(t + whole); }
  if (t >= S - 1) { setPlaying(false); return; }
  requestAnimationFrame(tick);
}
playButton.onclick = () => setPlaying(!playing);
document.getElementById('prev').onclick = () => go(t - 1);
document.getElementById('next').onclick = () => go(t + 1);
slider.oninput = () => go(parseInt(slider.value, 10));
robotSelect.onchange = () => { robotSel = parseInt(robotSelect.value, 10); ownBox = null; render(); };
document.getElementById('overlays').onchange = e => { showOverlays = e.target.checked; render(); };
document.addEventListener('keydown', e => {
  if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT' && e.target.type !== 'range') return;
  if (e.key === ' ') { setPlaying(!playing); e.preventDefault(); }
  else if (e.key === 'ArrowLeft') { go(t - 1); e.preventDefault(); }
  else if (e.key === 'ArrowRight') { go(t + 1); e.preventDefault(); }
});

// Tooltips: a robot's state on the map; the events at a step on the timeline.
const tip = document.getElementById('tip');
function showTip(e, text) {
  if (!text) { tip.style.display = 'none'; return; }
  tip.textContent = text; tip.style.display = 'block';
  tip.style.left = Math.min(window.innerWidth - tip.offsetWidth - 8, e.clientX + 14) + 'px';
  tip.style.top = (e.clientY + 14) + 'px';
}
function canvasPoint(c, e) { const b = c.getBoundingClientRect(); return [(e.clientX - b.left) * c.width / b.width, (e.clientY - b.top) * c.height / b.height]; }
let hovered = -1;
main.addEventListener('mousemove', e => {
  const p = canvasPoint(main, e);
  let bestD = Math.max(12, parseFloat(main.dataset.rpx || 0) + 4);
  hovered = -1;
  robotPx.forEach((q, i) => { const d = Math.hypot(q[0] - p[0], q[1] - p[1]); if (d < bestD) { bestD = d; hovered = i; } });
  showTip(e, hovered >= 0 ? robotState(hovered, true) + '\n(click: show its own map and why it chose its target)' : '');
});
main.addEventListener('mouseleave', () => { hovered = -1; showTip(null, ''); });
main.addEventListener('click', () => {
  if (hovered < 0) return;
  robotSel = hovered; robotSelect.value = hovered; ownBox = null; render();
});
function eventsNear(x) {
  const out = [];
  for (const e of D.events) if (Math.abs(xOf(e.step) - x) <= 3) out.push('step ' + e.step + ' ' + e.kind + ': ' + eventText(e));
  if (out.length > 12) { const n = out.length; out.length = 12; out.push('... and ' + (n - 12) + ' more'); }
  return out.join('\n');
}
for (const c of [curve, timeline]) {
  c.addEventListener('mousemove', e => {
    const p = canvasPoint(c, e), k = stepOf(p[0]);
    const near = c === timeline ? eventsNear(p[0]) : '';
    showTip(e, 'step ' + k + ': ' + (D.coverage[k] * 100).toFixed(1) + '% covered' + (near ? '\n' + near : ''));
  });
  c.addEventListener('mouseleave', () => showTip(null, ''));
  c.addEventListener('click', e => go(stepOf(canvasPoint(c, e)[0])));
}

if (onlyMap) document.body.classList.add('only');
if (opts.embedded) document.body.classList.add('embedded');
// The comparison page moves both of its replays to one step.
window.addEventListener('message', e => { if (e.data && e.data.fleetmap === 'go') go(e.data.step); });
layout();
window.addEventListener('resize', () => { layout(); render(); });
render();
</script>
</body>
</html>
)JS";

}  // namespace

std::string replay_page(const std::string& title, const std::string& json) {
  std::string page;
  page.reserve(json.size() + 40000);
  page += page_head();
  page += html_escape(title);
  page += kStyle;
  page += page_style();
  page += kBody;
  page += json;
  page += kScript;
  return page;
}

}  // namespace fleetmap::viz
