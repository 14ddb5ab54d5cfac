// The class's statistics: the mean learning curve with its 95 % interval across students (blocks shaded, the
// after-effect marked, n shown), the class's answer in one line, the generalization by direction when the protocol
// probes directions, and two groups side by side in a classroom experiment. Every number comes from /api/lab
// (armgame/lab/classstats.py); this page only draws.
"use strict";

const NS = "http://www.w3.org/2000/svg";
const MEASURES = {
  max_perpendicular_error_m: "largest sideways error",
  initial_direction_error_deg: "initial direction error",
};

// A label drawn past the drawing's edge (a short block's name at the right end) is moved in, whole.
function keepInside(node, W) {
  const b = node.getBBox();
  const dx = Math.min(0, W - 2 - (b.x + b.width)) + Math.max(0, 2 - b.x);
  if (dx !== 0) node.setAttribute("x", String(Number(node.getAttribute("x")) + dx));
  return node;
}

function el(name, attrs, text) {
  const node = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, String(v));
  if (text !== undefined) node.textContent = text;
  return node;
}

function fixed(v) { return v.toFixed(Math.abs(v) < 10 ? 1 : 0); }

// The SVG's own size, as CSS laid it out; the plot inside it leaves room for its labels (`margin`: each side's
// share of the width, left and right).
function frame(svg, margin = [0.1, 0.02]) {
  svg.replaceChildren();
  const box = svg.getBoundingClientRect();
  const W = Math.max(box.width, 200), H = Math.max(box.height, 150);
  svg.setAttribute("viewBox", "0 0 " + W + " " + H);
  return {W, H, left: W * margin[0], right: W * (1 - margin[1]), top: H * 0.12, bottom: H * 0.84};
}

// One learning-curve panel: `blocks` (the trials' block and perturbation, for the shading), `series` (each
// {points: [{trial, mean, low, high}], cls}), in `unit`; lo and hi shared when panels are compared.
function drawCurve(svg, blocks, series, unit, range) {
  const f = frame(svg);
  const {W, H, left, right, top, bottom} = f;
  const [lo, hi] = range;
  const first = blocks[0].trial, last = blocks[blocks.length - 1].trial;
  const x = (k) => left + (right - left) * (last > first ? (k - first) / (last - first) : 0.5);
  const y = (v) => bottom - (bottom - top) * (v - lo) / (hi - lo);
  let start = 0, shade = true;
  for (let i = 1; i <= blocks.length; i++) {
    if (i === blocks.length || blocks[i].block !== blocks[start].block) {
      const x0 = x(blocks[start].trial - 0.5), x1 = x(blocks[i - 1].trial + 0.5);
      if (shade) {
        svg.appendChild(el("rect", {class: "block", x: x0, y: top, width: Math.max(x1 - x0, 1), height: bottom - top}));
      }
      shade = !shade;
      keepInside(svg.appendChild(el("text", {x: (x0 + x1) / 2, y: top - 8, "text-anchor": "middle"},
                                 blocks[start].block)), W);
      // The after-effect: the first trial back without the perturbation after trials with it.
      if (start > 0 && blocks[start].perturbation === "none" && blocks[start - 1].perturbation !== "none") {
        const at = x(blocks[start].trial), leftward = at > (left + right) / 2;
        svg.appendChild(el("line", {class: "marker", x1: at, x2: at, y1: top, y2: bottom}));
        keepInside(svg.appendChild(el("text", {class: "news", x: leftward ? at - 6 : at + 6, y: top + 24,
                                            "text-anchor": leftward ? "end" : "start"}, "after-effect")), W);
      }
      start = i;
    }
  }
  for (const s of series) {
    const upper = [], lower = [];
    let path = "";
    for (const p of s.points) {
      if (p.mean === null) continue;
      if (p.low !== null && p.high !== null) {
        upper.push(x(p.trial) + "," + y(p.high));
        lower.unshift(x(p.trial) + "," + y(p.low));
      }
      path += (path ? " L" : "M") + x(p.trial) + "," + y(p.mean);
    }
    if (upper.length) svg.appendChild(el("polygon", {class: "band " + s.cls, points: upper.concat(lower).join(" ")}));
    svg.appendChild(el("path", {class: "mean " + s.cls, d: path}));
  }
  if (lo < 0 && hi > 0) svg.appendChild(el("line", {class: "zero", x1: left, x2: right, y1: y(0), y2: y(0)}));
  svg.appendChild(el("line", {class: "axis", x1: left, x2: right, y1: bottom, y2: bottom}));
  svg.appendChild(el("text", {x: x(first), y: bottom + 24, "text-anchor": "middle"}, String(first)));
  svg.appendChild(el("text", {x: x(last), y: bottom + 24, "text-anchor": "middle"}, String(last)));
  svg.appendChild(el("line", {class: "axis", x1: left, x2: left, y1: top, y2: bottom}));
  svg.appendChild(el("text", {x: (left + right) / 2, y: H - 8, "text-anchor": "middle"}, "trial"));
  svg.appendChild(el("text", {x: left - 8, y: y(hi), "text-anchor": "end"}, fixed(hi)));
  svg.appendChild(el("text", {x: left - 8, y: y(lo), "text-anchor": "end"}, fixed(lo)));
  if (lo < 0 && hi > 0) svg.appendChild(el("text", {x: left - 8, y: y(0), "text-anchor": "end"}, "0"));
  svg.appendChild(el("text", {x: left, y: top - 8 - H * 0.03}, unit));
}

// The range every series' means and intervals take, 0 included.
function rangeOf(seriesList) {
  const values = [0];
  for (const s of seriesList) for (const p of s.points) {
    for (const v of [p.mean, p.low, p.high]) if (v !== null && v !== undefined) values.push(v);
  }
  const lo = Math.min(...values);
  let hi = Math.max(...values);
  if (hi - lo < 1e-9) hi = lo + 1;
  return [lo, hi];
}

// A statistics block's series: the mean curve with its band, or with fewer than three students their own curves.
function seriesOf(stats, cls) {
  if (stats.own.length) {
    return stats.own.map((o, i) => ({cls: cls + " own own-" + (i % 3),
      points: o.points.map(([trial, v]) => ({trial, mean: v, low: null, high: null}))}));
  }
  return [{cls, points: stats.curve}];
}

function nWords(stats) {
  const ns = stats.curve.map((p) => p.n);
  const a = Math.min(...ns), b = Math.max(...ns);
  return "n = " + (a === b ? a : a + " to " + b) + " per trial";
}

// The generalization by direction: one point per probed direction (its angle from the trained one) with its
// interval across students.
function drawGeneral(svg, points, unit) {
  const {W, H, left, right, top, bottom} = frame(svg, [0.16, 0.06]);
  const values = [0];
  for (const p of points) for (const v of [p.mean, p.low, p.high]) if (v !== null) values.push(v);
  const lo = Math.min(...values);
  let hi = Math.max(...values);
  if (hi - lo < 1e-9) hi = lo + 1;
  const x = (a) => left + (right - left) * (a + 180) / 360;
  const y = (v) => bottom - (bottom - top) * (v - lo) / (hi - lo);
  if (lo < 0 && hi > 0) svg.appendChild(el("line", {class: "zero", x1: left, x2: right, y1: y(0), y2: y(0)}));
  svg.appendChild(el("line", {class: "axis", x1: left, x2: right, y1: bottom, y2: bottom}));
  svg.appendChild(el("line", {class: "axis", x1: left, x2: left, y1: top, y2: bottom}));
  let path = "";
  for (const p of points) {
    if (p.mean === null) continue;
    if (p.low !== null) svg.appendChild(el("line", {class: "bar", x1: x(p.angle_deg), x2: x(p.angle_deg),
                                                     y1: y(p.low), y2: y(p.high)}));
    svg.appendChild(el("circle", {class: "dot", cx: x(p.angle_deg), cy: y(p.mean), r: 5}));
    path += (path ? " L" : "M") + x(p.angle_deg) + "," + y(p.mean);
  }
  svg.appendChild(el("path", {class: "mean", d: path}));
  for (const a of [-180, -90, 0, 90, 180]) {
    keepInside(svg.appendChild(el("text", {x: x(a), y: bottom + 24, "text-anchor": "middle"}, String(a))), W);
  }
  keepInside(svg.appendChild(el("text", {x: (left + right) / 2, y: H - 8, "text-anchor": "middle"},
                                 "degrees from the trained direction")), W);
  svg.appendChild(el("text", {x: left - 8, y: y(hi), "text-anchor": "end"}, fixed(hi)));
  svg.appendChild(el("text", {x: left - 8, y: y(lo), "text-anchor": "end"}, fixed(lo)));
  svg.appendChild(el("text", {x: left, y: top - 8}, unit || "adaptation index"));
  keepInside(svg.lastChild, W);
}

function draw(lab) {
  const facts = document.getElementById("facts");
  const answer = document.getElementById("answer");
  const general = document.getElementById("general");
  const groups = document.getElementById("groups");
  const curve = document.getElementById("curve");
  // A classroom experiment: the two groups side by side take the curve's place (group A's alone would mislead).
  const split = Boolean(lab.groups && (lab.groups.a.stats || lab.groups.b.stats));
  groups.hidden = !split;
  curve.parentElement.hidden = split;
  if (split) {
    document.getElementById("title").textContent = "A classroom experiment: two groups";
    facts.textContent = (MEASURES[lab.groups.metric] || "error") + ", each group's mean and 95 % interval " +
      "across its students; assigned at random: " + lab.groups.a.assigned + " and " + lab.groups.b.assigned;
    answer.textContent = "The class's answer: " + lab.groups.difference_words;
    general.hidden = true;
    drawGroups(lab);
    document.body.dataset.students = String(lab.groups.a.students + lab.groups.b.students);
    return;
  }
  if (!lab.protocol || lab.trials.length === 0 || !lab.stats) {
    facts.textContent = "waiting for the first volunteer's run" +
      (lab.programs ? " (" + lab.programs + " program runs are not in the curve)" : "");
    answer.textContent = "";
    document.getElementById("curve").replaceChildren();
    general.hidden = true;
    groups.hidden = true;
    return;
  }
  const stats = lab.stats;
  document.getElementById("title").textContent = "Learning curve: " + lab.protocol;
  const measure = (MEASURES[lab.metric] || lab.metric) + " (" + lab.unit + ")";
  facts.textContent = lab.students + (lab.students === 1 ? " student" : " students") + " · " + measure + ", " +
    (stats.own.length ? "each student's own curve (too few for an interval)"
                      : "mean and 95 % interval across students, " + nWords(stats));
  answer.textContent = "The class's answer: " + stats.answer;
  const series = seriesOf(stats, "all");
  drawCurve(document.getElementById("curve"), stats.curve, series, lab.unit, rangeOf(series));
  general.hidden = stats.generalization.length === 0;
  if (!general.hidden) {
    drawGeneral(document.getElementById("general-plot"), stats.generalization, stats.probe_unit);
  }
  document.body.dataset.students = String(lab.students);
}

// A classroom experiment: the two groups' curves side by side on one scale, each with its interval and n, and
// the difference with Welch's interval under them.
function drawGroups(lab) {
  const g = lab.groups;
  const both = [g.a.stats ? seriesOf(g.a.stats, "a") : [], g.b.stats ? seriesOf(g.b.stats, "b") : []];
  const range = rangeOf(both.flat());
  for (const [key, s] of [["a", both[0]], ["b", both[1]]]) {
    const side = g[key];
    const svg = document.getElementById("group-" + key);
    const title = document.getElementById("group-" + key + "-title");
    if (!side.stats) {
      title.textContent = side.name + ": " + side.protocol + " · no run yet";
      svg.replaceChildren();
      continue;
    }
    title.textContent = side.name + ": " + side.protocol + " · " + side.students + " students · " +
      (side.stats.own.length ? "their own curves" : nWords(side.stats));
    drawCurve(svg, side.stats.curve, s, g.unit, range);
  }
  document.getElementById("difference").textContent = g.difference_words;
}

let latest = null;
const source = new EventSource("/events");
source.addEventListener("lab", (e) => {
  latest = JSON.parse(e.data);
  document.getElementById("link").hidden = true;
  draw(latest);
});
source.onerror = () => { document.getElementById("link").hidden = false; };
window.addEventListener("resize", () => { if (latest) draw(latest); });
