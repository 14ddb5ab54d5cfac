// The browser lab's view (ui/lab_window.py's LabRenderer and ui/lab_panels.py, for a page): the scene on the canvas
// (the targets' places, home, the target at the go cue, the cursor as the trial shows it, a reach's path after it,
// the muscle bars), and everything in words as HTML the page's CSS lays out (the trial line, the block's
// instruction, what was said of the last reach, the cards, the end screen and its learning curve as SVG). Text is
// set with textContent only. labpage.js holds the model and calls these; nothing here changes the run.
import { circle, rgb } from "./body.js";

// The high-contrast palette (ui/palette.py), and the lab window's own colours (tests/test_play_logic.py holds
// them to the Python's).
export const INK = "rgb(0,0,0)", PAPER = "rgb(255,255,255)", TARGET = [200, 0, 0], TRAIL = "rgb(90,90,90)";
export const WARN = "rgb(170,0,0)", BAR_BACK = "rgb(200,200,200)";
export const HOME = "rgb(0,114,178)";  // Okabe-Ito blue: told apart from the vermilion target by colour-blind players too
export const HIT = "rgb(0,128,90)";
export const MUSCLES = [[0, 80, 220], [180, 90, 0], [0, 120, 60], [160, 0, 160]];
// The learning curve's blocks (lab_panels.draw_curve's blend of the panel): a perturbed one in the target's tint,
// the others in two greys by turns.
export const BLOCK_SHADES = { perturbed: "rgb(246,214,214)", odd: "rgb(227,227,227)", even: "rgb(237,237,237)" };
const CURSOR_RADIUS = 0.006, MIN_LINE = 3;
const SVG = "http://www.w3.org/2000/svg";

const $ = (id) => document.getElementById(id);

/** The workspace around a home (LabRenderer.view): the targets' distance and half as much again, more above. */
export function labWorld(home, distance) {
  const span = Math.max(0.08, 1.45 * distance);
  return [home[0] - span, home[0] + span, home[1] - span, home[1] + 1.35 * span];
}

function viewport(w, h, world) {
  const [xmin, xmax, ymin, ymax] = world;
  const scale = Math.min(w / (xmax - xmin), h / (ymax - ymin));
  const left = (w - scale * (xmax - xmin)) / 2, top = (h - scale * (ymax - ymin)) / 2;
  return { scale, ox: left - xmin * scale, oy: top + ymax * scale, left, top, width: scale * (xmax - xmin),
    height: scale * (ymax - ymin) };
}

export class LabView {
  constructor(canvas, plan) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d", { alpha: false });
    this.plan = plan;
    this._places = new Map();  // a home's target places: every trial's position from that home
    for (const t of plan.trials) {
      const key = t.home.join(",");
      if (!this._places.has(key)) this._places.set(key, new Map());
      this._places.get(key).set(t.position.join(","), t.position);
    }
  }

  /** One frame of the scene in a box of w x h CSS px (sx, sy: device px a CSS px). ``s``: what labpage.js shows. */
  draw(w, h, sx, sy, s) {
    const g = this.ctx, run = s.run, plan = this.plan;
    const feedback = s.feedback;
    const home = feedback ? plan.trials[feedback.outcome.trial].home : run.home;  // a path in its own workspace
    const view = viewport(w, h, labWorld(home, plan.distance));
    const k = view.scale, px = (x, y) => [view.ox + x * k, view.oy - y * k];
    const line = Math.max(MIN_LINE, Math.round(Math.min(w, h) / 240));
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = PAPER;
    g.fillRect(0, 0, this.canvas.width, this.canvas.height);
    g.setTransform(sx, 0, 0, sy, 0, 0);
    for (const [x, y] of (this._places.get(home.join(","))?.values() ?? [])) {
      circle(g, ...px(x, y), plan.target_radius * k, null, INK, line);
    }
    const holding = run.phase === "hold" && !run.over && !feedback;
    const [hx, hy] = run.home;
    if (holding) circle(g, ...px(hx, hy), plan.home_radius * k, HOME);
    else circle(g, ...px(hx, hy), plan.home_radius * k - line / 2, null, HOME, line);
    if (feedback) {
      this._path(g, px, k, line, feedback.outcome, plan.trials[feedback.outcome.trial]);
    } else if (!holding && !run.over) {
      const t = run.target;
      circle(g, ...px(t.x, t.y), t.radius * k, rgb(TARGET));
    }
    if (!feedback && run.cursorVisible && s.phase !== "end") {  // a trial without vision hides it from the go cue on
      circle(g, ...px(...run.cursor), Math.max(3, CURSOR_RADIUS * k), INK);
    }
    if (s.phase !== "end") this._bars(g, w, h, line, run.muscleActivation);
    else if (this._curve) {  // the end screen's curve follows its box (a phone turned, a window resized)
      const root = $("lab-curve"), b = root.getBoundingClientRect();
      if (root.dataset.size !== Math.max(Math.round(b.width), 120) + "x" + Math.max(Math.round(b.height), 60)) {
        drawCurve(root, this._curve);
      }
    }
    // The scene's box in CSS px of the canvas: the tests hold it whole inside the screen, clear of every control.
    this.canvas.workspace = { x: view.left, y: view.top, width: view.width, height: view.height };
  }

  /** Knowledge of results (lab_panels.draw_feedback): the straight line asked for and the path made; with
   * endpoint feedback only where the reach ended; with none, nothing. */
  _path(g, px, k, line, outcome, trial) {
    if (trial.feedback === "none") return;
    const [hx, hy] = px(...trial.home), [tx, ty] = px(...trial.position);
    g.beginPath(); g.moveTo(hx, hy); g.lineTo(tx, ty);
    g.lineWidth = line; g.strokeStyle = INK; g.stroke();
    circle(g, tx, ty, this.plan.target_radius * k, null, rgb(TARGET), line);
    const n = outcome.homeAt === null ? outcome.xs.length : outcome.homeAt;  // the reach, not the jump home
    const dot = Math.max(line + 1, CURSOR_RADIUS * k);
    if (n === 0) return;
    if (trial.feedback === "endpoint") { circle(g, ...px(outcome.xs[n - 1], outcome.ys[n - 1]), dot, INK); return; }
    g.beginPath();
    for (let i = 0; i < n; i += 4) (i ? g.lineTo : g.moveTo).call(g, ...px(outcome.xs[i], outcome.ys[i]));
    g.lineWidth = line; g.strokeStyle = TRAIL; g.lineJoin = "round"; g.lineCap = "round"; g.stroke();
    circle(g, ...px(outcome.xs[n - 1 - ((n - 1) % 4)], outcome.ys[n - 1 - ((n - 1) % 4)]), dot, INK);
  }

  /** The four muscles' bars in the scene's lower right corner, in their keys' colours (the buttons and the first
   * card name the keys). */
  _bars(g, w, h, line, activation) {
    const u = Math.min(w, h) / 720, barW = Math.max(40, Math.round(110 * u)), barH = Math.max(5, Math.round(10 * u));
    const gap = Math.max(3, Math.round(6 * u)), pad = Math.max(6, Math.round(14 * u));
    const x = w - pad - barW;
    activation.forEach((a, i) => {
      const y = h - pad - (4 - i) * (barH + gap);
      g.fillStyle = BAR_BACK; g.fillRect(x, y, barW, barH);
      const v = Math.min(Math.max(a, 0), 1);
      if (v > 0.002) { g.fillStyle = rgb(MUSCLES[i]); g.fillRect(x, y, Math.max(2, barW * v), barH); }
    });
  }

  // ------------------------------------------------------------------ the words, as HTML
  /** The head over the scene: the trial and its block, the block's instruction, what was said of the last reach. */
  head(trialLine, instruction, said, colour) {
    $("lab-trial").textContent = trialLine;
    $("lab-instruction").textContent = instruction;
    const line = $("lab-said");
    line.textContent = said;
    line.dataset.colour = colour;
  }

  /** A card over the scene (lab_panels.draw_card): a title, what to do, and what goes on. */
  card(title, lines, prompt) {
    const card = $("lab-card");
    if (title === null) { card.hidden = true; return; }
    $("lab-card-title").textContent = title;
    $("lab-card-lines").replaceChildren(...lines.map((text) => {
      const p = document.createElement("p");
      p.textContent = text;
      return p;
    }));
    $("lab-go").textContent = prompt;
    card.hidden = false;
  }

  /** The end screen (lab_panels.draw_end): what was done, the student's learning curve (blocks shaded, the
   * perturbed ones in the target's colour, each block's mean, the after-effect marked), the blocks' means, and
   * what the class said of the run. */
  end(summary, curve, means, answer, kind) {
    $("lab-card").hidden = true;
    $("lab-end-summary").textContent = summary;
    $("lab-means").textContent = means;
    this.answer(answer, kind);
    this._curve = curve;
    $("lab-end").hidden = false;
    drawCurve($("lab-curve"), curve);  // once laid out: its box is the page's
  }

  answer(line, kind) {
    const p = $("lab-answer");
    p.textContent = line;
    p.className = kind;
  }
}

function ticks(low, high) {
  const span = high - low;
  if (!(span > 0)) return [low];
  const raw = span / 4, magnitude = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * magnitude).find((s) => s >= raw);
  const out = [];
  for (let v = Math.ceil(low / step) * step; v <= high + 1e-9 * step; v += step) out.push(Math.round(v / step) * step);
  return out;
}

function svg(parent, name, attributes, text) {
  const e = document.createElementNS(SVG, name);
  for (const [a, v] of Object.entries(attributes)) e.setAttribute(a, String(v));
  if (text !== undefined) e.textContent = text;
  parent.appendChild(e);
  return e;
}

/** The learning curve (lab_panels.draw_curve) as SVG, in the CSS px of the box play.css gives it, so its words are
 * the page's size on any screen (redrawn when the box changes: LabView.draw). */
export function drawCurve(root, curve) {
  root.replaceChildren();
  const box = root.getBoundingClientRect();
  const W = Math.max(Math.round(box.width), 120), H = Math.max(Math.round(box.height), 60);
  root.dataset.size = W + "x" + H;
  const text = Math.max(14, Math.min(22, Math.round(Math.min(W / 28, H / 10))));
  root.style.setProperty("--text", text + "px");
  const left = 3.4 * text, top = 1.8 * text, bottom = 2.2 * text, right = 0.5 * text;
  root.setAttribute("viewBox", `0 0 ${W} ${H}`);
  const points = curve.points;
  if (points.length === 0) return;
  const finite = points.map((p) => p.value).filter(Number.isFinite);
  let low = Math.min(0, ...finite), high = Math.max(0, ...finite);
  if (finite.length === 0) { low = -1; high = 1; }
  const margin = 0.08 * ((high - low) || 2);
  low -= margin; high += margin;
  const first = Math.min(...curve.blocks.map((b) => b.first)), last = Math.max(...curve.blocks.map((b) => b.last));
  const span = Math.max(last - first + 1, 1), plotW = W - left - right, plotH = H - top - bottom;
  const x = (t) => left + (t - first + 0.5) / span * plotW, y = (v) => top + (high - v) / (high - low) * plotH;
  curve.blocks.forEach((b, i) => {
    const x0 = x(b.first - 0.5), x1 = x(b.last + 0.5);
    svg(root, "rect", { x: x0, y: top, width: x1 - x0, height: plotH,
      fill: b.perturbed ? BLOCK_SHADES.perturbed : i % 2 ? BLOCK_SHADES.odd : BLOCK_SHADES.even });
    if (x1 - x0 > 0.6 * text * b.name.length) {  // a block too narrow for its name goes unnamed, as in the window
      svg(root, "text", { x: (x0 + x1) / 2, y: top - 0.4 * text, "text-anchor": "middle", class: "block" }, b.name);
    }
    if (Number.isFinite(b.mean) && b.mean >= low && b.mean <= high) {
      svg(root, "line", { x1: x0 + 3, x2: x1 - 3, y1: y(b.mean), y2: y(b.mean), stroke: WARN, "stroke-width": 3 });
    }
  });
  for (const t of ticks(low, high)) {
    svg(root, "line", { x1: left - 0.4 * text, x2: left, y1: y(t), y2: y(t), stroke: INK, "stroke-width": 2 });
    svg(root, "text", { x: left - 0.6 * text, y: y(t), "text-anchor": "end", "dominant-baseline": "middle" },
      String(Number(t.toPrecision(6))));
  }
  svg(root, "line", { x1: left, x2: W - right, y1: y(0), y2: y(0), stroke: INK, "stroke-width": 2 });
  svg(root, "rect", { x: left, y: top, width: plotW, height: plotH, fill: "none", stroke: INK, "stroke-width": 2 });
  const r = Math.max(3, Math.min(text / 3, plotW / span / 2.2));
  for (const p of points) {
    if (!Number.isFinite(p.value)) continue;
    if (p.catch) svg(root, "circle", { cx: x(p.trial), cy: y(p.value), r: r + 1, fill: "none", stroke: WARN, "stroke-width": 2 });
    else svg(root, "circle", { cx: x(p.trial), cy: y(p.value), r, fill: INK });
  }
  if (curve.afterEffect !== null) {
    const cx = x(curve.afterEffect.trial), cy = y(curve.afterEffect.value);
    svg(root, "circle", { cx, cy, r: r + 5, fill: "none", stroke: WARN, "stroke-width": 3 });
    const onLeft = cx - r - text - 7 * text >= left;
    svg(root, "text", { x: onLeft ? cx - r - text : cx + r + text, y: cy, "text-anchor": onLeft ? "end" : "start",
      "dominant-baseline": "middle", fill: WARN, stroke: PAPER, "stroke-width": Math.max(3, text / 4),
      "paint-order": "stroke" }, "after-effect");  // a white edge: the label reads over the dots it lies on
  }
  svg(root, "text", { x: left, y: H - 0.5 * text }, `${curve.label} (${curve.unit}) by trial`);
}
