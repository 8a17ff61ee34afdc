#include "report.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

namespace obsgroup::cli {

namespace {

/// At most this many observation dots on the page: beyond, every k-th (the
/// places' outlines and table hold the rest).
constexpr std::size_t kMaxDots = 20000;

// The page: the data goes in as JSON, the script builds the map and the
// tables from it with DOM calls (every text through textContent, never
// parsed as HTML).
constexpr const char* kHead = R"html(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>obsgroup report</title>
<style>
  body { font: 14px/1.4 system-ui, sans-serif; margin: 0; color: #222; background: #fafafa; }
  header { padding: 10px 16px; background: #263238; color: #fff; }
  header h1 { font-size: 18px; margin: 0; }
  header p { margin: 2px 0 0; color: #cfd8dc; }
  main { display: flex; gap: 12px; padding: 12px 16px; align-items: flex-start; }
  #mapbox { flex: 1; min-width: 0; background: #fff; border: 1px solid #ddd; }
  #map { display: block; width: 100%; height: 70vh; }
  #map .place { fill-opacity: 0.28; stroke-width: 1.5px; vector-effect: non-scaling-stroke; cursor: pointer; }
  #map .place:hover, #map .place.sel { fill-opacity: 0.6; stroke-width: 3px; }
  #map .dots { fill: none; stroke-linecap: round; cursor: pointer; vector-effect: non-scaling-stroke; }
  #map .door { stroke: #000; stroke-width: 4px; vector-effect: non-scaling-stroke; }
  #map text { font-weight: 700; text-anchor: middle; dominant-baseline: central; pointer-events: none;
              paint-order: stroke; stroke: #fff; stroke-width: 3px; vector-effect: non-scaling-stroke; }
  #panel { width: 360px; flex: none; background: #fff; border: 1px solid #ddd; padding: 10px 12px; }
  #panel h2 { margin: 0 0 6px; font-size: 17px; }
  #panel img { width: 100%; border: 1px solid #eee; margin-top: 8px; }
  #panel dl { display: grid; grid-template-columns: auto 1fr; gap: 2px 10px; margin: 0; }
  #panel dt { color: #666; } #panel dd { margin: 0; overflow-wrap: anywhere; }
  .swatch { display: inline-block; width: 12px; height: 12px; border-radius: 2px; margin-right: 6px;
            vertical-align: -1px; }
  a.place-link { color: #1565c0; cursor: pointer; text-decoration: underline; margin-right: 6px; }
  section { padding: 0 16px 12px; }
  table { border-collapse: collapse; background: #fff; }
  th, td { border: 1px solid #ddd; padding: 3px 8px; text-align: left; vertical-align: top; }
  th { background: #eceff1; }
  #places tbody tr { cursor: pointer; } #places tbody tr:hover, #places tbody tr.sel { background: #e3f2fd; }
  td.num { text-align: right; font-variant-numeric: tabular-nums; }
  .columns { display: flex; gap: 16px; flex-wrap: wrap; align-items: flex-start; }
  .warnings li { color: #8d4b00; }
</style>
</head>
<body>
<header><h1 id="title">obsgroup report</h1><p id="subtitle"></p></header>
<main>
  <div id="mapbox"><svg id="map" xmlns="http://www.w3.org/2000/svg" role="img" aria-label="the places"></svg></div>
  <aside id="panel"><h2>Places</h2><p id="hint">Point at a place or click it (or a row of the table) for its
  members, neighbours and local map.</p></aside>
</main>
<section><h2>Places</h2><table id="places"><thead><tr><th>place</th><th>observations</th><th>members</th>
<th>area (m²)</th><th>time span (from the first observation)</th><th>neighbours</th></tr></thead><tbody></tbody>
</table></section>
<section class="columns">
  <div><h2>Parameters</h2><table id="parameters"></table></div>
  <div><h2>Statistics</h2><table id="statistics"></table></div>
  <div><h2>Timings (s)</h2><table id="timings"></table></div>
</section>
<section><h2>Warnings</h2><ul id="warnings" class="warnings"></ul></section>
<script id="data" type="application/json">)html";

constexpr const char* kTail = R"html(</script>
<script>
"use strict";
const D = JSON.parse(document.getElementById("data").textContent);
const SVG = "http://www.w3.org/2000/svg";
const groups = D.groups, ids = D.place_ids, G = groups.length;
const groupOfId = new Map(ids.map((id, g) => [id, g]));
const placeOf = new Map((D.places || []).map(p => [p.id, p]));
const el = (tag, attrs, parent, ns) => {
  const e = ns ? document.createElementNS(SVG, tag) : document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
};
const text = (tag, value, parent) => { const e = el(tag, {}, parent); e.textContent = value; return e; };
const fmt = (x, d) => Number(x).toFixed(d);

function ranges(members) {  // [0,1,2,5,7,8] -> "0-2, 5, 7-8"
  const out = [];
  for (let i = 0; i < members.length;) {
    let j = i;
    while (j + 1 < members.length && members[j + 1] === members[j] + 1) ++j;
    out.push(i === j ? String(members[i]) : members[i] + "-" + members[j]);
    i = j + 1;
  }
  return out.join(", ");
}
const start = D.stamps ? Math.min(...D.stamps.filter(Number.isFinite)) : 0;
function span(members) {  // seconds from the run's first stamp
  if (!D.stamps) return "";
  let lo = Infinity, hi = -Infinity;
  for (const i of members) { const t = D.stamps[i]; if (t < lo) lo = t; if (t > hi) hi = t; }
  return lo === Infinity ? "" : fmt(lo - start, 1) + " to " + fmt(hi - start, 1) + " s (" + fmt(hi - lo, 1) + " s)";
}

// --- the map: y up, in metres ---
const svg = document.getElementById("map");
let minX = Infinity, minY = Infinity, maxX = -Infinity, maxY = -Infinity;
const grow = (x, y) => { minX = Math.min(minX, x); maxX = Math.max(maxX, x); minY = Math.min(minY, y); maxY = Math.max(maxY, y); };
for (const p of D.places || []) for (const ring of p.outline) for (const [x, y] of ring) grow(x, y);
for (const [x, y] of D.positions) grow(x, y);
if (minX === Infinity) { minX = minY = 0; maxX = maxY = 1; }
const pad = 0.03 * Math.max(maxX - minX, maxY - minY, 1);
svg.setAttribute("viewBox", [minX - pad, -maxY - pad, maxX - minX + 2 * pad, maxY - minY + 2 * pad].join(" "));
const size = Math.max(maxX - minX, maxY - minY, 1);
const layer = name => el("g", { class: name }, svg, true);
const outlines = layer("outlines"), dotLayer = layer("dot-layer"), doorLayer = layer("doors"), labels = layer("labels");
const shapes = Array.from({ length: G }, () => []);
for (const p of D.places || []) {
  const g = groupOfId.get(p.id);
  if (g === undefined || !p.outline.length) continue;
  const d = p.outline.map(r => "M" + r.map(([x, y]) => fmt(x, 3) + "," + fmt(-y, 3)).join("L") + "Z").join("");
  const path = el("path", { d, class: "place", fill: D.colours[g], stroke: D.colours[g], "fill-rule": "evenodd",
                            "data-group": g }, outlines, true);
  text("title", "place " + p.id + ": " + groups[g].length + " observations", path);
  shapes[g].push(path);
}
const dotPaths = Array.from({ length: G }, () => "");
for (const [x, y, g] of D.positions) dotPaths[g] += "M" + fmt(x, 3) + "," + fmt(-y, 3) + "h0";
dotPaths.forEach((d, g) => {
  if (!d) return;
  const path = el("path", { d, class: "dots", stroke: D.colours[g], "stroke-width": 5, "data-group": g }, dotLayer, true);
  text("title", "place " + ids[g] + ": " + groups[g].length + " observations", path);
  shapes[g].push(path);
});
for (const door of D.doors || []) {
  const [[x1, y1], [x2, y2]] = door.segment;
  const line = el("line", { x1, y1: -y1, x2, y2: -y2, class: "door" }, doorLayer, true);
  text("title", "door between places " + door.places.join(" and ") + ", " + fmt(door.width_m, 2) + " m", line);
}
for (let g = 0; g < G; ++g) {
  const p = placeOf.get(ids[g]);
  let c = p && p.outline.length ? (p.label_point || p.centroid) : null;
  if (!c) {  // no floor: the mean of its dots
    let sx = 0, sy = 0, n = 0;
    for (const [x, y, h] of D.positions) if (h === g) { sx += x; sy += y; ++n; }
    if (n) c = [sx / n, sy / n];
  }
  if (c) { const t = el("text", { x: c[0], y: -c[1], "font-size": size / 40 }, labels, true); t.textContent = ids[g]; }
}

// --- the panel ---
const panel = document.getElementById("panel");
let selected = -1;
function show(g) {
  panel.replaceChildren();
  if (g < 0) { text("h2", "Places", panel); text("p", G + " places: point at one or click it.", panel); return; }
  const id = ids[g], p = placeOf.get(id), members = groups[g];
  const h = text("h2", "", panel);
  el("span", { class: "swatch", style: "background:" + D.colours[g] }, h);
  h.appendChild(document.createTextNode("Place " + id));
  const dl = el("dl", {}, panel);
  const row = (k, v) => { text("dt", k, dl); return text("dd", v, dl); };
  row("observations", String(members.length));
  row("members", ranges(members));
  if (D.stamps) row("time span", span(members));
  if (p) {
    row("area", fmt(p.area_m2, 1) + " m²");
    row("centroid", p.centroid.map(v => fmt(v, 2)).join(", ") + " m");
    const nb = row("neighbours", p.neighbours.length ? "" : "none");
    for (const n of p.neighbours) {
      const a = text("a", String(n), nb);
      a.className = "place-link";
      a.onclick = () => select(groupOfId.get(n));
    }
    const doors = (D.doors || []).filter(d => d.places.includes(id));
    row("doors", doors.length ? doors.map(d => "to " + d.places.find(q => q !== id) + " (" + fmt(d.width_m, 2) + " m)").join(", ") : "none");
  }
  if (D.pictures[g]) {
    const img = el("img", { alt: "local map of place " + id }, panel);
    img.src = D.pictures[g];
  }
}
function mark(g, on) { for (const s of shapes[g] || []) s.classList.toggle("sel", on); }
function select(g) {
  if (selected >= 0) { mark(selected, false); rows[selected].classList.remove("sel"); }
  selected = g;
  if (g >= 0) { mark(g, true); rows[g].classList.add("sel"); history.replaceState(null, "", "#place=" + ids[g]); }
  show(g);
}
shapes.forEach((list, g) => list.forEach(s => {
  s.addEventListener("click", () => select(g));
  s.addEventListener("mouseenter", () => show(g));
  s.addEventListener("mouseleave", () => show(selected));
}));

// --- the tables ---
const body = document.querySelector("#places tbody");
const rows = groups.map((members, g) => {
  const p = placeOf.get(ids[g]), tr = el("tr", {}, body);
  const first = el("td", {}, tr);
  el("span", { class: "swatch", style: "background:" + D.colours[g] }, first);
  first.appendChild(document.createTextNode(ids[g]));
  text("td", String(members.length), tr).className = "num";
  text("td", ranges(members), tr);
  text("td", p ? fmt(p.area_m2, 1) : "", tr).className = "num";
  text("td", span(members), tr);
  text("td", p ? p.neighbours.join(", ") : "", tr);
  tr.onclick = () => select(g);
  return tr;
});
function keyValues(table, object) {
  for (const [k, v] of Object.entries(object || {})) {
    const tr = el("tr", {}, document.getElementById(table));
    text("th", k, tr);
    text("td", typeof v === "object" && v !== null ? JSON.stringify(v) : String(v), tr);
  }
}
keyValues("parameters", D.parameters);
keyValues("statistics", D.statistics);
keyValues("timings", D.timing_s);
const warnings = document.getElementById("warnings");
for (const w of D.warnings) text("li", w, warnings);
if (!D.warnings.length) text("li", "none", warnings).style.color = "#666";
document.getElementById("title").textContent = "obsgroup: " + D.input;
document.title = "obsgroup report: " + D.input;
document.getElementById("subtitle").textContent = D.observations + " observations, " + G + " places" +
  (D.places ? ", " + (D.doors || []).length + " doors" : "") + (D.parameters.format ? " (" + D.parameters.format + ")" : "");
function selectFromHash() {  // "#place=12": a link to a place
  const wanted = /^#place=(-?\d+)$/.exec(location.hash);
  select(wanted && groupOfId.has(Number(wanted[1])) ? groupOfId.get(Number(wanted[1])) : -1);
}
window.addEventListener("hashchange", selectFromHash);
selectFromHash();
</script>
</body>
</html>
)html";

/// JSON safe inside a <script> element: no "</" (which would end it) and no
/// "<!--"; invalid UTF-8 (a file name, say) replaced, not an error.
std::string scriptJson(const nlohmann::json& data) {
  std::string json = data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(json.size());
  for (std::size_t i = 0; i < json.size(); ++i) {
    if (json[i] == '<' && i + 1 < json.size() && (json[i + 1] == '/' || json[i + 1] == '!')) {
      out += "\\u003c";
      continue;
    }
    out += json[i];
  }
  return out;
}

}  // namespace

std::string pngDataUri(const std::string& bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out = "data:image/png;base64,";
  out.reserve(out.size() + (bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (unsigned char)bytes[i] << 16 | (unsigned char)bytes[i + 1] << 8 | (unsigned char)bytes[i + 2];
    for (int shift : {18, 12, 6, 0}) out += kDigits[(v >> shift) & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const unsigned v = (unsigned char)bytes[i] << 16 | (two ? (unsigned char)bytes[i + 1] << 8 : 0u);
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += two ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string reportHtml(const ReportInput& input) {
  const nlohmann::json& run = input.partition;
  nlohmann::json data = {{"input", run.value("input", "")},
                         {"observations", run.value("observations", 0)},
                         {"groups", run.at("groups")},
                         {"place_ids", run.at("place_ids")},
                         {"stamps", run.value("stamps", nlohmann::json())},
                         {"parameters", run.value("parameters", nlohmann::json::object())},
                         {"statistics", run.value("statistics", nlohmann::json::object())},
                         {"timing_s", run.value("timing_s", nlohmann::json::object())},
                         {"warnings", run.value("warnings", nlohmann::json::array())},
                         {"colours", input.colours},
                         {"pictures", input.pictures}};
  if (input.places.is_object()) {
    data["places"] = input.places.at("places");
    data["doors"] = input.places.at("doors");
  } else {
    data["places"] = nullptr;
    data["doors"] = nlohmann::json::array();
  }
  const std::size_t step = std::max<std::size_t>(1, (input.positions.size() + kMaxDots - 1) / kMaxDots);
  nlohmann::json positions = nlohmann::json::array();
  for (std::size_t i = 0; i < input.positions.size(); i += step) {
    const auto& p = input.positions[i];
    positions.push_back({std::round(p.x * 1000) / 1000, std::round(p.y * 1000) / 1000, p.group});
  }
  data["positions"] = std::move(positions);
  return std::string(kHead) + scriptJson(data) + kTail;
}

}  // namespace obsgroup::cli
