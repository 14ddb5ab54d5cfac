// The browser game's modules without a browser (node --test; tests/test_play_logic.py runs it in the default
// tier): the class's API and the outbox (outbox.js, on kept.js's real store over a fake localStorage, and a fake
// class answering fetch), the game on the page's clock (model.js), and where a frame's parts go (view.js's layout,
// with a fake text measure). No npm packages: Node's own test runner and assert.
import assert from "node:assert/strict";
import { beforeEach, describe, test } from "node:test";

const STATIC = new URL("../armgame/classroom/static/", import.meta.url);

// A Storage as the browser's: strings under string keys, in insertion order.
class FakeStorage {
  constructor() { this.items = new Map(); }
  get length() { return this.items.size; }
  key(i) { return [...this.items.keys()][i] ?? null; }
  getItem(k) { return this.items.has(k) ? this.items.get(k) : null; }
  setItem(k, v) { this.items.set(k, String(v)); }
  removeItem(k) { this.items.delete(k); }
}
globalThis.localStorage = new FakeStorage();

const kept = await import(new URL("kept.js", STATIC));
const { ANOTHER_CLASS, ClassLink, handInLine } = await import(new URL("outbox.js", STATIC));
const { COUNTDOWN, MAX_FRAME, PlayedGame } = await import(new URL("model.js", STATIC));
const { WARN_SECONDS, clockText, hudWords, layout } = await import(new URL("view.js", STATIC));

const CLASS = "c1a55", CODE = "ABCD";
const MEMBER = { code: CODE, name: "Ann", token: "tok-ann", seed: 7, duration: 60, class: CLASS };

// A class that answers each request with ``answer(path, init)``: {status, data}, or "unreachable" (fetch throws).
function fakeClass(answer) {
  const requests = [];
  const fetch = async (path, init = {}) => {
    requests.push({ path, headers: init.headers ?? {}, body: init.body });
    const a = answer(path, init);
    if (a === "unreachable") throw new TypeError("Failed to fetch");
    return { status: a.status, ok: a.status >= 200 && a.status < 300, json: async () => a.data };
  };
  return { fetch, requests };
}

const taken = { status: 200, data: { ok: true, message: "handed in: 3 points" } };
const joinedHere = { status: 200, data: { ok: true, name: "Ann", token: "tok-ann", seed: 7, class: CLASS } };

// A link to the class, Ann playing and the class here known; timers collected, run by the test.
function link(answer, { here = true } = {}) {
  const cls = fakeClass(answer), timers = [], answers = [];
  kept.saveMember(MEMBER);
  const l = new ClassLink({ fetch: cls.fetch, store: kept, timer: (f, ms) => timers.push([f, ms]),
    onAnswers: (r) => answers.push(r) });
  if (here) l.here = { class: CLASS, code: CODE };
  return { l, requests: cls.requests, timers, answers };
}

describe("outbox.js", () => {
  beforeEach(() => { globalThis.localStorage = new FakeStorage(); });

  test("a game is kept, sent with the class's code, the token, the class and the start ticket, and dropped once taken", async () => {
    const { l, requests } = link(() => taken);
    assert.deepEqual(l.member, MEMBER);
    const said = await l.handIn('{"game": 1}', "game", null, "tick-1");
    assert.equal(said.line, "handed in: 3 points");
    assert.equal(requests.length, 1);
    const { path, headers, body } = requests[0];
    assert.equal(path, "/api/handin");
    assert.equal(body, '{"game": 1}');
    assert.equal(headers.Authorization, "Bearer tok-ann");
    assert.equal(headers["X-Armgame-Code"], CODE);
    assert.equal(headers["X-Armgame-Class"], CLASS);
    assert.equal(headers["X-Armgame-Start"], "tick-1");
    assert.deepEqual(kept.outbox(), []);
  });

  test("a busy class keeps the game and tries again later, then says the kept game was taken", async () => {
    let busy = true;
    const { l, timers, answers } = link((path) => (path === "/api/handin" && busy ? { status: 503, data: null } : taken));
    const said = await l.handIn("{}", "game");
    assert.equal(said.kind, "kept");
    assert.match(said.line, /busy, your game is kept/);
    assert.equal(kept.outbox().length, 1);
    assert.equal(timers.length, 1);
    await l.handIn("{}", "game");
    assert.equal(timers.length, 1, "one retry waits for every kept game");
    busy = false;
    await timers[0][0]();
    await l.flushing;
    assert.deepEqual(kept.outbox(), []);
    assert.equal(answers.at(-1).length, 2, "both kept games handed in, oldest first");
  });

  test("another class here: the game stays kept, nothing more is sent to it, and the student is told", async () => {
    const { l, requests } = link(() => ({ status: ANOTHER_CLASS, data: { error: "another class" } }));
    const said = await l.handIn("{}", "game");
    assert.equal(l.here, null);
    assert.match(said.line, /not the one your game was played for/);
    assert.equal(kept.outbox().length, 1);
    assert.deepEqual(await l.flush(), []);
    assert.equal(requests.length, 1);
  });

  test("a refusal that will never change drops the game; an unreachable class keeps it", async () => {
    const { l } = link(() => ({ status: 400, data: { ok: false, error: "this is not a replay" } }));
    assert.equal((await l.handIn("{}", "game")).line, "not handed in: this is not a replay");
    assert.deepEqual(kept.outbox(), []);
    const away = link(() => "unreachable");
    const said = await away.l.handIn("{}", "run");
    assert.equal(said.line, "the class could not be reached: your run is kept and will be handed in");
    assert.equal(kept.outbox().length, 1);
  });

  test("only this class's games are handed in, with the code it took; another class's stay kept", async () => {
    kept.keepGame({ id: "old1", code: "WXYZ", token: "t-old", class: "0bad", body: "{}" });
    kept.keepGame({ id: "mine1", code: "abcd", token: "t-mine", class: null, body: "{}" });
    const { l, requests } = link(() => taken);
    const results = await l.flush();
    assert.deepEqual(results.map((r) => r.id), ["mine1"]);
    assert.equal(requests[0].headers["X-Armgame-Code"], CODE);
    assert.equal(requests[0].headers["X-Armgame-Class"], undefined);
    assert.deepEqual(kept.outbox().map((g) => g.id), ["old1"]);
  });

  test("a page that has not reached the class rejoins under its class before handing in", async () => {
    const { l, requests } = link((path) => (path === "/api/join" ? joinedHere : taken), { here: false });
    const said = await l.handIn("{}", "game");
    assert.equal(said.line, "handed in: 3 points");
    assert.deepEqual(requests.map((r) => r.path), ["/api/join", "/api/handin"]);
    assert.deepEqual(JSON.parse(requests[0].body), { code: CODE, name: "Ann", token: "tok-ann", class: CLASS });
    assert.deepEqual(l.here, { class: CLASS, code: CODE });
  });

  test("the class's state, the start ticket and the lines a hand-in shows", async () => {
    const { l } = link((path) => (path === "/api/standings" ? { status: 200, data: { closed: true, browser_lab: "x" } }
      : { status: 200, data: { ticket: "bad ticket!" } }));
    assert.deepEqual(await l.classState(), { closed: true, lab: true });
    assert.equal(await l.startTicket(), null, "a ticket the class could not have given is not sent back");
    const away = link(() => "unreachable");
    assert.deepEqual(await away.l.classState(), { closed: false, lab: false });
    assert.equal(handInLine({ status: 429, data: null }, "game").kind, "kept");
  });
});

describe("model.js", () => {
  test("a 30 Hz and a 144 Hz display reach the same step with the same state at the same moment", () => {
    const slow = new PlayedGame(MEMBER), fast = new PlayedGame(MEMBER);
    for (const p of [slow, fast]) p.game.keyEvent("d", "down");
    for (let i = 0; i < 60; i++) slow.advance(1 / 30);
    for (let i = 0; i < 288; i++) fast.advance(1 / 144);
    assert.equal(slow.taken, Math.floor(2 / slow.game.dt + 1e-9));
    assert.equal(fast.taken, slow.taken);
    assert.deepEqual(fast.game.state, slow.game.state);
  });

  test("a stalled frame is clamped, the countdown runs out, and the game ends", () => {
    const p = new PlayedGame({ ...MEMBER, duration: 1 });
    assert.equal(p.countDown(COUNTDOWN - 0.5), false);
    assert.equal(p.countDown(0.5), true);
    p.advance(5);
    assert.equal(p.taken, Math.floor(MAX_FRAME / p.game.dt + 1e-9));
    let over = false;
    for (let i = 0; i < 10 && !over; i++) over = p.advance(MAX_FRAME);
    assert.equal(over, true);
    assert.equal(p.alpha, 1);
  });
});

describe("view.js", () => {
  const arm = { l1: 0.34, l2: 0.46 };
  const hud = { seed: 7, name: "Ann", score: 12, timeLeft: 42.25, keys: ["d", "f", "j", "k"],
    names: ["pectoralis", "posterior deltoid", "biceps", "triceps"], activation: [0, 0.5, 2, -1],
    touchMode: false, resetCost: 2, phase: "playing", countdownLeft: 0 };
  const inside = (a, b) => a.x >= b.x - 1e-9 && a.y >= b.y - 1e-9 && a.x + a.w <= b.x + b.w + 1e-9 &&
    a.y + a.h <= b.y + b.h + 1e-9;

  for (const [w, h] of [[1280, 720], [844, 390], [390, 500], [300, 260], [2560, 1440]]) {
    test(`at ${w}x${h} the arm's whole reach is in the scene, the scene in the canvas, and as large as fits`, () => {
      const lay = layout(w, h, arm);
      const reach = { x: lay.reach.x, y: lay.reach.y, w: lay.reach.width, h: lay.reach.height };
      assert.ok(inside(lay.scene, { x: 0, y: 0, w, h }), JSON.stringify(lay.scene));
      assert.ok(inside(reach, lay.scene), JSON.stringify([lay.reach, lay.scene]));
      // The scene's shorter side holds the reach and its margin: no more room is left unused.
      const side = Math.min(lay.scene.w, lay.scene.h);
      assert.ok(Math.abs(lay.view.scale * 2 * (arm.l1 + arm.l2 + 0.04) - side) < 1e-9, String(lay.view.scale));
      assert.ok(Math.abs(lay.view.ox - (lay.scene.x + lay.scene.w / 2)) < 1e-9, "the shoulder in the middle");
    });
  }

  test("the HUD's words: the clock and its warning, the bars' levels, the help, the countdown", () => {
    const words = hudWords(hud);
    assert.deepEqual([words.seed, words.name, words.score, words.clock], ["seed 7", "Ann", "Score 12", "Time 42.3"]);
    assert.equal(words.warn, false);
    assert.equal(hudWords({ ...hud, timeLeft: WARN_SECONDS - 0.5 }).warn, true);
    assert.equal(hudWords({ ...hud, timeLeft: 0 }).warn, false, "a clock run out is not a warning");
    assert.deepEqual(words.bars.map((b) => b.level), [0, 0.5, 1, 0], "activations shown between 0 and 1");
    assert.deepEqual(words.bars.map((b) => b.key + " " + b.name), ["d pectoralis", "f posterior deltoid", "j biceps",
      "k triceps"]);
    assert.deepEqual(words.help, ["d/f shoulder", "j/k elbow", "space reset (-2)", "tab hide arm"]);
    assert.deepEqual(hudWords({ ...hud, touchMode: true }).help, ["the buttons pull the muscles", "reset costs 2"]);
    assert.equal(words.countdown, null);
    assert.deepEqual(hudWords({ ...hud, phase: "countdown", countdownLeft: 2.2 }).countdown,
      { number: "3", hint: "any key starts" });
    assert.deepEqual(hudWords({ ...hud, phase: "countdown", countdownLeft: 0.01, touchMode: true }).countdown,
      { number: "1", hint: "a tap starts" });
    assert.equal(clockText(5), " 5.0");
    assert.equal(clockText(100.2), "1:41");
  });
});
