// The browser game's view (/play), as ui/render.py's GameRenderer: layout() returns where everything goes as data
// (the HUD's lines and bars, the scene, the metres-to-pixels view, the arm's reach), which tests/play_logic.test.mjs
// checks without a canvas; View.draw() paints one frame of it on the canvas. The text is set with fillText, never
// as HTML. Its looks are ui/palette.py's and ui/render.py's: tests/test_play_logic.py ties them to the Python.
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
// ui/render.py's: the smallest text at 720 lines and as a fraction of the height; the narrowest line a student must
// see; the clock turns to the warning colour in its last WARN_SECONDS.
export const MIN_TEXT_AT_720 = 14, MIN_TEXT_FRACTION = 0.025, MIN_LINE = 3, WARN_SECONDS = 10;
// The scene shows the arm's whole reach, every target in it, and a margin for the palm and a target's flash at its
// edge. The game's view (ui/render.py's) runs 0.4 m above the reach, where nothing is drawn, and cuts its bottom.
export const REACH_MARGIN = 0.04;

export function textSizes(w, h) {
  const m = Math.min(w, h), u = m / 720;
  const minText = Math.max(Math.round(MIN_TEXT_AT_720 * m / 720), Math.round(MIN_TEXT_FRACTION * h));
  const small = Math.max(12, Math.round(18 * u), minText);
  return { small, normal: Math.max(Math.max(13, Math.round(22 * u)), small + 2), big: Math.max(18, Math.round(40 * u)) };
}

export function font(size, bold) { return (bold ? "bold " : "") + size + "px " + FONT; }

export function clockText(seconds) {
  if (seconds < 100) return seconds.toFixed(1).padStart(4, " ");
  const whole = Math.ceil(seconds);
  return Math.floor(whole / 60) + ":" + String(whole % 60).padStart(2, "0");
}

// ``text`` cut to ``room`` px with an ellipsis; ``measure(text, size, bold)`` is its width.
function fit(text, size, room, measure) {
  if (measure(text, size) <= room) return text;
  while (text && measure(text + "…", size) > room) text = text.slice(0, -1);
  return text + "…";
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

// Where a frame's parts go in a canvas box of w x h CSS px (the canvas is its own cell: the buttons and the status
// line have cells of their own, play.css). ``s``: what the HUD shows ({seed, name, score, timeLeft, keys, names,
// activation, touchMode, resetCost, arm: {l1, l2}}); ``measure(text, size, bold)``: a text's width in px.
// Returns the sizes, the HUD's and the scene's boxes, the view, the reach's box (``reach``), the labels
// ([text, x, y, size, colour: a PALETTE name, bold]), the muscle bars ([x, y, w, h, muscle, activation]).
export function layout(w, h, s, measure) {
  const u = Math.min(w, h) / 720;
  const pad = Math.max(6, Math.round(16 * u)), gap = Math.max(4, Math.round(8 * u));
  const { small, normal, big } = textSizes(w, h);
  const landscape = w >= 1.15 * h;
  let hud, scene;
  if (landscape) {
    const needed = measure("Time 00.0", big, true) + 2 * pad;
    const side = Math.min(Math.max(Math.round(w * 0.27), 200, needed), Math.max(480, needed), w - Math.round(h * 0.55));
    hud = { x: pad, y: pad, w: side - 2 * pad, h: h - 2 * pad };
    scene = { x: side, y: pad, w: w - side - pad, h: h - 2 * pad };
  } else {
    hud = { x: pad, y: pad, w: w - 2 * pad, h: h - 2 * pad };
    scene = { x: pad, y: 0, w: w - 2 * pad, h: 0 };
  }
  // The HUD's top: the mode, the score and the clock.
  const labels = [];
  let y = hud.y;
  // The mode's parts share a line where they fit (a long name goes on a line of its own), as in the window.
  const modeLines = [];
  for (const part of ["PLAY", "seed " + s.seed, s.name]) {
    const line = modeLines.length ? modeLines[modeLines.length - 1] + "   " + part : null;
    if (line !== null && measure(line, normal) <= hud.w) modeLines[modeLines.length - 1] = line;
    else modeLines.push(fit(part, normal, hud.w, measure));
  }
  for (const line of modeLines) {
    labels.push([line, hud.x, y, normal, "ink", false]);
    y += Math.round(normal * 1.2) + gap / 2;
  }
  y += gap / 2;
  let head = big;
  const score = "Score " + s.score, clockLine = "Time " + clockText(s.timeLeft);
  const clockColour = s.timeLeft > 0 && s.timeLeft <= WARN_SECONDS ? "warn" : "ink";
  if (landscape) {
    labels.push([score, hud.x, y, head, "ink", true]);
    y += Math.round(head * 1.2) + gap;
    labels.push([clockLine, hud.x, y, head, clockColour, true]);
  } else {
    while (head > normal && measure("Score 000", head, true) + 2 * gap + measure("Time 00.0", head, true) > hud.w) head -= 1;
    labels.push([score, hud.x, y, head, "ink", true]);
    labels.push([clockLine, hud.x + hud.w - measure("Time 00.0", head, true), y, head, clockColour, true]);
  }
  y += Math.round(head * 1.2) + 2 * gap;
  // The muscle bars: one column beside the scene, two above it on a tall window.
  const columns = landscape ? 1 : 2;
  const colW = (hud.w - (columns - 1) * 2 * pad) / columns;
  const barH = Math.max(5, Math.round(10 * u));
  const rowH = Math.round(small * 1.2) + gap / 2 + barH + gap;
  const short = s.names.some((n, i) => measure(s.keys[i] + "  " + n, small) > colW);
  const bars = [];
  for (let i = 0; i < 4; i++) {
    const cx = hud.x + (i % columns) * (colW + 2 * pad), ry = y + Math.floor(i / columns) * rowH;
    const name = short ? s.names[i].split(" ").pop() : s.names[i];
    labels.push([fit(s.keys[i] + "  " + name, small, colW, measure), cx, ry, small, "ink", false]);
    bars.push([cx, ry + Math.round(small * 1.2) + gap / 2, colW, barH, i, Math.min(Math.max(s.activation[i], 0), 1)]);
  }
  y += rowH * (4 / columns) + gap;
  // The help line(s), at the bottom of the HUD (the touch buttons say what they do themselves).
  const items = s.touchMode ? ["the buttons pull the muscles", "reset costs " + s.resetCost]
    : [s.keys[0] + "/" + s.keys[1] + " shoulder", s.keys[2] + "/" + s.keys[3] + " elbow", "space reset (-" + s.resetCost + ")",
      "tab hide arm"];
  const lines = [];
  for (const item of items) {
    if (lines.length && measure(lines[lines.length - 1] + "    " + item, small) <= hud.w) lines[lines.length - 1] += "    " + item;
    else lines.push(fit(item, small, hud.w, measure));
  }
  const lineH = Math.round(small * 1.2);
  const helpTop = hud.y + hud.h - lines.length * (lineH + gap / 2);
  lines.forEach((line, i) => {
    const ly = helpTop + i * (lineH + gap / 2);
    labels.push([line, landscape ? hud.x : (w - measure(line, small)) / 2, ly, small, "faint", false]);
  });
  if (!landscape) { scene.y = y; scene.h = Math.max(helpTop - gap - y, 10); }
  const view = viewport(scene, sceneWorld(s.arm));
  const r = (s.arm.l1 + s.arm.l2) * view.scale;
  const reach = { x: view.ox - r, y: view.oy - r, width: 2 * r, height: 2 * r };
  return { w, h, u, pad, gap, small, normal, big, landscape, hud, scene, view, reach, labels, bars };
}

// The countdown's panel in the middle of the scene: {x, y, w, h, size, number, hint}.
export function countdownPanel(lay, countdownLeft, touchMode, measure) {
  const s = lay.scene, size = Math.max(lay.big, Math.round(s.h * 0.2));
  const number = String(Math.max(1, Math.ceil(countdownLeft)));
  const hint = touchMode ? "a tap starts" : "any key starts";
  const w = Math.max(measure(number, size, true), measure(hint, lay.normal)) + 6 * lay.gap;
  const h = size * 1.2 + lay.normal * 1.2 + 4 * lay.gap;
  return { x: s.x + s.w / 2 - w / 2, y: s.y + s.h / 2 - h / 2, w, h, size, number, hint };
}

export class View {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d", { alpha: false });
    this.box = { w: 0, h: 0 };  // the canvas's box (CSS px), as play.css's grid sizes its cell
    this.background = null;
    this.backgroundKey = "";
    this.measure = (text, size, bold) => { this.ctx.font = font(size, bold); return this.ctx.measureText(text).width; };
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

  // One frame: ``s`` is layout()'s HUD and the scene's moving parts ({phase, now, target, angles, armVisible, hits,
  // countdownLeft}). Sets the canvas's ``workspace``: the reach's box, which the tests hold inside the screen.
  draw(s) {
    const { w, h } = this.box;
    if (w < 1 || h < 1) return;
    const canvas = this.canvas, ctx = this.ctx, p = PALETTE;
    const sx = canvas.width / w, sy = canvas.height / h;  // the device pixels a CSS px has, as the bitmap has them
    const lay = layout(w, h, s, this.measure);
    const view = lay.view, gap = lay.gap, big = lay.big;
    const key = [w, h, canvas.width, canvas.height, lay.scene.x, lay.scene.y, lay.scene.w, lay.scene.h].join(",");
    if (key !== this.backgroundKey) { this.background = this.drawBackground(lay, s.arm, sx, sy); this.backgroundKey = key; }
    canvas.workspace = lay.reach;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(this.background, 0, 0);
    ctx.setTransform(sx, 0, 0, sy, 0, 0);
    ctx.textBaseline = "top";
    ctx.textAlign = "left";
    // The scene: target, arm, hand, clipped to it.
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
    circle(ctx, view.ox + hand[0] * view.scale, view.oy - hand[1] * view.scale, Math.max(1, 0.02 * view.scale), rgb(p.hand));
    const labels = lay.labels.slice();
    for (const [x, yy, t] of s.hits) {
      const age = s.now - t;
      if (age < PLUS_ONE_TIME) {
        const r = s.target.radius * view.scale;
        labels.push(["+1", view.ox + x * view.scale + r + gap, view.oy - yy * view.scale - age / PLUS_ONE_TIME * 2 * r - big / 2,
          big, "ink", true]);
      }
    }
    ctx.restore();
    if (s.phase === "over") {  // the end card is HTML, over the veiled game
      ctx.fillStyle = "rgba(255,255,255,0.67)";
      ctx.fillRect(0, 0, w, h);
    }
    for (const [x, by, bw, bh, i, a] of lay.bars) {
      this.roundRect(x, by, bw, bh, bh / 2, rgb(p.bar_back));
      if (a > 0.002) this.roundRect(x, by, Math.max(bh, Math.round(bw * a)), bh, bh / 2, rgb(p.muscles[i]));
    }
    for (const [text, x, ly, size, colour, bold] of labels) {
      ctx.font = font(size, bold);
      ctx.fillStyle = rgb(p[colour]);
      ctx.fillText(text, x, ly);
    }
    if (s.phase === "countdown") this.drawCountdown(lay, s);
  }

  roundRect(x, y, w, h, r, fill, stroke, line) {
    const ctx = this.ctx;
    ctx.beginPath();
    ctx.roundRect(x, y, w, h, r);
    if (fill) { ctx.fillStyle = fill; ctx.fill(); }
    if (stroke) { ctx.lineWidth = line; ctx.strokeStyle = stroke; ctx.stroke(); }
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

  drawCountdown(lay, s) {
    const ctx = this.ctx, sc = lay.scene;
    const c = countdownPanel(lay, s.countdownLeft, s.touchMode, this.measure);
    this.roundRect(c.x, c.y, c.w, c.h, Math.max(4, Math.round(12 * lay.u)), rgb(PALETTE.panel), rgb(PALETTE.edge),
      Math.max(MIN_LINE, Math.round(2 * lay.u)));
    ctx.textAlign = "center";
    ctx.fillStyle = rgb(PALETTE.ink);
    ctx.font = font(c.size, true);
    ctx.fillText(c.number, sc.x + sc.w / 2, c.y + 1.5 * lay.gap);
    ctx.font = font(lay.normal, false);
    ctx.fillText(c.hint, sc.x + sc.w / 2, c.y + 1.5 * lay.gap + c.size * 1.2 + lay.gap);
    ctx.textAlign = "left";
  }
}
