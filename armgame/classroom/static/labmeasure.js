// What the browser's lab tells a student of their reaches: each reach's measure (lab/metrics.py's reach_metrics, the
// one the learning curve plots), the words after it (lab/analysis.py's outcome_word and result_words) and the
// learning curve at the end (analysis.learning_curve). Shown only: the class's truth is the server's, which
// re-simulates the run and measures it in Python (tests/test_lab_page.py holds these to its numbers).

export const PERPENDICULAR = "max_perpendicular_error_m", DIRECTION = "initial_direction_error_deg";
const THRESHOLD = 0.05, DIRECTION_DELAY = 0.1, MIN_PEAK_SPEED = 0.01;

/** analysis.figure_metric: the perpendicular error under a force field, the initial direction error under a changed
 * display. A plan's trials carry their loads: any load at all is a force. */
export function figureMetric(plan) {
  return plan.trials.some((t) => t.load !== null) ? PERPENDICULAR : DIRECTION;
}

/** The samples of a reach: all, or those before space sent the hand home (TrialOutcome.reach_samples). */
function reachSamples(outcome) { return outcome.homeAt === null ? outcome.xs.length : outcome.homeAt; }

function interp(t, times, values) {
  const n = times.length;
  if (t <= times[0]) return values[0];
  if (t >= times[n - 1]) return values[n - 1];
  let lo = 0, hi = n - 1;
  while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (times[mid] <= t) lo = mid; else hi = mid; }
  return values[lo] + (t - times[lo]) / (times[hi] - times[lo]) * (values[hi] - values[lo]);
}

/** reach_metrics' measure ``metric`` of one finished trial (NaN where it is undefined), in its SI unit. */
export function reachMeasure(outcome, trial, dt, metric) {
  const n = reachSamples(outcome);
  if (n < 2) return NaN;
  const xs = outcome.xs.slice(0, n), ys = outcome.ys.slice(0, n);
  const t = xs.map((_, i) => (outcome.goStep + i) * dt);
  const step = (t[n - 1] - t[0]) / (n - 1);
  const speed = new Float64Array(n);
  for (let i = 0; i < n; i++) {  // numpy's gradient: central differences inside, one-sided at the ends
    const a = i === 0 ? 0 : i === n - 1 ? n - 2 : i - 1, b = i === 0 ? 1 : i === n - 1 ? n - 1 : i + 1;
    const h = (b - a) * step;
    speed[i] = Math.hypot((xs[b] - xs[a]) / h, (ys[b] - ys[a]) / h);
  }
  let peak = 0;
  for (let i = 1; i < n; i++) if (speed[i] > speed[peak]) peak = i;
  if (!(speed[peak] >= MIN_PEAK_SPEED) || speed[peak] === 0) return NaN;
  const level = THRESHOLD * speed[peak];
  let tOn = t[0], tEnd = t[n - 1];
  for (let i = peak - 1; i >= 0; i--) {
    if (speed[i] < level) { tOn = t[i] + (level - speed[i]) / (speed[i + 1] - speed[i]) * (t[i + 1] - t[i]); break; }
  }
  for (let j = peak + 1; j < n; j++) {
    if (speed[j] < level) {
      tEnd = t[j - 1] + (speed[j - 1] - level) / (speed[j - 1] - speed[j]) * (t[j] - t[j - 1]);
      break;
    }
  }
  const at = (time) => [interp(time, t, xs), interp(time, t, ys)];
  const [sx, sy] = trial.home, [tx, ty] = trial.position;
  const distance = Math.hypot(tx - sx, ty - sy);
  if (!(distance > 0)) return NaN;
  const ux = (tx - sx) / distance, uy = (ty - sy) / distance;
  if (metric === PERPENDICULAR) {
    const path = [at(tOn)];
    for (let i = 0; i < n; i++) if (t[i] > tOn && t[i] < tEnd) path.push([xs[i], ys[i]]);
    path.push(at(tEnd));
    let deviation = 0, most = -1;
    for (const [x, y] of path) {
      const side = ux * (y - sy) - uy * (x - sx);
      if (Math.abs(side) > most) { most = Math.abs(side); deviation = side; }
    }
    return deviation;
  }
  const [ox, oy] = at(tOn), [dx, dy] = at(Math.min(tOn + DIRECTION_DELAY, t[n - 1]));
  const mx = dx - ox, my = dy - oy;
  if (mx === 0 && my === 0) return NaN;
  const direction = Math.atan2(ux * my - uy * mx, ux * mx + uy * my) * 180 / Math.PI;
  return direction === -180 ? 180 : direction;
}

/** analysis.display_unit: cm for distances, degrees for angles. */
export function displayUnit(metric) { return metric === PERPENDICULAR ? [100, "cm"] : [1, "deg"]; }

/** analysis.outcome_word: "hit", "missed" (a reach without a cursor that stopped off the target) or "time out";
 * null on a trial that gives no feedback (a no-vision probe tells nothing, not even whether it hit). */
export function outcomeWord(outcome, trial, timeoutSteps) {
  if (trial.feedback === "none") return null;
  if (outcome.hit) return "hit";
  return outcome.endStep - outcome.goStep >= timeoutSteps ? "time out" : "missed";
}

/** analysis.result_words: the reach's measure in words, "1.9 cm off the line (left)" or "aimed 12 deg clockwise". */
export function resultWords(value, metric, hit) {
  if (!Number.isFinite(value)) return hit ? "on target" : "no reach";
  if (metric === PERPENDICULAR) {
    const side = Math.abs(value) < 0.0005 ? "" : value > 0 ? " (left)" : " (right)";
    return (Math.abs(value) * 100).toFixed(1) + " cm off the line" + side;
  }
  if (Math.abs(value) < 0.5) return "aimed straight at the target";
  return "aimed " + Math.abs(value).toFixed(0) + " deg " + (value > 0 ? "anticlockwise" : "clockwise") + " of the target";
}

/** The perturbation's kind a trial ran with, as the trials table names it (analysis.perturbation_label): "none" where
 * nothing acted (a catch trial, a mix's "off"), "channel" on a channel trial, else its block's kind (a mix's opposite
 * field is the same kind). */
function perturbationOf(plan, trial) {
  if (trial.channel) return "channel";
  if (trial.load === null && trial.display === null) return "none";
  return plan.protocol.blocks[trial.block].perturbation;
}

/** analysis.learning_curve of a run's finished trials: a point per trial (trial number, value in the unit shown,
 * catch), each block's span, whether it is perturbed and its mean (catch trials left out), and the after-effect
 * (the first measured trial after a perturbed block). */
export function learningCurve(plan, outcomes, dt) {
  const metric = figureMetric(plan);
  const [scale, unit] = displayUnit(metric);
  const spans = [];
  for (const o of outcomes) {
    const trial = plan.trials[o.trial];
    const row = { trial: o.trial + 1, value: reachMeasure(o, trial, dt, metric) * scale, label: perturbationOf(plan, trial) };
    const last = spans[spans.length - 1];
    if (last && last.block === trial.block) last.rows.push(row); else spans.push({ block: trial.block, rows: [row] });
  }
  const points = [], blocks = [];
  let after = null, previousPerturbed = false, unperturbed = null;
  for (const span of spans) {
    const counts = new Map();
    for (const r of span.rows) counts.set(r.label, (counts.get(r.label) ?? 0) + 1);
    let label = null;  // the most trials' label (the first seen of equal counts)
    for (const r of span.rows) if (label === null || counts.get(r.label) > counts.get(label)) label = r.label;
    if (unperturbed === null) unperturbed = label;
    const perturbed = label !== unperturbed;
    const values = [];
    for (const r of span.rows) {
      const isCatch = r.label !== label;
      points.push({ trial: r.trial, value: r.value, catch: isCatch });
      if (Number.isFinite(r.value) && !isCatch) {
        values.push(r.value);
        if (after === null && previousPerturbed && !perturbed) after = { trial: r.trial, value: r.value };
      }
    }
    blocks.push({ name: plan.protocol.blocks[span.block].name, first: span.rows[0].trial,
      last: span.rows[span.rows.length - 1].trial, perturbed,
      mean: values.length ? values.reduce((a, b) => a + b, 0) / values.length : NaN });
    previousPerturbed = perturbed;
  }
  return { label: metric === PERPENDICULAR ? "perpendicular error" : "initial direction error", unit, metric, points,
    blocks, afterEffect: after };
}
