// The comparison page: the replays inside it as text (each shown in a frame made from that text,
// so nothing is fetched), one slider for all, the coverage curves on one plot and a metrics table.
#include "viz/replay_compare.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <map>
#include <optional>

#include "core/error.h"
#include "viz/html.h"

namespace fleetmap::viz {

using nlohmann::json;

namespace {

constexpr std::string_view kDataStart = "<script type=\"application/json\" id=\"data\">";

// Text inside <script type="application/json">: no '<' may read as a closing tag.
std::string script_safe(const std::string& text) {
  std::string out;
  out.reserve(text.size() + text.size() / 50);
  for (char c : text) {
    if (c == '<') out += "\\u003c";
    else out += c;
  }
  return out;
}

// What the comparison page shows of a run without opening its frame.
json summary(const ComparedReplay& run) {
  json d;
  try {
    d = json::parse(replay_page_data(run.page, run.label));
  } catch (const json::exception& e) {
    throw InputError(run.label + ": not a fleetmap replay page (its data does not parse: " + e.what() + ")");
  }
  if (!d.contains("coverage") || !d.contains("robots") || !d.contains("facts"))
    throw InputError(run.label + ": not a fleetmap replay page (its data has no coverage, robots or facts)");
  // The distance the run reported (metrics.json's), which a page written before pages carried it lacks.
  std::optional<double> distance = 0.0;
  for (const auto& r : d["robots"]) {
    if (!r.contains("distance") || !r["distance"].is_number()) distance.reset();
    if (distance) *distance += r["distance"].get<double>();
  }
  std::map<std::string, int> events;
  for (const auto& e : d["events"]) ++events[e["kind"].get<std::string>()];
  int decisions = 0;
  for (const auto& r : d["robots"])
    if (r.contains("decisions")) decisions += int(r["decisions"].size());
  json out = {{"label", run.label},
             {"title", d.value("title", "")},
             {"facts", d["facts"]},
             {"coverage", d["coverage"]},
             {"period", d.value("period", 1.0)},
             {"robots", d["robots"].size()},
             {"strategy", d.contains("scores") ? d["scores"].value("strategy", "") : ""},
             {"events", events},
             {"decisions", decisions}};
  if (distance) out["distance"] = std::round(*distance * 10.0) / 10.0;
  return out;
}

constexpr std::string_view kStyle = R"HTML(</title>
<style>
.controls { display: flex; align-items: center; gap: 8px; margin: 6px 0; flex-wrap: wrap; position: sticky; top: 0;
            background: #fff; z-index: 5; padding: 4px 0; border-bottom: 1px solid #ddd; }
.controls input[type=range] { flex: 1; min-width: 300px; }
#stepText { font-variant-numeric: tabular-nums; }
.runs { display: flex; gap: 10px; align-items: flex-start; }
.run { flex: 1; min-width: 0; border: 1px solid #ddd; }
.run h2 { font-size: 14px; margin: 0; padding: 4px 6px; background: #f3f3f3; }
.run iframe { width: 100%; border: 0; height: 1000px; display: block; }
td.diff { color: #555; }
td.same { color: #aaa; }
</style>
)HTML";

constexpr std::string_view kBody = R"HTML(</head>
<body>
<h1 id="title">Comparing runs</h1>
<table id="metrics"></table>
<canvas id="curve" height="190"></canvas>
<div class="controls">
  <button id="play">&#9654; play</button>
  <button id="prev">&#9664;</button>
  <button id="next">&#9654;</button>
  <label>speed <select id="speed"><option>5</option><option>10</option><option selected>20</option><option>50</option><option>100</option></select> steps/s</label>
  <input type="range" id="slider" min="0" max="0" value="0" aria-label="step">
  <span id="stepText"></span>
</div>
<div class="runs" id="runs"></div>
<div id="tip"></div>
<script type="application/json" id="summary">)HTML";

constexpr std::string_view kScript = R"JS(</script>
<script>
"use strict";
const R = JSON.parse(document.getElementById('summary').textContent);
const pages = R.map((r, i) => JSON.parse(document.getElementById('page' + i).textContent));
const S = Math.max(...R.map(r => r.coverage.length));
const COLORS = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728'];
const opts = {};
for (const part of location.hash.replace(/^#/, '').split('&')) { const kv = part.split('='); if (kv[0]) opts[kv[0]] = decodeURIComponent(kv[1] || ''); }
let t = Math.min(S - 1, Math.max(0, parseInt(opts.step || '0', 10) || 0));
const esc = s => String(s).replace(/[&<>"]/g, c => ({'&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;'})[c]);
document.title = 'Comparing ' + R.map(r => r.label).join(' and ');
document.getElementById('title').textContent = 'Comparing ' + R.map(r => r.label).join(' and ');

// Metrics: every fact of the runs, then what the page counts from their data; differences against the first run.
function factOf(r, key) { const f = r.facts.find(f => f[0] === key); return f ? f[1] : undefined; }
const rows = [['title', r => r.title]];
for (const r of R) for (const f of r.facts) if (!rows.some(x => x[0] === f[0])) rows.push([f[0], q => factOf(q, f[0])]);
rows.push(['robots', r => r.robots], ['distance travelled (m)', r => r.distance], ['strategy decisions recorded', r => r.decisions]);
const kinds = [...new Set(R.flatMap(r => Object.keys(r.events)))].sort();
for (const k of kinds) rows.push(['events: ' + k, r => r.events[k] || 0]);
function number(v) { if (typeof v === 'number') return v; const m = /^(?:step )?(-?[0-9.]+)%?$/.exec(String(v)); return m ? parseFloat(m[1]) : NaN; }
let html = '<tr><th class="text">metric</th>' + R.map((r, i) => '<th class="text" style="color:' + COLORS[i] + '">' + esc(r.label) + '</th>').join('') +
           R.slice(1).map(r => '<th class="text">' + esc(r.label) + ' \u2212 ' + esc(R[0].label) + '</th>').join('') + '</tr>';
for (const [name, get] of rows) {
  const vals = R.map(get);
  html += '<tr><td class="text">' + esc(name) + '</td>' + vals.map(v => '<td class="text">' + esc(v === undefined ? '\u2013' : v) + '</td>').join('');
  for (let i = 1; i < R.length; ++i) {
    const a = number(vals[0]), b = number(vals[i]);
    if (String(vals[0]) === String(vals[i])) html += '<td class="text same">same</td>';
    else if (isFinite(a) && isFinite(b)) html += '<td class="diff">' + ((b - a) > 0 ? '+' : '') + +(b - a).toFixed(2) + (/%$/.test(String(vals[0])) ? ' points' : '') + '</td>';
    else html += '<td class="text diff">differs</td>';
  }
  html += '</tr>';
}
document.getElementById('metrics').innerHTML = html;

// The runs, each in a frame made from its page's text; a frame's name carries its options.
const frames = R.map((r, i) => {
  const box = document.createElement('div');
  box.className = 'run';
  box.innerHTML = '<h2 style="color:' + COLORS[i] + '">' + esc(r.label) + ': ' + esc(r.title) + '</h2>';
  const f = document.createElement('iframe');
  f.name = 'fleetmap:embedded=1&step=' + t + '&run=' + i;
  f.title = r.label;
  f.srcdoc = pages[i];
  box.appendChild(f);
  document.getElementById('runs').appendChild(box);
  return f;
});
const shown = R.map(() => -1);
window.addEventListener('message', e => {
  const m = e.data;
  if (!m || m.fleetmap !== 'shown') return;
  const i = frames.findIndex(f => f.contentWindow === e.source);
  if (i < 0) return;
  shown[i] = m.step;
  if (m.height) frames[i].style.height = (m.height + 20) + 'px';
  document.body.dataset['shown' + i] = m.step;
  document.body.dataset['why' + i] = m.why || '';
  stepText();
});

const curve = document.getElementById('curve'), PAD = 44;
curve.width = Math.max(500, Math.min(1400, window.innerWidth - 40));
const xOf = k => PAD + (curve.width - PAD - 10) * (S > 1 ? k / (S - 1) : 0);
const stepOf = x => Math.round(Math.min(S - 1, Math.max(0, (x - PAD) / (curve.width - PAD - 10) * (S - 1))));
function cov(r, k) { return r.coverage[Math.min(k, r.coverage.length - 1)]; }
function drawCurve() {
  const ctx = curve.getContext('2d'), W = curve.width, H = curve.height, top = 8, bottom = H - 22;
  ctx.clearRect(0, 0, W, H);
  const y = v => bottom - (bottom - top) * v;
  ctx.strokeStyle = '#ddd'; ctx.fillStyle = '#555'; ctx.font = '11px sans-serif'; ctx.lineWidth = 1;
  for (const v of [0, 0.25, 0.5, 0.75, 1]) { ctx.beginPath(); ctx.moveTo(PAD, y(v)); ctx.lineTo(W - 10, y(v)); ctx.stroke(); ctx.fillText(Math.round(v * 100) + '%', 6, y(v) + 4); }
  ctx.setLineDash([4, 4]); ctx.strokeStyle = '#aaa';
  for (const v of [0.95, 0.99]) { ctx.beginPath(); ctx.moveTo(PAD, y(v)); ctx.lineTo(W - 10, y(v)); ctx.stroke(); }
  ctx.setLineDash([]);
  for (let k = 0; k < S; k += Math.max(1, Math.pow(10, Math.floor(Math.log10(Math.max(1, S - 1))))) / (S > 500 ? 1 : 2)) ctx.fillText(String(Math.round(k)), xOf(k) - 8, H - 6);
  R.forEach((r, i) => {
    ctx.beginPath();
    r.coverage.forEach((c, k) => { if (k === 0) ctx.moveTo(xOf(k), y(c)); else ctx.lineTo(xOf(k), y(c)); });
    ctx.strokeStyle = COLORS[i]; ctx.lineWidth = 2; ctx.stroke();
    ctx.fillStyle = COLORS[i]; ctx.fillText(r.label, W - 10 - ctx.measureText(r.label).width, y(0.1) + 14 * i);
  });
  ctx.strokeStyle = '#d62728'; ctx.lineWidth = 1.5; ctx.beginPath(); ctx.moveTo(xOf(t), top); ctx.lineTo(xOf(t), bottom); ctx.stroke();
}
function stepText() {
  const parts = R.map((r, i) => r.label + ' ' + (100 * cov(r, t)).toFixed(1) + '%' + (t >= r.coverage.length ? ' (ended at step ' + (r.coverage.length - 1) + ')' : ''));
  const d = R.slice(1).map(r => r.label + ' \u2212 ' + R[0].label + ' ' + (100 * (cov(r, t) - cov(R[0], t))).toFixed(1) + ' points');
  document.getElementById('stepText').textContent = 'step ' + t + ' of ' + (S - 1) + ': ' + parts.join(', ') + (d.length ? '; ' + d.join(', ') : '');
}
const slider = document.getElementById('slider');
slider.max = S - 1;
function go(k) {
  t = Math.min(S - 1, Math.max(0, k));
  slider.value = t;
  drawCurve(); stepText();
  for (const f of frames) if (f.contentWindow) f.contentWindow.postMessage({fleetmap: 'go', step: t}, '*');
  document.body.dataset.step = t;
}
slider.oninput = () => go(parseInt(slider.value, 10));
document.getElementById('prev').onclick = () => go(t - 1);
document.getElementById('next').onclick = () => go(t + 1);
curve.addEventListener('click', e => { const b = curve.getBoundingClientRect(); go(stepOf((e.clientX - b.left) * curve.width / b.width)); });
let playing = false, last = 0, carry = 0;
const play = document.getElementById('play');
function setPlaying(p) {
  playing = p; play.innerHTML = p ? '&#10074;&#10074; pause' : '&#9654; play';
  if (p) { if (t >= S - 1) go(0); last = performance.now(); carry = 0; requestAnimationFrame(tick); }
}
function tick(now) {
  if (!playing) return;
  carry += (now - last) / 1000 * parseFloat(document.getElementById('speed').value); last = now;
  const whole = Math.floor(carry);
  if (whole > 0) { carry -= whole; go(t + whole); }
  if (t >= S - 1) { setPlaying(false); return; }
  requestAnimationFrame(tick);
}
play.onclick = () => setPlaying(!playing);
document.addEventListener('keydown', e => {
  if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT' && e.target.type !== 'range') return;
  if (e.key === ' ') { setPlaying(!playing); e.preventDefault(); }
  else if (e.key === 'ArrowLeft') { go(t - 1); e.preventDefault(); }
  else if (e.key === 'ArrowRight') { go(t + 1); e.preventDefault(); }
});
slider.value = t;
drawCurve(); stepText();
document.body.dataset.step = t;
document.body.dataset.ready = '1';
</script>
</body>
</html>
)JS";

}  // namespace

std::string replay_page_data(std::string_view page, const std::string& name) {
  const auto start = page.find(kDataStart);
  const auto end = start == std::string_view::npos ? start : page.find("</script>", start);
  if (start == std::string_view::npos || end == std::string_view::npos || page.find("fleetmap") == std::string_view::npos)
    throw InputError(name + ": not a fleetmap replay page (no replay data in it; fleetmap explore --html writes one)");
  return std::string(page.substr(start + kDataStart.size(), end - start - kDataStart.size()));
}

std::string replay_comparison_html(const std::vector<ComparedReplay>& runs) {
  if (runs.size() < 2) throw InputError("a comparison needs two replay pages");
  json summaries = json::array();
  for (const auto& r : runs) summaries.push_back(summary(r));
  std::string title = "Comparing";
  for (std::size_t i = 0; i < runs.size(); ++i) title += (i == 0 ? " " : " and ") + runs[i].label;
  std::string page;
  std::size_t size = 0;
  for (const auto& r : runs) size += r.page.size() + r.page.size() / 8;
  page.reserve(size + 30000);
  page += page_head();
  page += html_escape(title);
  page += kStyle;
  page += page_style();
  page += kBody;
  page += script_safe(summaries.dump());
  page += "</script>\n";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    page += fmt::format("<script type=\"application/json\" id=\"page{}\">", i);
    page += script_safe(json(runs[i].page).dump(-1, ' ', false, json::error_handler_t::replace));
    page += "</script>\n";
  }
  page += kScript.substr(std::string_view("</script>\n").size());
  return page;
}

}  // namespace fleetmap::viz
