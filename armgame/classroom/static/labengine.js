// The lab's centre-out run for a browser tab: armgame.lab.session.LabSession (sine="arm"), bit for bit.
//
// The server hands the page the run's plan (armgame.lab.plan.lab_plan): its config and protocol and every trial
// resolved to numbers (target, go cue's delay, load, display transform, channel, home), so nothing here is drawn
// at random or built from the protocol. This file plays the plan on a key timeline with LabSession's rules, in
// its order: hold at home for the delay, the go cue, the reach (a hit held for the hold time, a no-cursor trial
// ending where the hand stopped, or the time-out), the arm put home at rest, the reset key. The arm's accel,
// RK4, the muscles, the loop that steps them (ArmSession.advance) and the arm's own sine are engine.js's, the
// game's: one definition of the physics.
// tests/test_browser_lab.py holds it to LabSession in Node; the server re-simulates every hand-in anyway.

import { ArmSession, fail, rk4, sinCos } from "./engine.js";

export const PLAN_FORMAT = "armgame-lab-plan";
export const PLAN_VERSION = 1;
export const HOLD = "hold", REACH = "reach";
const WENT = 1, ENDED = 2;
const TASK_KIND = "centre-out";

// ------------------------------------------------------------------------ loads (physics/loads.py)
/** A hand force's function (x, y, vx, vy) -> [fx, fy], as physics.loads' fields compute it. */
function handForce(spec) {
  const [kind, ...v] = spec;
  if (kind === "curl") {
    const [b] = v;
    return (x, y, vx, vy) => [b * vy, -b * vx];
  }
  if (kind === "viscous") {
    const [b11, b12, b21, b22] = v;
    return (x, y, vx, vy) => [b11 * vx + b12 * vy, b21 * vx + b22 * vy];
  }
  if (kind === "constant") {
    const [fx, fy] = v;
    return (x, y) => [fx + 0.0 * x, fy + 0.0 * y];
  }
  if (kind === "spring") {
    const [k, ax, ay] = v;
    return (x, y) => [-k * (x - ax), -k * (y - ay)];
  }
  return fail(`the lab's plan names no hand force ${JSON.stringify(kind)}`);
}

/** ChannelField.force: a spring and damper across the line through origin along the unit direction. */
function channelForce(channel) {
  const { stiffness, damping } = channel;
  const [ox, oy] = channel.origin, [ux, uy] = channel.direction;
  return (x, y, vx, vy) => {
    const d = -uy * (x - ox) + ux * (y - oy);
    const vn = -uy * vx + ux * vy;
    const f = -(stiffness * d + damping * vn);
    return [-uy * f, ux * f];
  };
}

/** loads._with_loads' accel (float backend, the arm's own sine): the loads' torque added to the muscles'. */
function loadedAccel(base, l1, l2, force, joint) {
  const [c1, c2, v11, v12, v21, v22] = joint ?? [0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
  return (q1, q2, w1, w2, t1, t2) => {
    let e1 = c1 + v11 * w1 + v12 * w2;
    let e2 = c2 + v21 * w1 + v22 * w2;
    if (force !== null) {
      const [s1, k1] = sinCos(q1);
      const [s12, k12] = sinCos(q1 + q2);
      const j12 = -l2 * s12;
      const j22 = l2 * k12;
      const j11 = -l1 * s1 + j12;
      const j21 = l1 * k1 + j22;
      const [fx, fy] = force(l1 * k1 + l2 * k12, l1 * s1 + l2 * s12, j11 * w1 + j12 * w2, j21 * w1 + j22 * w2);
      e1 = e1 + j11 * fx + j21 * fy;
      e2 = e2 + j12 * fx + j22 * fy;
    }
    return base(q1, q2, w1, w2, t1 + e1, t2 + e2);
  };
}

/** The shown hand's transform (perturbations.rotation, mirror, joint_space), or null for the hand as it is. */
function display(spec) {
  if (spec === null) return null;
  const [kind, ...v] = spec;
  if (kind === "linear") {
    const [cx, cy, m11, m12, m21, m22] = v;
    return (x, y) => {
      const dx = x - cx, dy = y - cy;
      return [cx + m11 * dx + m12 * dy, cy + m21 * dx + m22 * dy];
    };
  }
  if (kind === "joint") {
    const [cx, cy, gain, h1, h2] = v;
    return (x, y, q1, q2) => [cx + gain * (q1 - h1), cy + gain * (q2 - h2)];
  }
  return fail(`the lab's plan names no display ${JSON.stringify(kind)}`);
}

function contains(target, x, y) {
  const dx = x - target.x, dy = y - target.y;
  return dx * dx + dy * dy <= target.radius * target.radius;
}

// --------------------------------------------------------------------------------------- SHA-256
const K256 = new Uint32Array([
  0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5, 0xd807aa98,
  0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
  0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8,
  0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
  0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819,
  0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
  0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
  0xc67178f2]);

/** SHA-256 of bytes, as hex: the lab's paths digest (record.paths_digest). A page served over plain HTTP on
 * the class's network is no secure context, so the browser's own digest (SubtleCrypto) is not there to ask. */
export function sha256Hex(bytes) {
  const length = bytes.length;
  const padded = new Uint8Array(((length + 9 + 63) >> 6) << 6);
  padded.set(bytes);
  padded[length] = 0x80;
  const bits = new DataView(padded.buffer);
  bits.setUint32(padded.length - 8, Math.floor(length / 0x20000000));
  bits.setUint32(padded.length - 4, (length * 8) >>> 0);
  const h = new Uint32Array([0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab,
    0x5be0cd19]);
  const w = new Uint32Array(64);
  const rotr = (x, n) => (x >>> n) | (x << (32 - n));
  for (let offset = 0; offset < padded.length; offset += 64) {
    for (let i = 0; i < 16; i++) w[i] = bits.getUint32(offset + 4 * i);
    for (let i = 16; i < 64; i++) {
      const s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >>> 3);
      const s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >>> 10);
      w[i] = (w[i - 16] + s0 + w[i - 7] + s1) >>> 0;
    }
    let [a, b, c, d, e, f, g, k] = h;
    for (let i = 0; i < 64; i++) {
      const t1 = (k + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + K256[i] + w[i]) >>> 0;
      const t2 = ((rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c))) >>> 0;
      k = g; g = f; f = e; e = (d + t1) >>> 0; d = c; c = b; b = a; a = (t1 + t2) >>> 0;
    }
    h[0] += a; h[1] += b; h[2] += c; h[3] += d; h[4] += e; h[5] += f; h[6] += g; h[7] += k;
  }
  return Array.from(h, (x) => x.toString(16).padStart(8, "0")).join("");
}

// -------------------------------------------------------------------------------------------- the run
/** One lab run: LabSession's input, steps and rules on the server's plan, and the replay the server verifies. */
export class LabRun extends ArmSession {
  constructor(plan) {
    if (plan === null || typeof plan !== "object" || plan.format !== PLAN_FORMAT) fail("this is not a lab plan");
    if (plan.format_version !== PLAN_VERSION) fail(`the lab plan's version ${plan.format_version} is not ${PLAN_VERSION}`);
    if (plan.sine !== "arm") fail("the browser's lab plays runs on the arm's own sine only");
    if (!Array.isArray(plan.trials) || plan.trials.length === 0) fail("the lab plan has no trials");
    const config = plan.config;
    super(config);
    if (config.scene !== "lab") fail(`a lab run's scene is "lab", got ${JSON.stringify(config.scene)}`);
    this._plan = plan;
    this._holdSteps = plan.hold_steps;
    this._timeoutSteps = plan.timeout_steps;
    this._targetRadius = plan.target_radius;
    this._homeRadius = plan.home_radius;
    this._distance = plan.distance;
    this._stillSpeed = plan.still_speed;
    this._trials = plan.trials;
    this._unloaded = this._step;
    this._home = [...plan.home];
    this._homeQ = [...plan.home_q];
    this._homeTarget = { x: this._home[0], y: this._home[1], radius: this._homeRadius };
    this._outcomes = [];
    this._trialIndex = 0;
    this._finished = false;
    this._phase = HOLD;
    this._cursor = [...this._home];
    this._counter = 0;
    this._goStep = 0;
    this._still = 0;
    this._xs = [];
    this._ys = [];
    this._homeAt = null;
    this._channel = false;
    this._target = this._homeTarget;
    this._enterTrial();
  }

  // ------------------------------------------------------------------------------------ the task
  /** The step function and shown-hand transform of a trial's reach (LabSession.physics_for, channel_for). */
  _reachPhysics(trial) {
    const l1 = this._l1, l2 = this._l2;
    let accel = null;
    if (trial.channel) {
      accel = loadedAccel(this._accel, l1, l2, channelForce(trial.channel_field), null);
    } else if (trial.load !== null) {
      const force = trial.load.hand ? handForce(trial.load.hand) : null;
      accel = loadedAccel(this._accel, l1, l2, force, trial.load.joint ?? null);
    }
    const step = accel === null ? this._unloaded : (q1, q2, w1, w2, t1, t2, dt) => rk4(accel, q1, q2, w1, w2, t1, t2, dt);
    return [step, trial.channel ? null : display(trial.display)];
  }

  _enterTrial() {
    this._channel = false;
    const trial = this._trials[this._trialIndex];
    if (trial === undefined) {
      this._finished = true;
      return;
    }
    const [h1, h2] = trial.home_q;
    if ((h1 !== this._homeQ[0] || h2 !== this._homeQ[1]) && !(h1 === 0.0 && h2 === 0.0)) {
      this._home = [...trial.home];
      this._homeQ = [h1, h2];
      this._homeTarget = { x: this._home[0], y: this._home[1], radius: this._homeRadius };
    }
    this._step = this._unloaded;
    this._show = null;
    this._phase = HOLD;
    this._counter = 0;
    this._target = this._homeTarget;
  }

  /** LabSession._task_step: the rules after a physics step, the shown hand at (x, y); 0, WENT or ENDED. */
  _taskStep(x, y) {
    this._cursor = [x, y];
    const trial = this._trials[this._trialIndex];
    if (this._phase === HOLD) {
      this._counter = contains(this._homeTarget, x, y) ? this._counter + 1 : 0;
      if (this._counter >= trial.delay_steps) {
        this._phase = REACH;
        this._goStep = this._steps;
        this._counter = 0;
        this._xs = [x];
        this._ys = [y];
        this._homeAt = null;
        this._target = { x: trial.position[0], y: trial.position[1], radius: this._targetRadius };
        this._still = 0;
        [this._step, this._show] = this._reachPhysics(trial);
        this._channel = trial.channel;
        return WENT;
      }
      return 0;
    }
    this._xs.push(x);
    this._ys.push(y);
    this._counter = contains(this._target, x, y) ? this._counter + 1 : 0;
    let hit = this._counter >= this._holdSteps;
    if (!hit && trial.feedback !== "full" && this._stopped(x, y)) {
      hit = contains(this._target, x, y); // without a cursor the reach ends where the hand stopped
    } else if (!hit && this._steps - this._goStep < this._timeoutSteps) {
      return 0;
    }
    this._outcomes.push({ trial: this._trialIndex, target: trial.target, goStep: this._goStep, endStep: this._steps,
      hit, xs: this._xs, ys: this._ys, homeAt: this._homeAt });
    if (hit) {
      this._hits += 1;
      this._score += 1;
    }
    this._trialIndex += 1;
    this._enterTrial();
    return ENDED;
  }

  /** LabSession._stopped: a no-cursor trial's hand, past half the target distance, slower than still_speed for
   * the hold time (or the time-out). */
  _stopped(x, y) {
    const xs = this._xs, ys = this._ys;
    const [hx, hy] = this._home;
    const away = (x - hx) * (x - hx) + (y - hy) * (y - hy) > 0.25 * this._distance * this._distance;
    if (away && xs.length >= 2) {
      const dx = x - xs[xs.length - 2], dy = y - ys[ys.length - 2];
      const limit = this._stillSpeed * this._dt;
      this._still = dx * dx + dy * dy < limit * limit ? this._still + 1 : 0;
    } else {
      this._still = 0;
    }
    return this._still >= this._holdSteps || this._steps - this._goStep >= this._timeoutSteps;
  }

  // ------------------------------------------------------------------------------------ input
  /** LabSession's reset: the hand home (its block's), at rest, counted; the trial's clock runs on. */
  _reset() {
    this._resetTo(...this._homeQ);
    this._cursor = this.shownHand();
    if (this._phase === REACH && this._homeAt === null && !this.over) this._homeAt = this._xs.length;
  }

  // ---------------------------------------------------------------------------------- physics
  /** LabSession._advance's rules after a step (engine.js's ArmSession.advance steps the muscles and the arm): the
   * task on the shown hand; at a trial's end the arm goes home at rest and the muscles relax. True once the run is
   * finished. */
  _afterStep() {
    const [q1, q2] = this._state;
    let [hx, hy] = this._handAt(q1, q2);
    if (this._show !== null) [hx, hy] = this._show(hx, hy, q1, q2);
    if (this._taskStep(hx, hy) !== ENDED) return false;
    const [h1, h2] = this._homeQ;
    this._state = this._previous = [h1, h2, 0.0, 0.0];
    this._activation = [0.0, 0.0, 0.0, 0.0];
    this._cursor = [...this._home];
    return this._finished;
  }

  /** LabSession.steps_before_an_end: the fewest steps after which the current trial could end (0 once over), so
   * a page that never advances further in one go shows each trial's end before the next begins. */
  stepsBeforeAnEnd() {
    if (this.over) return 0;
    if (this._phase === HOLD) return this._holdSteps;
    return Math.max(1, Math.min(this._holdSteps - this._counter, this._timeoutSteps - (this._steps - this._goStep)));
  }

  // ---------------------------------------------------------------------------------- queries
  get finished() { return this._finished; }
  get over() { return this._finished || this._steps >= this._totalSteps; }
  get phase() { return this._phase; }
  /** The step of the current trial's go cue (its last one while holding at home). */
  get goStep() { return this._goStep; }
  get trialIndex() { return this._trialIndex; }
  get trials() { return this._trials.length; }
  /** The current trial's plan (null once finished). */
  get trial() { return this._trials[this._trialIndex] ?? null; }
  get home() { return [...this._home]; }
  get cursor() { return [...this._cursor]; }
  /** LabSession.cursor_visible: always at home, and in a reach unless the trial hides it. */
  get cursorVisible() {
    const trial = this.trial;
    return this._phase === HOLD || trial === null || trial.feedback === "full";
  }
  /** Each finished trial: its index, target, go and end steps, hit, the shown hand's path and where space sent
   * the hand home (null: never). */
  get outcomes() { return this._outcomes.map((o) => ({ ...o, xs: [...o.xs], ys: [...o.ys] })); }

  /** The hand as the player is shown it (the trial's display transform applied). */
  shownHand() {
    const [x, y] = this.hand();
    return this._show === null ? [x, y] : this._show(x, y, this._state[0], this._state[1]);
  }

  /** LabSession.trial_records: each finished trial as [target, go_step, end_step, hit]. */
  trialRecords() {
    return this._outcomes.map((o) => [o.target, o.goStep, o.endStep, o.hit]);
  }

  /** record.paths_digest: SHA-256 of every trial's shown hand, its xs then its ys as little-endian doubles. */
  pathsDigest() {
    let count = 0;
    for (const o of this._outcomes) count += 2 * o.xs.length;
    const bytes = new Uint8Array(8 * count);
    const view = new DataView(bytes.buffer);
    let at = 0;
    for (const o of this._outcomes) {
      for (const values of [o.xs, o.ys]) {
        for (const v of values) {
          view.setFloat64(at, v, true);
          at += 8;
        }
      }
    }
    return sha256Hex(bytes);
  }

  /** The lab's task section (record.LabTask.as_dict). */
  task() {
    const task = { kind: TASK_KIND, protocol: this._plan.protocol, trials: this.trialRecords(),
      paths_sha256: this.pathsDigest() };
    if (this._plan.mixed) task.fields = this._outcomes.map((o) => this._trials[o.trial].field);
    task.sine = "arm";
    return task;
  }

  /** The replay as records.replay.Replay.as_dict writes a lab run's, played in a browser: the game's, with its task. */
  replay(player) {
    return { ...super.replay(player), task: this.task() };
  }
}
