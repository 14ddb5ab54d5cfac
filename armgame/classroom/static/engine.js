// The game's engine for a browser tab: armgame.game.session.GameSession, bit for bit.
//
// Every number a result depends on is computed here with the operations the Python computes it with, in the
// same order, in IEEE doubles: the muscles (game/muscles.py), RK4 (physics/integrators.py), the arm's accel
// (physics/twojoint.py), the arm's own sine (physics/trig.py: + - * only, never Math.sin), the rules' hand
// and targets (game/rules.py), and Python's random.Random (MT19937, seeded as CPython seeds from an int).
// JavaScript numbers are IEEE doubles and JavaScript never fuses a*b+c, so the same expressions give the
// same bits; tests/test_browser_engine.py holds this file to GameSession on thousands of games in Node.
// The server re-simulates every hand-in anyway (records.replay.Replay.verify): this engine only has to
// show the student the game the server will find.
//
// It plays one game, the class's (the standard arm, muscles and step; a seed, a clock and a target size of its own):
// the numbers that game's physics needs come computed by the Python in constants.js, generated from armgame's own
// definitions (armgame/classroom/jsconstants.py), so nothing here copies a parameter by hand.
//
// No build step, no eval, one import (constants.js): it runs as it is under a CSP of script-src 'self', and in Node.

import { ARM, ARMGAME_VERSION, DECAY, MAX_EVENTS, MAX_GAME_STEPS, MAX_TRIES, MOMENTS, MUSCLE_KEYS, RESET_KEY, RISE,
  STANDARD_CONFIG, TOGGLE_ARM_KEY } from "./constants.js";

export { ARMGAME_VERSION };
const DEG_TO_RAD = Math.PI / 180.0; // CPython's math.radians: x * degToRad, degToRad = pi / 180
const SIXTH = 1.0 / 6.0;

// ------------------------------------------------------------------ the arm's sine (physics/trig.py)
const MAX_ANGLE = 1e15;
const INV_PIO2 = 6.36619772367581382433e-01;
const SHIFT = 6755399441055744.0;
const PIO2_1 = 1.57079632673412561417e+00;
const PIO2_2 = 6.07710050630396597660e-11;
const PIO2_3 = 2.02226624871116645580e-21;
const S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03, S3 = -1.98412698298579493134e-04;
const S4 = 2.75573137070700676789e-06, S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
const C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03, C3 = 2.48015872894767294178e-05;
const C4 = -2.75573143513906633035e-07, C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;

/** [sin x, cos x] as armgame.physics.trig.sin_cos gives them, bit for bit. */
export function sinCos(x) {
  if (!(-MAX_ANGLE <= x && x <= MAX_ANGLE)) return [NaN, NaN];
  const k = (x * INV_PIO2 + SHIFT) - SHIFT;
  const r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
  const z = r * r;
  const w = z * z;
  const s = r + z * r * (S1 + z * (S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6)));
  const hz = 0.5 * z;
  const v = 1.0 - hz;
  const c = v + (((1.0 - v) - hz) + z * (z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6))));
  const n = k - 4 * Math.floor(k / 4); // k mod 4, exact: k is a whole number below 2^51
  if (n === 0) return [s, c];
  if (n === 1) return [c, -s];
  if (n === 2) return [-s, -c];
  return [-c, s];
}

// ---------------------------------------------- Python's random.Random(seed): MT19937, CPython's seeding
/** Python's random.Random seeded from a whole number 0 <= seed < 2^63 (a BigInt). */
export class PythonRandom {
  constructor(seed) {
    const mt = new Uint32Array(624);
    this.mt = mt;
    // CPython's random_seed: the int's absolute value as 32-bit words, least significant first (one at least).
    let n = BigInt(seed);
    if (n < 0n) n = -n;
    const key = [];
    while (n > 0n) {
      key.push(Number(n & 0xffffffffn));
      n >>= 32n;
    }
    if (key.length === 0) key.push(0);
    // init_genrand(19650218) then init_by_array(key), as in CPython's _randommodule.c.
    mt[0] = 19650218;
    for (let i = 1; i < 624; i++) {
      const prev = mt[i - 1] ^ (mt[i - 1] >>> 30);
      mt[i] = (Math.imul(1812433253, prev) + i) >>> 0;
    }
    let i = 1, j = 0;
    for (let k = Math.max(624, key.length); k > 0; k--) {
      const prev = mt[i - 1] ^ (mt[i - 1] >>> 30);
      mt[i] = ((mt[i] ^ Math.imul(prev, 1664525)) + key[j] + j) >>> 0;
      i++; j++;
      if (i >= 624) { mt[0] = mt[623]; i = 1; }
      if (j >= key.length) j = 0;
    }
    for (let k = 623; k > 0; k--) {
      const prev = mt[i - 1] ^ (mt[i - 1] >>> 30);
      mt[i] = ((mt[i] ^ Math.imul(prev, 1566083941)) - i) >>> 0;
      i++;
      if (i >= 624) { mt[0] = mt[623]; i = 1; }
    }
    mt[0] = 0x80000000;
    this.index = 624;
  }

  _next() {
    const mt = this.mt;
    if (this.index >= 624) {
      for (let k = 0; k < 624; k++) {
        const y = (mt[k] & 0x80000000) | (mt[(k + 1) % 624] & 0x7fffffff);
        mt[k] = mt[(k + 397) % 624] ^ (y >>> 1) ^ ((y & 1) ? 0x9908b0df : 0);
      }
      this.index = 0;
    }
    let y = mt[this.index++];
    y ^= y >>> 11;
    y ^= (y << 7) & 0x9d2c5680;
    y ^= (y << 15) & 0xefc60000;
    y ^= y >>> 18;
    return y >>> 0;
  }

  /** random(): 53 random bits, as CPython's random_random. */
  random() {
    const a = this._next() >>> 5, b = this._next() >>> 6;
    return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
  }

  /** uniform(a, b) = a + (b - a) * random(), as Python's random.py. */
  uniform(a, b) {
    return a + (b - a) * this.random();
  }
}

// ------------------------------------------------------------------------------------- small helpers
/** Python's round(x) of a float to an int: the nearest, ties to even. */
function roundHalfEven(x) {
  const r = Math.round(x); // ties toward +infinity, exactly
  return (r - x === 0.5 && r % 2 !== 0) ? r - 1 : r;
}

export function fail(message) {
  throw new Error(message);
}

function number(value, name, low = -Infinity, high = Infinity) {
  if (typeof value !== "number" || !Number.isFinite(value) || value < low || value > high) {
    fail(`config.${name} must be a finite number from ${low} to ${high}, got ${JSON.stringify(value)}`);
  }
  return value;
}

function numbers(value, name, count, low, high) {
  if (!Array.isArray(value) || value.length !== count) fail(`config.${name} must be a list of ${count} numbers`);
  return value.map((v, i) => number(v, `${name}[${i}]`, low, high));
}

/** A seed (Number, BigInt or decimal string) as a BigInt, checked as GameConfig checks it. */
function seedOf(seed) {
  let big;
  if (typeof seed === "bigint") big = seed;
  else if (typeof seed === "number" && Number.isSafeInteger(seed)) big = BigInt(seed);
  else if (typeof seed === "string" && /^[0-9]{1,19}$/.test(seed)) big = BigInt(seed);
  else fail(`the seed must be a whole number from 0 to 2^63 - 1 (a decimal string above 2^53), got ${String(seed)}`);
  if (big < 0n || big >= (1n << 63n)) fail(`the seed must be from 0 to 2^63 - 1, got ${big}`);
  return big;
}

/** A BigInt seed as JSON data: a Number where it is exact, else the BigInt (JSON.stringify refuses it:
 * use replayJSON, which writes its digits). */
export function seedValue(big) {
  return big <= BigInt(Number.MAX_SAFE_INTEGER) ? Number(big) : big;
}

/** JSON text of plain data whose BigInts are written as their digits (JSON's numbers have no size limit). */
export function toJSON(value) {
  if (typeof value === "bigint") return value.toString();
  if (Array.isArray(value)) return "[" + value.map(toJSON).join(", ") + "]";
  if (value !== null && typeof value === "object") {
    return "{" + Object.keys(value).map((k) => JSON.stringify(k) + ": " + toJSON(value[k])).join(", ") + "}";
  }
  return JSON.stringify(value);
}

// ---------------------------------------------------------------------------- the standard game
/** Whether two pieces of JSON data are equal: numbers and text by ===, lists and objects item by item. */
function same(a, b) {
  if (Array.isArray(a)) return Array.isArray(b) && a.length === b.length && a.every((v, i) => same(v, b[i]));
  if (a !== null && typeof a === "object") {
    if (b === null || typeof b !== "object" || Array.isArray(b)) return false;
    const keys = Object.keys(a);
    return keys.length === Object.keys(b).length && keys.every((k) => k in b && same(a[k], b[k]));
  }
  return a === b;
}

/** The replay "config" of the class's standard game (records.replay.config_to_dict(GameConfig(seed=seed))), on
 * a clock of `duration` seconds: 60, or a rehearsal's 15 (records.rulesets.REHEARSAL), as the class's join answer
 * says. The replay records it (config.time_limit, result.duration), so the class verifies the game it names. */
export function standardConfig(seed, duration = 60.0) {
  const config = structuredClone(STANDARD_CONFIG);
  config.time_limit = duration;
  config.seed = seedValue(seedOf(seed));
  return config;
}

/** An ISO 8601 date as records.replay.now_iso writes it: UTC, microseconds, "+00:00". */
export function nowIso() {
  return new Date().toISOString().replace(/\.(\d{3})Z$/, ".$1000+00:00");
}

// ------------------------------------------------------------------------------------ the arm's physics
/** TwoJointArm's accel_with_damping (twojoint._build_components, its operations in its order) for the class's arm,
 * whose constants (constants.js's ARM) Python computed: a damped arm without gravity. */
function accel(q1, q2, w1, w2, t1, t2) {
  const { b, d, det0, aMinusD, k1, k2 } = ARM;
  const [sn, cs] = sinCos(q2);
  const bc = b * cs, h = b * sn, m12 = d + bc;
  const f1 = t1 + h * (w1 + w1 + w2) * w2 - k1 * w1;
  const f2 = t2 - h * w1 * w1 - k2 * w2;
  const r = 1.0 / (det0 - bc * bc);
  return [(d * f1 - m12 * f2) * r, ((m12 + aMinusD + bc) * f2 - m12 * f1) * r];
}

/** A replay config's physics, checked: the class's arm, muscles, step and integrator (anything else is refused in
 * one line naming what differs), a seed (a BigInt) and a clock in steps. The game and the lab (labengine.js) both
 * step the arm on these. */
export function armPhysics(config) {
  if (config === null || typeof config !== "object") fail("the game's config must be an object");
  for (const name of Object.keys(STANDARD_CONFIG)) if (!(name in config)) fail(`config.${name} is missing`);
  if (config.integrator !== STANDARD_CONFIG.integrator) {
    fail(`the browser plays only RK4 games, this one uses ${JSON.stringify(config.integrator)}`);
  }
  for (const name of ["arm", "muscles", "dt"]) {
    if (!same(config[name], STANDARD_CONFIG[name])) {
      fail(`the browser plays only the class's game: this config's ${name} is not the class's`);
    }
  }
  const dt = STANDARD_CONFIG.dt;
  const timeLimit = number(config.time_limit, "time_limit", 0, 3600);
  const totalSteps = roundHalfEven(timeLimit / dt);
  if (!(timeLimit > 0) || totalSteps > MAX_GAME_STEPS) fail(`config.time_limit ${timeLimit} s is not a game's`);
  return { seed: seedOf(config.seed), dt, totalSteps, l1: ARM.l1, l2: ARM.l2, accel, keys: [...MUSCLE_KEYS],
    moments: MOMENTS.map((m) => [...m]), rise: [...RISE], decay: [...DECAY] };
}

/** integrators._rk4: one RK4 step of the arm under the held torques (t1, t2), as [q1, q2, w1, w2]. */
export function rk4(f, q1, q2, w1, w2, t1, t2, dt) {
  const h = 0.5 * dt;
  const [ka1, ka2] = f(q1, q2, w1, w2, t1, t2);
  const v1 = w1 + h * ka1, v2 = w2 + h * ka2;
  const [kb1, kb2] = f(q1 + h * w1, q2 + h * w2, v1, v2, t1, t2);
  const u1 = w1 + h * kb1, u2 = w2 + h * kb2;
  const [kc1, kc2] = f(q1 + h * v1, q2 + h * v2, u1, u2, t1, t2);
  const z1 = w1 + dt * kc1, z2 = w2 + dt * kc2;
  const [kd1, kd2] = f(q1 + dt * u1, q2 + dt * u2, z1, z2, t1, t2);
  const k = dt * SIXTH;
  return [q1 + k * (w1 + z1 + 2.0 * (v1 + u1)), q2 + k * (w2 + z2 + 2.0 * (v2 + u2)),
    w1 + k * (ka1 + kd1 + 2.0 * (kb1 + kc1)), w2 + k * (ka2 + kd2 + 2.0 * (kb2 + kc2))];
}

// ------------------------------------------------------------------------------------------- the game
/** One game: GameSession's input, steps and rules, and the replay the server verifies. */
/** GameSession's arm, muscles, keys, clock and record, which the game (Game) and the lab's run (labengine.js's
 * LabRun) share, as LabSession is a GameSession in Python: each adds its rules, its advance and its reset. */
export class ArmSession {
  constructor(config) {
    const physics = armPhysics(config);
    this._config = config;
    this._seed = physics.seed;
    this._dt = physics.dt;
    this._totalSteps = physics.totalSteps;
    this._l1 = physics.l1;
    this._l2 = physics.l2;
    this._accel = physics.accel;
    // The arm's step without loads: RK4 of its accel. A lab trial's reach swaps in its loads' (labengine.js).
    this._step = (q1, q2, w1, w2, t1, t2, dt) => rk4(physics.accel, q1, q2, w1, w2, t1, t2, dt);
    this._muscleKeys = physics.keys;
    this._moments = physics.moments;
    this._rise = physics.rise;
    this._decay = physics.decay;
    this._activation = [0.0, 0.0, 0.0, 0.0];
    this._goal = [0.0, 0.0, 0.0, 0.0];
    this._rate = [...this._decay];
    this._held = [false, false, false, false];
    this._start = numbers(config.start_posture, "start_posture", 2, -7, 7);
    this._resetCost = config.reset_cost;
    if (!Number.isInteger(this._resetCost) || this._resetCost < 0) fail("config.reset_cost must be a whole number");
    this._score = 0;
    this._hits = 0;
    this._resets = 0;
    this._armVisible = true;
    this._steps = 0;
    const [q1, q2] = this._start;
    this._state = [q1, q2, 0.0, 0.0];
    this._previous = this._state;
    this._timeline = [];
  }

  /** rules.hand_position: the arm's own sine, the same bits as Python's. */
  _handAt(q1, q2) {
    const [s1, c1] = sinCos(q1);
    const [s12, c12] = sinCos(q1 + q2);
    return [this._l1 * c1 + this._l2 * c12, this._l1 * s1 + this._l2 * s12];
  }

  /** The reset key's common part: the arm at (q1, q2) at rest, the muscles relaxed, the reset counted and paid. */
  _resetTo(q1, q2) {
    this._state = this._previous = [q1, q2, 0.0, 0.0];
    this._activation = [0.0, 0.0, 0.0, 0.0];
    this._resets += 1;
    this._score = Math.max(0, this._score - this._resetCost);
  }

  /** GameSession.key_event: a key ("d", "space", "tab"...) going "down" or "up" before the next step. Returns
   * whether it acted (only those enter the timeline). The reset key is each session's own ``_reset``. */
  keyEvent(key, action) {
    if (this.over) return false;
    if (this._timeline.length >= MAX_EVENTS) {
      this._totalSteps = this._steps; // the game stops here, as the Python's does
      return false;
    }
    const i = this._muscleKeys.indexOf(key);
    if (i >= 0) {
      const down = action === "down";
      if (this._held[i] === down) return false;
      this._held[i] = down;
      this._goal[i] = down ? 1.0 : 0.0;
      this._rate[i] = down ? this._rise[i] : this._decay[i];
    } else if (key === RESET_KEY && action === "down") {
      this._reset();
    } else if (key === TOGGLE_ARM_KEY && action === "down") {
      this._armVisible = !this._armVisible;
    } else {
      return false;
    }
    this._timeline.push([this._steps, key, action]);
    return true;
  }

  // ---------------------------------------------------------------------------------- physics
  /** GameSession.advance, and LabSession's: up to n physics steps, fewer at the clock's end or where the session's
   * rules end it (`_afterStep` returns true); returns how many ran. A step is GameSession._advance's, in its order:
   * the muscles' torques from their activation, the activation a step toward its goal, the arm one `_step` under
   * those torques, then the rules on the new state (`_afterStep`: the game's hit test, the lab's task). */
  advance(n) {
    if (!Number.isInteger(n)) fail(`advance takes a whole number of steps, got ${n}`);
    n = Math.min(n, this._totalSteps - this._steps);
    if (n <= 0 || this.over) return 0;
    const dt = this._dt, start = this._steps;
    const [g0, g1, g2, g3] = this._goal;
    const [r0, r1, r2, r3] = this._rate;
    const [[s0, e0], [s1, e1], [s2, e2], [s3, e3]] = this._moments;
    let ran = 0;
    while (ran < n) {
      let [a0, a1, a2, a3] = this._activation;
      const t1 = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3;
      const t2 = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3;
      a0 += (g0 - a0) * r0;
      a1 += (g1 - a1) * r1;
      a2 += (g2 - a2) * r2;
      a3 += (g3 - a3) * r3;
      this._activation = [a0, a1, a2, a3];
      const [q1, q2, w1, w2] = this._previous = this._state;
      this._state = this._step(q1, q2, w1, w2, t1, t2, dt);
      this._steps += 1;
      ran += 1;
      if (this._afterStep()) break;
    }
    const [q1, q2, w1, w2] = this._state;
    if (!Number.isFinite(q1 + q2 + w1 + w2)) {
      fail(`the arm's state became non-finite between t = ${start * dt} and ${(start + n) * dt} s`);
    }
    return ran;
  }

  // ---------------------------------------------------------------------------------- queries
  get steps() { return this._steps; }
  get totalSteps() { return this._totalSteps; }
  get dt() { return this._dt; }
  get over() { return this._steps >= this._totalSteps; }
  get state() { return [...this._state]; }
  get target() { return { ...this._target }; }
  get score() { return this._score; }
  get hits() { return this._hits; }
  get resets() { return this._resets; }
  get armVisible() { return this._armVisible; }
  get muscleActivation() { return [...this._activation]; }
  get muscleKeys() { return [...this._muscleKeys]; }
  get timeline() { return this._timeline.map((e) => [...e]); }

  /** GameSession.interpolated_angles: the joint angles a fraction alpha of a step past the previous state. */
  interpolatedAngles(alpha) {
    const [p1, p2] = this._previous, [c1, c2] = this._state;
    return [p1 + alpha * (c1 - p1), p2 + alpha * (c2 - p2)];
  }

  /** The hand [x, y] in metres (world coordinates), where the rules see it. */
  hand() {
    return this._handAt(this._state[0], this._state[1]);
  }

  /** GameSession.result() as JSON data. */
  result() {
    const c = this._config;
    return { score: this._score, hits: this._hits, resets: this._resets, seed: seedValue(this._seed),
      duration: c.time_limit, steps: this._steps, scene: c.scene, integrator: c.integrator, dt: c.dt,
      version: ARMGAME_VERSION };
  }

  /** The replay as records.replay.Replay.as_dict writes a keyboard game's, its driver the device a person
   * played it on ("browser", one of records.replay.KEYBOARD_DEVICES: still a person's game, not a program's).
   * A seed above 2^53 is a BigInt, which JSON.stringify refuses: replayJSON writes it. */
  replay(player) {
    const config = { ...this._config, seed: seedValue(this._seed) };
    return {
      format: "armgame-replay",
      format_version: 1,
      armgame_version: ARMGAME_VERSION,
      date: nowIso(),
      player: player ?? null,
      driven: "keyboard",
      driver: "browser",
      scene: this._config.scene,
      config,
      timeline: this.timeline,
      result: this.result(),
    };
  }

  /** The replay as JSON text, any seed's digits exact: what the page hands in. */
  replayJSON(player) {
    return toJSON(this.replay(player));
  }
}

export class Game extends ArmSession {
  constructor(config) {
    super(config);
    // GameRules, the class's: its target ranges and view. The target's size is the config's, which the class's game
    // fixes (its ruleset) and the engine's tests vary by an ulp to put a hit on the target's very edge.
    for (const name of ["target_shoulder_range", "target_elbow_range", "view", "scene"]) {
      if (!same(config[name], STANDARD_CONFIG[name])) {
        fail(`the browser plays only the class's game: this config's ${name} is not the class's`);
      }
    }
    this._radius = number(config.target_radius, "target_radius", 0.005, 0.5);
    this._shoulderRange = [...STANDARD_CONFIG.target_shoulder_range];
    this._elbowRange = [...STANDARD_CONFIG.target_elbow_range];
    this._view = [...STANDARD_CONFIG.view];
    this._rng = new PythonRandom(this._seed);
    this._hitTimes = [];
    this.tries = 0;
    const [q1, q2] = this._start;
    this._target = this._drawTarget(this._handAt(q1, q2));
  }

  // ------------------------------------------------------------------------------------ the rules
  /** GameRules._draw_target. */
  _drawTarget(hand) {
    const [xmin, xmax, ymin, ymax] = this._view;
    const r = this._radius;
    const clear = 3.0 * r;
    const clear2 = clear * clear;
    const [hx, hy] = hand;
    let best = null, bestDistance = -1.0;
    for (let tries = 1; tries <= MAX_TRIES; tries++) {
      const q1 = this._rng.uniform(this._shoulderRange[0], this._shoulderRange[1]) * DEG_TO_RAD;
      const q2 = this._rng.uniform(this._elbowRange[0], this._elbowRange[1]) * DEG_TO_RAD;
      const [x, y] = this._handAt(q1, q2);
      if (!(xmin + r <= x && x <= xmax - r && ymin + r <= y && y <= ymax - r)) continue;
      const dx = x - hx, dy = y - hy;
      const distance = dx * dx + dy * dy;
      if (distance > clear2) {
        this.tries += tries;
        return { x, y, radius: r };
      }
      if (distance > bestDistance) {
        best = { x, y, radius: r };
        bestDistance = distance;
      }
    }
    this.tries += MAX_TRIES;
    if (best === null) fail("no target fits on screen with these settings (target radius or ranges too large)");
    return best;
  }

  _contains(x, y) {
    const t = this._target;
    const dx = x - t.x, dy = y - t.y;
    return dx * dx + dy * dy <= t.radius * t.radius;
  }

  /** GameRules.hand_moved. */
  _handMoved(x, y, t) {
    if (!this._contains(x, y)) return false;
    this._score += 1;
    this._hits += 1;
    this._hitTimes.push(t);
    this._target = this._drawTarget([x, y]);
    return true;
  }

  // ------------------------------------------------------------------------------------ input
  /** The reset key: the arm back at its start posture (GameRules.reset). */
  _reset() {
    this._resetTo(...this._start);
  }

  /** GameSession._advance's rules after a step: a hand on the target is a hit (GameRules.hand_moved). */
  _afterStep() {
    const [hx, hy] = this.hand();
    this._handMoved(hx, hy, this._steps * this._dt);
    return false;
  }

  // ---------------------------------------------------------------------------------- queries
  get timeLeft() { return Math.max(0.0, (this._totalSteps - this._steps) * this._dt); }
  get hitTimes() { return [...this._hitTimes]; }
  get view() { return [...this._view]; }
}
