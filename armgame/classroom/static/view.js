// The browser game's view (/play), as ui/render.py's GameRenderer: layout() returns where the scene goes as data
// (its box, the metres-to-pixels view, the arm's reach) and hudWords() what the HUD says, which
// tests/play_logic.test.mjs checks without a page; View.draw() paints the scene on the canvas, and Hud sets the
// HUD's words (the mode, the score, the clock, the muscle bars, the help, the countdown) as HTML that play.css lays
// out, with textContent only. Its looks are ui/palette.py's and ui/render.py's: tests/test_play_logic.py ties them
// to the Python.
import { blend, circle, drawArm, drawTorso, rgb } from "./body.js";
import { FADE_IN, FLASH_TIME, PLUS_ONE_TIME } from "./model.js";

// PALETTES["high-contrast"] (ui/palette.py), the colours the page draws with: black on white, every colour at least
// 4.5:1 on white (a bright classroom).
export const PALETTE = {
  window: [255, 255, 255], scene: [255, 255, 255], workspace: [236, 236, 236], edge: [0, 0, 0], ink: [0, 0, 0],
  faint: [0, 0, 0], link: [0, 0, 0], hand: [0, 0, 0], target: [200, 0, 0], flash: [255, 210, 0], warn: [170, 0, 0],
  bar_back: [200, 200, 200], muscles: [[0, 80, 220], [180, 90, 0], [0, 120, 60], [160, 0, 160]],
  panel: [255, 255, 255], skin: [225, 225, 225],
};
const FONT = '"DejaVu Sans", "Segoe UI", Helvetica, Arial, sans-serif';
// ui/render.py's: the narrowest line a student must see; the clock turns to the warning colour in its last
// WARN_SECONDS.
export const MIN_LINE = 3, WARN_SECONDS = 10;
// The scene shows the arm's whole reach, every target in it, and a margin for the palm and a target's flash at its
// edge. The game's view (ui/render.py's) runs 0.4 m above the reach, where nothing is drawn, and cuts its bottom.
export const REACH_MARGIN = 0.04;

export function font(size, bold) { return (bold ? "bold " : "") + size + "px " + FONT; }

export function clockText(seconds) {
  if (seconds < 100) return seconds.toFixed(1).padStart(4, " ");
  const whole = Math.ceil(seconds);
  return Math.floor(whole / 60) + ":" + String(whole % 60).padStart(2, "0");
}

export function sceneWorld(arm) {
  const r = arm.l1 + arm.l2 + REACH_MARGIN;
  return [-r, r, -r, r];
}

// Metres to CSS px: the world's box as large as fits in the scene, centred.
export function viewport(scene, world) {
  const [xmin, xmax, ymin, ymax] = world;
  const scale = Math.min(scene.w / (xmax - xmin), scene.h / (ymax - ymin));
  const left = scene.x + (scene.w - scale * (xmax - xmin)) / 2, top = scene.y + (scene.h - scale * (ymax - ymin)) / 2;
  return { scale, ox: left - xmin * scale, oy: top + ymax * scale };
}

// Where a frame's parts go in a canvas box of w x h CSS px: the canvas is the scene's cell alone (the HUD, the
// buttons and the status line have cells of their own, play.css). Returns the sizes, the scene's box, the view
// (metres to px) and the box of the arm's reach (``reach``: x, y, width, height).
export function layout(w, h, arm) {
  const u = Math.min(w, h) / 720;
  const pad = Math.max(6, Math.round(16 * u)), gap = Math.max(4, Math.round(8 * u));
  const big = Math.max(18, Math.round(40 * u));  // a hit's "+1"
  const scene = { x: pad, y: pad, w: Math.max(w - 2 * pad, 10), h: Math.max(h - 2 * pad, 10) };
  const view = viewport(scene, sceneWorld(arm));
  const r = (arm.l1 + arm.l2) * view.scale;
  const reach = { x: view.ox - r, y: view.oy - r, width: 2 * r, height: 2 * r };
  return { w, h, u, pad, gap, big, scene, view, reach };
}

// The HUD's words (view.js's Hud sets them as text; play.css lays them out): ``s`` is {seed, name, score, timeLeft,
// keys, names, activation, touchMode, resetCost, phase, countdownLeft}. The clock is "warn" in its last
// WARN_SECONDS; each bar's level is its muscle's activation between 0 and 1; the countdown's words while it runs.
export function hudWords(s) {
  return {
    seed: "seed " + s.seed, name: s.name, score: "Score " + s.score, clock: "Time " + clockText(s.timeLeft),
    warn: s.timeLeft > 0 && s.timeLeft <= WARN_SECONDS,
    bars: s.keys.map((key, i) => ({ key, name: s.names[i], level: Math.min(Math.max(s.activation[i], 0), 1) })),
    // The touch buttons say what they do themselves.
    help: s.touchMode ? ["the buttons pull the muscles", "reset costs " + s.resetCost]
      : [s.keys[0] + "/" + s.keys[1] + " shoulder", s.keys[2] + "/" + s.keys[3] + " elbow",
        "space reset (-" + s.resetCost + ")", "tab hide arm"],
    countdown: s.phase === "countdown" ? { number: String(Math.max(1, Math.ceil(s.countdownLeft))),
      hint: s.touchMode ? "a tap starts" : "any key starts" } : null,
  };
}

// The HUD and the countdown as HTML (play.html's #hud and #countdown): words set with textContent only when they
// change, the bars' levels as a transform (no layout a frame).
export class Hud {
  constructor(doc) {
    const $ = (id) => doc.getElementById(id);
    this.body = doc.body;
    this.root = $("hud");
    this.parts = { seed: $("hud-seed"), name: $("hud-name"), score: $("hud-score"), clock: $("hud-clock") };
    this.bars = [...this.root.querySelectorAll(".bar")].map((bar) => ({ key: bar.querySelector(".key"),
      name: bar.querySelector(".name"), fill: bar.querySelector(".fill") }));
    this.help = $("hud-help");
    this.countdownBox = $("countdown");
    this.number = $("countdown-number");
    this.hint = $("countdown-hint");
    this.said = new Map();
    this.helpSaid = "";
  }

  // The page is written only where it changes: a frame that changes nothing costs no style or layout.
  text(element, text) {
    if (this.said.get(element) !== text) { element.textContent = text; this.said.set(element, text); }
  }

  mark(element, name, on) {
    const key = name + on;
    if (this.said.get(element) !== key) { element.classList.toggle(name, on); this.said.set(element, key); }
  }

  // ``s``: hudWords's argument, or null when no game is on screen (the HUD's cell goes: the join form and the lab
  // have the screen).
  show(s) {
    const on = s !== null;
    if (this.root.hidden === on) { this.root.hidden = !on; this.body.classList.toggle("hud", on); }
    if (!on) { this.countdownBox.hidden = true; return; }
    const w = hudWords(s);
    this.mark(this.root, "veiled", s.phase === "over");  // as the canvas is, under the end card
    for (const part of ["seed", "name", "score", "clock"]) this.text(this.parts[part], w[part]);
    this.mark(this.parts.clock, "warn", w.warn);
    w.bars.forEach((bar, i) => {
      const shown = this.bars[i];
      this.text(shown.key, bar.key);
      this.text(shown.name, bar.name);
      const level = "scaleX(" + bar.level + ")";
      if (this.said.get(shown.fill) !== level) { shown.fill.style.transform = level; this.said.set(shown.fill, level); }
    });
    if (w.help.join("\n") !== this.helpSaid) {
      this.helpSaid = w.help.join("\n");
      this.help.replaceChildren(...w.help.map((item) => {
        const span = this.help.ownerDocument.createElement("span");
        span.textContent = item;
        return span;
      }));
    }
    this.countdownBox.hidden = w.countdown === null;
    if (w.countdown !== null) { this.text(this.number, w.countdown.number); this.text(this.hint, w.countdown.hint); }
  }
}

export class View {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d", { alpha: false });
    this.box = { w: 0, h: 0 };  // the canvas's box (CSS px), as play.css's grid sizes its cell
    this.background = null;
    this.backgroundKey = "";
  }

  // The canvas's box as a ResizeObserver saw it: its bitmap follows it in device pixels.
  resized(entry, dpr) {
    const device = entry.devicePixelContentBoxSize?.[0];
    this.box = { w: entry.contentRect.width, h: entry.contentRect.height };
    const w = device ? device.inlineSize : Math.round(this.box.w * dpr), h = device ? device.blockSize : Math.round(this.box.h * dpr);
    const c = this.canvas;
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; this.backgroundKey = ""; }
  }

  // No game yet (the join form over it): the window's colour, not black.
  blank() {
    const ctx = this.ctx;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = rgb(PALETTE.window);
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
  }

  // What never moves (the window, the scene, the reachable annulus, the torso): drawn once per size.
  drawBackground(lay, arm, sx, sy) {
    const off = document.createElement("canvas");
    off.width = this.canvas.width; off.height = this.canvas.height;
    const g = off.getContext("2d", { alpha: false }), view = lay.view;
    g.fillStyle = rgb(PALETTE.window);
    g.fillRect(0, 0, off.width, off.height);  // every device pixel, the last row of a fractional box too
    g.scale(sx, sy);
    const s = lay.scene;
    g.beginPath();
    g.roundRect(s.x, s.y, s.w, s.h, Math.max(4, Math.round(12 * lay.u)));
    g.fillStyle = rgb(PALETTE.scene);
    g.fill();
    g.save();
    g.beginPath();
    g.rect(s.x, s.y, s.w, s.h);
    g.clip();
    const line = Math.max(MIN_LINE, Math.round(2 * lay.u));
    circle(g, view.ox, view.oy, (arm.l1 + arm.l2) * view.scale, rgb(PALETTE.workspace), rgb(PALETTE.edge), line);
    circle(g, view.ox, view.oy, Math.abs(arm.l1 - arm.l2) * view.scale, rgb(PALETTE.scene), rgb(PALETTE.edge), line);
    drawTorso(g, view, PALETTE);
    g.restore();
    return off;
  }

  // One frame of the scene: ``s`` is {arm: {l1, l2}, phase, now, target, angles, armVisible, activation, hits}. Sets
  // the canvas's ``workspace``: the reach's box, which the tests hold inside the screen.
  draw(s) {
    const { w, h } = this.box;
    if (w < 1 || h < 1) return;
    const canvas = this.canvas, ctx = this.ctx;
    const sx = canvas.width / w, sy = canvas.height / h;  // the device pixels a CSS px has, as the bitmap has them
    const lay = layout(w, h, s.arm);
    const view = lay.view;
    const key = [w, h, canvas.width, canvas.height].join(",");
    if (key !== this.backgroundKey) { this.background = this.drawBackground(lay, s.arm, sx, sy); this.backgroundKey = key; }
    canvas.workspace = lay.reach;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(this.background, 0, 0);
    ctx.setTransform(sx, 0, 0, sy, 0, 0);
    // The scene: target, arm, hand, a hit's "+1", clipped to it.
    const sc = lay.scene;
    ctx.save();
    ctx.beginPath();
    ctx.rect(sc.x, sc.y, sc.w, sc.h);
    ctx.clip();
    this.drawTarget(view, s);
    const [q1, q2] = s.angles;
    const { l1, l2 } = s.arm;
    const elbow = [l1 * Math.cos(q1), l1 * Math.sin(q1)];
    const hand = [elbow[0] + l2 * Math.cos(q1 + q2), elbow[1] + l2 * Math.sin(q1 + q2)];
    if (s.armVisible) drawArm(ctx, view, q1, q2, l1, l2, s.activation, PALETTE);
    circle(ctx, view.ox + hand[0] * view.scale, view.oy - hand[1] * view.scale, Math.max(1, 0.02 * view.scale), rgb(PALETTE.hand));
    ctx.textBaseline = "top";
    ctx.textAlign = "left";
    ctx.font = font(lay.big, true);
    ctx.fillStyle = rgb(PALETTE.ink);
    for (const [x, y, t] of s.hits) {
      const age = s.now - t;
      if (age < PLUS_ONE_TIME) {
        const r = s.target.radius * view.scale;
        ctx.fillText("+1", view.ox + x * view.scale + r + lay.gap,
          view.oy - y * view.scale - age / PLUS_ONE_TIME * 2 * r - lay.big / 2);
      }
    }
    ctx.restore();
    if (s.phase === "over") {  // the end card is HTML, over the veiled game
      ctx.fillStyle = "rgba(255,255,255,0.67)";
      ctx.fillRect(0, 0, w, h);
    }
  }

  drawTarget(view, s) {
    const ctx = this.ctx, t = s.target, k = view.scale, hits = s.hits;
    const x = view.ox + t.x * k, y = view.oy - t.y * k, r = Math.max(1, t.radius * k);
    const newest = hits.length ? s.now - hits[hits.length - 1][2] : null;
    const fade = newest === null ? 1 : Math.min(Math.max(newest / FADE_IN, 0), 1);
    const colour = rgb(blend([255, 255, 255], PALETTE.target, fade));
    circle(ctx, x, y, r - Math.max(MIN_LINE, r / 3) / 2, null, colour, Math.max(MIN_LINE, r / 3));
    circle(ctx, x, y, Math.max(2, r / 4), colour);
    for (const [hx, hy, when] of hits) {
      const age = s.now - when;
      if (age < FLASH_TIME) {
        const rr = r * (1 + 0.8 * age / FLASH_TIME);
        circle(ctx, view.ox + hx * k, view.oy - hy * k, rr, rgb(PALETTE.flash), rgb(PALETTE.target), Math.max(2, r / 5));
      }
    }
  }
}
