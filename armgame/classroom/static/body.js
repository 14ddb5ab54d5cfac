// The body in the browser's game (ui/body.py): the torso and head behind the scene, and the arm, its limbs and
// joints outlined, the palm, the four muscles swelling with their activation in their keys' colours. Pure
// drawing on a 2D context, given the view (metres to pixels: scale, ox, oy) and the palette (view.js's PALETTE: RGB
// triples); view.js draws with it. tests/test_play_logic.py ties its sizes and outlines to ui/body.py's.

// In metres, as ui/body.py's.
export const UPPER_ARM = [0.048, 0.034], FOREARM = [0.034, 0.022], HAND = [0.036, 0.030];
export const MUSCLE_REST = 0.011, MUSCLE_GAIN = 0.02, BREADTH = [1.4, 1.4, 1.0, 1.0], MUSCLE_TINT = 0.45;
export const TORSO = [[-0.19, -0.035], [0.23, 0.11]], HEAD = [[-0.19, -0.02], 0.085];
export const SPINDLE = Array.from({ length: 9 }, (_, k) => [k / 8, Math.sin(Math.PI * k / 8) ** 1.2]);
const PALM = Array.from({ length: 14 }, (_, j) => {
  const t = 2 * Math.PI * j / 14;
  return [Math.sign(Math.cos(t)) * Math.abs(Math.cos(t)) ** 0.6, Math.sign(Math.sin(t)) * Math.abs(Math.sin(t)) ** 0.6];
});

export function rgb(c) { return `rgb(${c[0]},${c[1]},${c[2]})`; }
export function blend(a, b, k) { return a.map((x, i) => Math.round(x + (b[i] - x) * k)); }

export function circle(g, x, y, r, fill, stroke, line) {
  g.beginPath();
  g.arc(x, y, Math.max(r, 0.5), 0, 2 * Math.PI);
  if (fill) { g.fillStyle = fill; g.fill(); }
  if (stroke) { g.lineWidth = line; g.strokeStyle = stroke; g.stroke(); }
}

// The torso, the head and the other shoulder, which never move: view.js draws them once per size.
export function drawTorso(g, view, palette) {
  const k = view.scale, body = Math.max(3, Math.round(k * 0.005));
  const px = (x, y) => [view.ox + x * k, view.oy - y * k];
  const [[cx, cy], [hw, hh]] = TORSO;
  const [left, top] = px(cx - hw, cy + hh);
  g.beginPath();
  g.roundRect(left, top, 2 * hw * k, 2 * hh * k, hh * k);
  g.fillStyle = rgb(palette.skin);
  g.fill();
  const edge = rgb(palette.link);
  g.lineWidth = body; g.strokeStyle = edge; g.stroke();
  const [[hx, hy], r] = HEAD;
  circle(g, ...px(hx, hy + r * 0.95), 0.022 * k, rgb(palette.skin), edge, body);
  circle(g, ...px(hx, hy), r * k, rgb(palette.skin), edge, body);
  circle(g, ...px(-0.38, 0), 0.03 * k, rgb(palette.skin), edge, body);
}

// The arm (ui/body.py's draw_arm): limbs and joints outlined, the palm, the four muscles swelling with
// their activation in their keys' colours.
export function drawArm(ctx, view, q1, q2, l1, l2, activation, palette) {
  const k = view.scale, line = Math.max(3, Math.round(k * 0.005)), grow = line / k;
  const shoulder = [0, 0], elbow = [l1 * Math.cos(q1), l1 * Math.sin(q1)];
  const hand = [elbow[0] + l2 * Math.cos(q1 + q2), elbow[1] + l2 * Math.sin(q1 + q2)];
  const wf = Math.max(0, 1 - HAND[0] / l2);
  const wrist = [elbow[0] + wf * (hand[0] - elbow[0]), elbow[1] + wf * (hand[1] - elbow[1])];
  const poly = (points, fill, stroke) => {
    ctx.beginPath();
    points.forEach(([x, y], i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, view.ox + x * k, view.oy - y * k));
    ctx.closePath();
    ctx.fillStyle = fill; ctx.fill();
    if (stroke) { ctx.lineWidth = 1; ctx.strokeStyle = stroke; ctx.stroke(); }
  };
  const joints = [[shoulder, UPPER_ARM[0]], [elbow, UPPER_ARM[1]], [wrist, FOREARM[1]]];
  const skin = rgb(palette.skin), edge = rgb(palette.link);
  const limbs = [[shoulder, elbow, UPPER_ARM], [elbow, wrist, FOREARM]];
  for (const [a, b, wd] of limbs) poly(limbOutline(a, b, [wd[0] + grow, wd[1] + grow]), edge);
  for (const [c, r] of joints) circle(ctx, view.ox + c[0] * k, view.oy - c[1] * k, r * k + line, edge);
  poly(palm(wrist, hand, grow), edge);
  for (const [a, b, wd] of limbs) poly(limbOutline(a, b, wd), skin);
  for (const [c, r] of joints) circle(ctx, view.ox + c[0] * k, view.oy - c[1] * k, r * k, skin);
  poly(palm(wrist, hand, 0), skin);
  for (const i of [1, 0, 3, 2]) {  // the shoulder pair under the elbow pair, where they cross
    const a = Math.min(Math.max(activation[i], 0), 1);
    const fill = rgb(blend(palette.skin, palette.muscles[i], MUSCLE_TINT + (1 - MUSCLE_TINT) * Math.round(64 * a) / 64));
    poly(muscleOutline(i, q1, q2, l1, l2, a), fill, rgb(blend(palette.muscles[i], [0, 0, 0], 0.35)));
  }
}

function along(o, d, n, a, b) { return [o[0] + a * d[0] + b * n[0], o[1] + a * d[1] + b * n[1]]; }

function muscleEnds(i, q1, q2, l1, l2) {
  const elbow = [l1 * Math.cos(q1), l1 * Math.sin(q1)];
  const u = [Math.cos(q1), Math.sin(q1)], n = [-u[1], u[0]];
  const f = [Math.cos(q1 + q2), Math.sin(q1 + q2)], nf = [-f[1], f[0]];
  const s = [0, 0];
  if (i === 0) return [[-0.12, 0.05], along(s, u, n, 0.30 * l1, 0.6 * UPPER_ARM[0])];
  if (i === 1) return [[-0.07, -0.085], along(s, u, n, 0.28 * l1, -0.6 * UPPER_ARM[0])];
  if (i === 2) return [along(s, u, n, 0.12 * l1, 0.55 * UPPER_ARM[0]), along(elbow, f, nf, 0.12 * l2, 0.4 * FOREARM[0])];
  return [along(s, u, n, 0.12 * l1, -0.55 * UPPER_ARM[0]), along(elbow, u, n, 0.02, -0.5 * UPPER_ARM[1])];
}

export function muscleOutline(i, q1, q2, l1, l2, a) {
  const [[x0, y0], [x1, y1]] = muscleEnds(i, q1, q2, l1, l2);
  const dx = x1 - x0, dy = y1 - y0, length = Math.hypot(dx, dy) || 1e-9;
  const nx = -dy / length, ny = dx / length, belly = (MUSCLE_REST + MUSCLE_GAIN * a) * BREADTH[i];
  const side = [], other = [];
  for (const [s, shape] of SPINDLE) {
    const w = 0.002 + belly * shape, cx = x0 + s * dx, cy = y0 + s * dy;
    side.push([cx + w * nx, cy + w * ny]);
    other.push([cx - w * nx, cy - w * ny]);
  }
  return side.concat(other.reverse());
}

export function limbOutline(start, end, [w0, w1]) {
  const dx = end[0] - start[0], dy = end[1] - start[1], length = Math.hypot(dx, dy) || 1e-9;
  const nx = -dy / length, ny = dx / length;
  return [[start[0] + w0 * nx, start[1] + w0 * ny], [end[0] + w1 * nx, end[1] + w1 * ny],
    [end[0] - w1 * nx, end[1] - w1 * ny], [start[0] - w0 * nx, start[1] - w0 * ny]];
}

export function palm(wrist, hand, grow) {
  const dx = hand[0] - wrist[0], dy = hand[1] - wrist[1], length = Math.hypot(dx, dy) || 1e-9;
  const ux = dx / length, uy = dy / length, nx = -uy, ny = ux;
  const halfL = HAND[0] * 1.1 + grow, halfW = HAND[1] + grow;
  const cx = hand[0] - 0.2 * HAND[0] * ux, cy = hand[1] - 0.2 * HAND[0] * uy;
  return PALM.map(([c, s]) => [cx + c * halfL * ux + s * halfW * nx, cy + c * halfL * uy + s * halfW * ny]);
}
