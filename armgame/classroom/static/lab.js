// The class's learning curve: mean and s.e.m. per trial, blocks shaded, the after-effect marked.
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

function draw(lab) {
  const svg = document.getElementById("curve");
  svg.replaceChildren();
  const facts = document.getElementById("facts");
  if (!lab.protocol || lab.trials.length === 0) {
    facts.textContent = "waiting for the first volunteer's run" +
      (lab.programs ? " (" + lab.programs + " program runs are not in the curve)" : "");
    return;
  }
  document.getElementById("title").textContent = "Learning curve: " + lab.protocol;
  facts.textContent = lab.students + (lab.students === 1 ? " student" : " students") + " · " +
    (MEASURES[lab.metric] || lab.metric) + " (" + lab.unit + "), mean ± s.e.m. per trial";
  const box = svg.getBoundingClientRect();
  const W = Math.max(box.width, 300), H = Math.max(box.height, 200);
  svg.setAttribute("viewBox", "0 0 " + W + " " + H);
  const left = W * 0.08, right = W * 0.98, top = H * 0.12, bottom = H * 0.84;
  const t = lab.trials;
  const values = [];
  for (const p of t) if (p.mean !== null) values.push(p.mean + (p.sem || 0), p.mean - (p.sem || 0));
  let lo = Math.min(0, ...values), hi = Math.max(...values, 1e-9);
  if (hi - lo < 1e-9) hi = lo + 1;
  const first = t[0].trial, last = t[t.length - 1].trial;
  const x = (k) => left + (right - left) * (last > first ? (k - first) / (last - first) : 0.5);
  const y = (v) => bottom - (bottom - top) * (v - lo) / (hi - lo);
  // Blocks: shaded in turn, named at the top.
  let start = 0, shade = true;
  for (let i = 1; i <= t.length; i++) {
    if (i === t.length || t[i].block !== t[start].block) {
      const x0 = x(t[start].trial - 0.5), x1 = x(t[i - 1].trial + 0.5);
      if (shade) {
        svg.appendChild(el("rect", {class: "block", x: x0, y: top, width: Math.max(x1 - x0, 1), height: bottom - top}));
      }
      shade = !shade;
      keepInside(svg.appendChild(el("text", {x: (x0 + x1) / 2, y: top - 8, "text-anchor": "middle"},
                                 t[start].block)), W);
      // The after-effect: the first trial back without the perturbation after trials with it.
      if (start > 0 && t[start].perturbation === "none" && t[start - 1].perturbation !== "none") {
        svg.appendChild(el("line", {class: "marker", x1: x(t[start].trial), x2: x(t[start].trial), y1: top, y2: bottom}));
        // Past the plot's middle (a short washout) the label goes left of the line, inside the plot.
        const at = x(t[start].trial), leftward = at > (left + right) / 2;
        keepInside(svg.appendChild(el("text", {class: "news", x: leftward ? at - 6 : at + 6, y: top + 24,
                                            "text-anchor": leftward ? "end" : "start"}, "after-effect")), W);
      }
      start = i;
    }
  }
  // The s.e.m. band, then the mean.
  const upper = [], lower = [];
  let path = "";
  for (const p of t) {
    if (p.mean === null) continue;
    const s = p.sem || 0;
    upper.push(x(p.trial) + "," + y(p.mean + s));
    lower.unshift(x(p.trial) + "," + y(p.mean - s));
    path += (path ? " L" : "M") + x(p.trial) + "," + y(p.mean);
  }
  svg.appendChild(el("polygon", {class: "band", points: upper.concat(lower).join(" ")}));
  svg.appendChild(el("path", {class: "mean", d: path}));
  if (lo < 0 && hi > 0) svg.appendChild(el("line", {class: "zero", x1: left, x2: right, y1: y(0), y2: y(0)}));
  svg.appendChild(el("line", {class: "axis", x1: left, x2: right, y1: bottom, y2: bottom}));
  svg.appendChild(el("text", {x: x(first), y: bottom + 24, "text-anchor": "middle"}, String(first)));
  svg.appendChild(el("text", {x: x(last), y: bottom + 24, "text-anchor": "middle"}, String(last)));
  svg.appendChild(el("line", {class: "axis", x1: left, x2: left, y1: top, y2: bottom}));
  svg.appendChild(el("text", {x: (left + right) / 2, y: H - 8, "text-anchor": "middle"}, "trial"));
  svg.appendChild(el("text", {x: left - 8, y: y(hi), "text-anchor": "end"}, hi.toFixed(hi < 10 ? 1 : 0)));
  svg.appendChild(el("text", {x: left - 8, y: y(lo), "text-anchor": "end"}, lo.toFixed(lo > -10 ? 1 : 0)));
  if (lo < 0 && hi > 0) svg.appendChild(el("text", {x: left - 8, y: y(0), "text-anchor": "end"}, "0"));
  svg.appendChild(el("text", {x: left, y: top - 8 - H * 0.03}, lab.unit));
  document.body.dataset.students = String(lab.students);
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
