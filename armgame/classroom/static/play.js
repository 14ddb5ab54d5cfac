// The class's game in a browser tab (/play): the engine (engine.js, the game's physics and rules ported
// bit for bit) plays the class's seed; this page joins, draws, reads keys and fingers, and hands the game in.
// Everything a student or the server wrote is set as text (textContent, fillText), never as HTML.
import { blend, circle, drawArm, drawTorso, rgb } from "./body.js";
import { Game, standardConfig } from "./engine.js";
import { dropGame, forgetMember, keepGame, loadMember, outbox, saveMember, tokenFor } from "./kept.js";

const RETRY_MS = 5000;

// ------------------------------------------------------------------ the looks (ui/palette.py, ui/render.py)
// PALETTES["high-contrast"]: black on white, every colour at least 4.5:1 on white (a bright classroom).
const PALETTE = {
  window: "rgb(255,255,255)", scene: "rgb(255,255,255)", workspace: "rgb(236,236,236)", edge: "rgb(0,0,0)",
  ink: "rgb(0,0,0)", faint: "rgb(0,0,0)", link: "rgb(0,0,0)", hand: "rgb(0,0,0)", target: [200, 0, 0],
  flash: "rgb(255,210,0)", warn: "rgb(170,0,0)", barBack: "rgb(200,200,200)",
  muscles: [[0, 80, 220], [180, 90, 0], [0, 120, 60], [160, 0, 160]], panel: "rgb(255,255,255)",
  skin: [225, 225, 225],
};
const FONT = '"DejaVu Sans", "Segoe UI", Helvetica, Arial, sans-serif';
const MIN_TEXT_AT_720 = 14, MIN_TEXT_FRACTION = 0.025, MIN_LINE = 3;
const FLASH_TIME = 0.35, PLUS_ONE_TIME = 0.9, FADE_IN = 0.3, WARN_SECONDS = 10;
const COUNTDOWN = 3;
// A frame longer than this (a stalled tab) is clamped: the game slows for a moment rather than jumping.
const MAX_FRAME = 0.25;
// ------------------------------------------------------------------ the page's parts
const canvas = document.getElementById("game");
const ctx = canvas.getContext("2d", { alpha: false });
const touch = document.getElementById("touch");
const joinForm = document.getElementById("join");
const endCard = document.getElementById("end");
const statusLine = document.getElementById("status");
// The last frames' times (ms of script and drawing each): benchmarks/browser_page.py and the tests read them.
canvas.frameTimes = [];

let member = loadMember();  // {code, name, token, seed, duration, class}: the name playing now
// The class this page's last join reached: {class: its id, code: the code it took}. Only its games are handed in,
// with that code; null until a join answers, and nothing kept is sent before (a game from another class never is).
let here = null;
let config = null, game = null, names = [], keys = [];
let phase = "join";  // join, countdown, playing, over, closed; lab-loading, lab, lab-over (the teacher's switch)
let lab = null;  // the lab's screen (labpage.js) while the class runs the lab in every browser
let countdownLeft = 0, clock = 0, taken = 0, last = null, alpha = 1;
const held = new Set();  // keys this page has pressed in the game and not yet released
const fingers = new Map();  // pointer id -> the key its button holds
let hits = [], seenHits = 0, lastTarget = null, touchMode = false;
let background = null, backgroundKey = "";

// ------------------------------------------------------------------ the class's API (same origin only)
async function post(path, body, headers = {}) {
  let response;
  try {
    response = await fetch(path, { method: "POST", body, credentials: "omit",
      headers: { "Content-Type": "application/json", ...headers } });
  } catch {
    return { status: 0, data: null };  // not reached: no answer at all
  }
  let data = null;
  try { data = await response.json(); } catch { data = null; }
  return { status: response.status, data };
}

function refusal(answer) {
  return answer.data && typeof answer.data.error === "string" ? answer.data.error : "the class refused (" + answer.status + ")";
}

// ``state``: the class's state asked before a new name joins. With the teacher's switch on, the join says it is for
// the lab (a closed class takes a new name for it). A name this browser has is known to the class: it rejoins as
// it always did, and the lab's own join follows if the switch is on (startLab).
async function join(code, name, token, state, cls = null) {
  const body = { code, name };
  if (token) body.token = token;
  if (cls) body.class = cls;  // a name kept from another class at this address is refused, and no guess counted
  if (state && state.lab) body.for = "lab";
  return post("/api/join", JSON.stringify(body));
}

// A refusal that will be the same every time (a game the class does not take): dropped from the outbox.
function final(status) {
  return status >= 400 && status < 500 && status !== 408 && status !== 429 && status !== ANOTHER_CLASS;
}
// The class's answer to a join or a game that names another class (app.py's OTHER_CLASS): the game stays kept.
const ANOTHER_CLASS = 410;

function classOf(data) { return typeof data.class === "string" && /^[0-9a-f]{1,64}$/.test(data.class) ? data.class : null; }

// A kept game is the class's here by the class's id; one kept before classes said it, by its code.
function belongsHere(game) {
  if (here === null) return false;
  if (game.class !== null && here.class !== null) return game.class === here.class;
  return game.code.toUpperCase() === here.code.toUpperCase();
}
function toHandIn() { return outbox().filter(belongsHere); }

// A kept game sent with the code the class here took at the join (its own class's, whatever code it was kept with).
function send(game) {
  const headers = { Authorization: "Bearer " + game.token, "X-Armgame-Code": here.code };
  if (game.class !== null) headers["X-Armgame-Class"] = game.class;
  return post("/api/handin", game.body, { ...headers, ...startHeader(game.start) });
}

let flushing = null;
// Every kept game handed in, oldest first; returns the answers ({game, answer}) to show.
function flushOutbox() {
  if (flushing === null) flushing = doFlush().finally(() => { flushing = null; });
  return flushing;
}
async function doFlush() {
  const results = [];
  for (;;) {
    const box = toHandIn();
    if (box.length === 0) break;
    const item = box[0];
    const answer = await send(item);
    results.push({ id: item.id, answer });
    if (answer.status === ANOTHER_CLASS) { here = null; break; }  // another class is here now: it is sent nothing
    if (!(answer.status === 200 && answer.data && answer.data.ok) && !final(answer.status)) {
      scheduleRetry();
      break;  // busy or unreachable: the rest wait with it
    }
    dropGame(item.id);
  }
  showOutbox();
  return results;
}

let retryTimer = null;
function scheduleRetry() {
  if (retryTimer !== null) return;
  retryTimer = setTimeout(async () => {
    retryTimer = null;
    if (here === null) await rejoin();
    if (here !== null) flushOutbox().then(showAnswers);
  }, RETRY_MS);
}

// The name playing now joined again, to learn which class is here (the page played on while the class was away).
// It names its class: another class at this address refuses it without counting a guess. Returns the answer.
async function rejoin() {
  if (member === null) return { status: 0, data: null };
  const answer = await join(member.code, member.name, member.token, null, member.class);
  if (answer.status === 200 && answer.data && answer.data.ok) {
    here = { class: classOf(answer.data), code: member.code };
    if (member.class === null && here.class !== null) { member.class = here.class; saveMember(member); }
  } else if (answer.status === 0 || answer.status === 408 || answer.status === 429 || answer.status >= 500) {
    scheduleRetry();
  }
  showOutbox();
  return answer;
}

function showOutbox() {
  const box = outbox(), mine = here === null ? box : box.filter(belongsHere);
  const elsewhere = box.filter((g) => !mine.includes(g));
  const between = phase !== "playing" && phase !== "lab" && phase !== "lab-loading";
  statusLine.replaceChildren();
  if (phase === "closed") statusLine.append(CLOSED + " · ");
  if (member) statusLine.append((lab !== null ? "in the lab as " : "playing as ") + member.name + " ");
  if (mine.length > 0) statusLine.append("· " + games(mine.length) + (here === null ? " kept " : " kept, to hand in "));
  if (elsewhere.length > 0) {
    // Games played for another class at this address (last week's): never handed in here; the student may let go.
    statusLine.append("· " + games(elsewhere.length) + " kept from another class, not handed in here ");
    if (between) statusLine.append(discardButton(elsewhere), " ");
  }
  if (member && between) {
    const change = document.createElement("button");
    change.type = "button";
    change.id = "not-me";
    change.textContent = "not " + member.name + "?";
    change.addEventListener("click", forget);
    statusLine.append(change);
  }
}

function games(n) { return n === 1 ? "1 game" : n + " games"; }

// Two clicks: the first asks, the second lets the games go.
function discardButton(elsewhere) {
  const button = document.createElement("button");
  button.type = "button";
  button.id = "discard";
  button.textContent = "discard " + (elsewhere.length === 1 ? "it" : "them");
  button.addEventListener("click", () => {
    if (button.dataset.sure !== "yes") {
      button.dataset.sure = "yes";
      button.textContent = "discard " + games(elsewhere.length) + " for good?";
      return;
    }
    for (const game of elsewhere) dropGame(game.id);
    showOutbox();
  });
  return button;
}

// ------------------------------------------------------------------ joining
function askToJoin(error) {
  phase = "join";
  joinForm.hidden = false;
  endCard.hidden = true;
  document.getElementById("join-error").textContent = error || "";
  if (member) {
    document.getElementById("code").value = member.code;
    document.getElementById("name").value = member.name;
  }
  document.getElementById(member ? "name" : "code").focus();
  showOutbox();
}

// "not Ann?": another name plays next; Ann's token stays (NAMES), for when she joins on this browser again.
function forget() {
  member = null;
  forgetMember();
  askToJoin("");
}

joinForm.addEventListener("submit", async (event) => {
  event.preventDefault();
  const code = document.getElementById("code").value.trim();
  const name = document.getElementById("name").value.trim();
  const button = document.getElementById("join-button");
  button.disabled = true;
  // A name this browser joined under before keeps its token (the class knows it); a new one starts afresh.
  const state = await classState();
  const answer = await join(code, name, tokenFor(code, name), state);
  button.disabled = false;
  if (answer.status === 0) {
    document.getElementById("join-error").textContent = "the class could not be reached: is this the address on the projector?";
    return;
  }
  if (!(answer.data && answer.data.ok)) {
    document.getElementById("join-error").textContent = refusal(answer);
    return;
  }
  joined(code, answer.data, state);
});

// ``state``: the class's state asked just before (the next run chosen at once), or null: the game starts at once
// (a tap just after the page loads starts it), and the lab replaces it if the teacher's switch is on.
function joined(code, data, state = null) {
  // The class's game: its seed and its clock (a rehearsal's games are 15 s; a class that does not say: 60 s).
  member = { code, name: data.name, token: data.token, seed: data.seed, duration: data.duration ?? 60,
    class: classOf(data) };
  here = { class: member.class, code };
  saveMember(member);
  joinForm.hidden = true;
  statusLine.textContent = "";
  if (state !== null) nextRun(state);
  else if (data.closed) nextRun();
  else {
    newGame();
    classState().then((s) => { if (s.lab && phase === "countdown") startLab(); });
  }
  flushOutbox().then(showAnswers);
}

// A closed class takes no games: none is started that could not be handed in. The page asks again every few
// seconds and starts one once the teacher opens the class.
let closedTimer = null;
const CLOSED = "the class is closed: it takes no more games (the game starts if the teacher opens it)";
// What the class says of itself now (public: the projector's standings): closed, and whether the teacher has every
// browser run the lab. Not reached: {closed: false, lab: false}, and the game is played, kept, handed in later.
async function classState() {
  try {
    const r = await fetch("/api/standings", { cache: "no-store" });
    const s = r.ok ? await r.json() : {};
    return { closed: s.closed === true, lab: typeof s.browser_lab === "string" && s.browser_lab !== "" };
  } catch (e) {
    return { closed: false, lab: false };
  }
}

function waitWhileClosed() {
  phase = "closed";
  endCard.hidden = true;
  showOutbox();
  clearTimeout(closedTimer);
  closedTimer = setTimeout(() => nextRun(), 5000);
}

// What a student does next: the lab when the teacher has switched it on (a closed class takes lab runs), else the
// game, or a wait while the class is closed. ``known``: the class's state just asked (else it is asked now).
async function nextRun(known) {
  const state = known ?? await classState();
  if (state.lab) { startLab(); return; }
  if (state.closed) { waitWhileClosed(); return; }
  newGame();
}

async function playAgain() { await nextRun(); }

// The teacher's switch, looked for every few seconds while no game is under way: a student at the countdown goes to
// the lab at once; one looking at their score is told, and "Play again" starts it. A game under way is finished.
setInterval(async () => {
  if (member === null || (phase !== "countdown" && phase !== "over")) return;
  const state = await classState();
  if (!state.lab) return;
  if (phase === "countdown") startLab();
  else if (phase === "over") statusLine.textContent = "the teacher has started the lab: Play again starts it";
}, 5000);

// ------------------------------------------------------------------ the lab (the teacher's switch)
let labTimer = null;
// The lab's join says it is for the lab (a closed class takes it; in a classroom experiment it assigns the student's
// condition), then the plan of the student's run (/api/labplan, asked as the student: the plan of their condition).
async function startLab() {
  if (phase === "lab-loading" || phase === "lab") return;
  phase = "lab-loading";
  clearTimeout(closedTimer);
  clearTimeout(labTimer);
  endCard.hidden = true;
  document.getElementById("lab-end").hidden = true;
  statusLine.textContent = "the teacher has started the lab: loading it…";
  const answer = await post("/api/join", JSON.stringify({ code: member.code, name: member.name, token: member.token,
    for: "lab", ...(member.class ? { class: member.class } : {}) }));
  let plan = null;
  if (answer.status === 200 && answer.data && answer.data.ok) {
    here = { class: classOf(answer.data), code: member.code };
    try {
      const r = await fetch("/api/labplan", { cache: "no-store", credentials: "omit",
        headers: { Authorization: "Bearer " + member.token, "X-Armgame-Code": member.code } });
      plan = r.ok ? await r.json() : null;
    } catch { plan = null; }
  }
  if (plan === null) {
    phase = "closed";  // asked again in a few seconds
    statusLine.textContent = answer.status === 200 ? "the lab could not be loaded: trying again in a few seconds"
      : "the class could not be reached for the lab: trying again in a few seconds";
    labTimer = setTimeout(() => nextRun(), RETRY_MS);
    return;
  }
  // The lab's modules are loaded when a lab starts: a class that only plays the game never fetches them.
  let LabScreen;
  try { ({ LabScreen } = await import("./labpage.js")); } catch {
    phase = "closed";
    statusLine.textContent = "the lab could not be loaded: trying again in a few seconds";
    labTimer = setTimeout(() => nextRun(), RETRY_MS);
    return;
  }
  game = null;
  lab = new LabScreen(plan, canvas, member.name, touchMode);
  keys = lab.keys;
  names = plan.config.muscles.map((m) => m.name);
  labelButtons("home", "");
  document.body.classList.add("lab");
  document.getElementById("lab-head").hidden = false;
  phase = "lab";
  held.clear();
  fingers.clear();
  showOutbox();
}

async function finishLab() {
  phase = "lab-over";
  document.body.classList.add("lab-over");
  held.clear();
  fingers.clear();
  document.getElementById("lab-again").textContent = "Run the lab again";
  const answer = await handIn(lab.replayJSON(), "run");
  lab.answer(answer.line, answer.kind);
  showOutbox();
  document.getElementById("lab-again").focus();
}

function leaveLab() {
  lab = null;
  document.body.classList.remove("lab", "lab-over");
  document.getElementById("lab-head").hidden = true;
  document.getElementById("lab-card").hidden = true;
  document.getElementById("lab-end").hidden = true;
}

document.getElementById("lab-go").addEventListener("click", () => { if (phase === "lab") lab.goOn(); });
document.getElementById("lab-again").addEventListener("click", () => { if (phase === "lab-over") { leaveLab(); nextRun(); } });

// ------------------------------------------------------------------ a game
function newGame() {
  leaveLab();
  config = standardConfig(member.seed, member.duration ?? 60);
  game = new Game(config);
  names = config.muscles.map((m) => m.name);
  keys = game.muscleKeys;
  labelButtons("reset", "-" + config.reset_cost);
  phase = "countdown";
  countdownLeft = COUNTDOWN;
  clock = 0; taken = 0; alpha = 1; hits = []; seenHits = 0; lastTarget = game.target;
  held.clear();
  fingers.clear();
  endCard.hidden = true;
  showOutbox();
}

function press(key) {
  if (phase === "lab") { lab.press(key); return; }
  if (phase === "countdown") { start(); return; }  // any key starts, and is not the game's input
  if (phase !== "playing" || held.has(key)) return;
  held.add(key);
  game.keyEvent(key, "down");
}

function lift(key) {
  if (phase === "lab" || phase === "lab-over") { lab.lift(key); return; }
  if (!held.delete(key)) return;
  if (phase === "playing") game.keyEvent(key, "up");
}

// Every held key let go, into the game as key-ups (the tab lost focus; a finger left the screen unseen).
function releaseAll() {
  if (lab !== null) lab.releaseAll();
  for (const key of [...held]) lift(key);
  fingers.clear();
  touch.querySelectorAll("button.held").forEach((b) => b.classList.remove("held"));
}

function start() {
  phase = "playing";
  ticket = startTicket(member);
  showOutbox();
}

// The class's start ticket for the game beginning now: its hand-in sends it back, and a round counts only games
// begun during it. Never waited for by the game; no ticket (an older class, no answer) is a game kept on the board
// but not in a round.
let ticket = null;
const TICKET = /^[A-Za-z0-9_-]{1,64}$/;
async function startTicket(m) {
  const answer = await post("/api/start", "{}", { Authorization: "Bearer " + m.token, "X-Armgame-Code": m.code });
  const t = answer.status === 200 && answer.data ? answer.data.ticket : null;
  return typeof t === "string" && TICKET.test(t) ? t : null;
}
function startHeader(t) { return typeof t === "string" && TICKET.test(t) ? { "X-Armgame-Start": t } : {}; }

async function finish() {
  phase = "over";
  held.clear();
  fingers.clear();
  showEnd("handing in…", "");
  const body = game.replayJSON(member.name);  // any seed's digits exact (a seed past 2^53 is a BigInt)
  const start = ticket === null ? null : await ticket;
  ticket = null;
  const answer = await handIn(body, "game", (line) => showEnd(line, ""), start);
  if (answer.data) showEnd(answer.line, answer.kind, answer.data); else showEnd(answer.line, answer.kind);
}

// A game's or a lab run's replay kept first, then sent: a page closed while the answer is on its way hands it in
// next time. Returns the line to show ({line, kind, data}); ``showing`` is told the line while it is on its way.
async function handIn(body, what, showing, start = null) {
  const id = Date.now().toString(36) + Math.random().toString(36).slice(2, 8);
  const game = { id, code: member.code, token: member.token, class: member.class, body, ...(start ? { start } : {}) };
  const kept = keepGame(game);
  if (!kept && showing) showing("handing in (this browser keeps nothing: stay on the page)…");
  // This game first, by itself: another tab's hand-in may send it too, and the class takes a game once.
  const answer = here === null ? await rejoin() : null;
  if (here === null) return handInLine(answer, what);
  if (!belongsHere(game)) return handInLine({ status: ANOTHER_CLASS, data: null }, what);
  const mine = await send(game);
  if (mine.status === ANOTHER_CLASS) here = null;
  else if ((mine.status === 200 && mine.data && mine.data.ok) || final(mine.status)) dropGame(id);
  else scheduleRetry();
  showAnswers(here !== null && mine.status === 200 ? await flushOutbox() : []);
  showOutbox();
  return handInLine(mine, what);
}

function handInLine(answer, what) {
  if (answer.status === 200 && answer.data && answer.data.ok) return { line: answer.data.message, kind: "", data: answer.data };
  if (answer.status === 0) return { line: `the class could not be reached: your ${what} is kept and will be handed in`, kind: "kept" };
  if (answer.status === ANOTHER_CLASS) {
    return { line: `kept, not handed in: the class here is not the one your ${what} was played for`, kind: "kept" };
  }
  if (answer.status === 503 || answer.status === 429 || answer.status === 408 || answer.status >= 500) {
    return { line: `the class is busy, your ${what} is kept and will be handed in`, kind: "kept" };
  }
  return { line: "not handed in: " + refusal(answer), kind: "kept" };
}

function showHandIn(answer) {
  const said = handInLine(answer, "game");
  if (said.data) showEnd(said.line, said.kind, said.data); else showEnd(said.line, said.kind);
}

// Games from before (the outbox) handed in now: one line for the student, under whatever is on screen.
function showAnswers(results) {
  const taken = results.filter((r) => r.answer.status === 200 && r.answer.data && r.answer.data.ok);
  if (taken.length > 0) {
    const last = taken[taken.length - 1].answer.data;
    statusLine.textContent = (taken.length === 1 ? "a kept game was " : taken.length + " kept games were ") +
      last.message;
  }
  if (phase === "lab-over" && toHandIn().length === 0 && taken.length > 0 &&
      document.getElementById("lab-answer").className === "kept") {
    lab.answer(taken[taken.length - 1].answer.data.message, "");
  }
  if (phase === "over" && endCard.dataset.kept === "kept" && toHandIn().length === 0 && taken.length > 0) {
    const mine = taken[taken.length - 1];
    showHandIn(mine.answer);
  }
}

function showEnd(line, kind, data) {
  endCard.hidden = false;
  endCard.dataset.kept = kind;
  document.getElementById("end-score").textContent = "Your score: " + game.score;
  document.getElementById("end-hits").textContent = plural(game.hits, "hit") + ", " + plural(game.resets, "reset");
  const answer = document.getElementById("end-answer");
  answer.textContent = line;
  answer.className = kind;
  const table = document.getElementById("end-top");
  table.replaceChildren();
  if (data && Array.isArray(data.top)) {
    // The student's own row is the one the class names (data.yours): equal scores share a place, so the
    // place alone would mark every row tied with theirs.
    for (const [i, [rank, name, score]] of data.top.entries()) {
      const row = table.insertRow();
      if (i === data.yours) row.className = "mine";
      for (const [text, kind] of [[rank + ".", "rank"], [name, "name"], [String(score), "score"]]) {
        const cell = row.insertCell();
        cell.className = kind;
        cell.textContent = text;
      }
    }
  }
  document.getElementById("end-hint").textContent = touchMode ? "" : "Enter plays again";
  document.getElementById("again").focus();
}

function plural(n, word) { return n + " " + word + (n === 1 ? "" : "s"); }

document.getElementById("again").addEventListener("click", () => { if (phase === "over") playAgain(); });

// ------------------------------------------------------------------ keys and fingers
const SPECIAL = { " ": "space", "Tab": "tab" };
function gameKey(event) {
  const key = SPECIAL[event.key] ?? event.key.toLowerCase();
  return key === "space" || key === "tab" || keys.includes(key) ? key : null;
}

window.addEventListener("keydown", (event) => {
  if (phase === "join") return;
  if (phase === "lab" || phase === "lab-over") { labKey(event); return; }
  if (phase === "over") {
    if (event.key === "Enter") { event.preventDefault(); playAgain(); }
    return;
  }
  const key = gameKey(event);
  if (phase === "countdown" && !event.repeat && !event.ctrlKey && !event.metaKey && !event.altKey) {
    if (key !== null) event.preventDefault();
    start();
    return;
  }
  if (key === null || event.ctrlKey || event.metaKey || event.altKey) return;
  event.preventDefault();  // tab must not leave the page, space must not scroll it
  if (!event.repeat) press(key);
});
// The lab's keys, as the lab window's: the muscles' and space (the hand home; a card's "go on", as Enter is).
function labKey(event) {
  if (event.ctrlKey || event.metaKey || event.altKey) return;
  if (phase === "lab-over") {
    if (event.key === "Enter" && document.activeElement !== document.getElementById("lab-again")) {
      event.preventDefault();
      leaveLab();
      nextRun();
    }
    return;
  }
  const key = gameKey(event);
  if (event.key === "Enter" && lab.phase === "card") { event.preventDefault(); lab.goOn(); return; }
  if (key === null || key === "tab") { if (key === "tab") event.preventDefault(); return; }
  event.preventDefault();  // space must not scroll the page, nor press the card's button
  if (!event.repeat) lab.press(key);
}

window.addEventListener("keyup", (event) => {
  if (phase === "lab" || phase === "lab-over") {
    const key = gameKey(event);
    if (key !== null) { event.preventDefault(); lab.lift(key); }
    return;
  }
  const key = gameKey(event);
  if (key !== null && held.has(key)) { event.preventDefault(); lift(key); }
});
window.addEventListener("blur", releaseAll);
document.addEventListener("visibilitychange", () => { if (document.hidden) releaseAll(); });

// Each finger is its own pointer: two thumbs on two buttons hold two keys; a button stays held while any
// finger is on it.
function fingerDown(event) {
  const button = event.currentTarget;
  const key = button.id === "reset" ? "space" : button.dataset.key;
  event.preventDefault();
  touchMode = true;
  if (button.setPointerCapture) { try { button.setPointerCapture(event.pointerId); } catch { /* synthetic */ } }
  if (phase === "countdown") { start(); }
  if (phase !== "playing" && phase !== "lab") return;
  fingers.set(event.pointerId, key);
  button.classList.add("held");
  press(key);
}
function fingerUp(event) {
  const key = fingers.get(event.pointerId);
  if (key === undefined) return;
  fingers.delete(event.pointerId);
  if (![...fingers.values()].includes(key)) {
    event.currentTarget.classList.remove("held");
    lift(key);
  }
}
for (const button of touch.querySelectorAll("button")) {
  button.addEventListener("pointerdown", fingerDown);
  button.addEventListener("pointerup", fingerUp);
  button.addEventListener("pointercancel", fingerUp);
  button.addEventListener("lostpointercapture", fingerUp);
  button.addEventListener("contextmenu", (e) => e.preventDefault());
}
// Each muscle's button: its key's letter, large, and its muscle's name under it; reset says what it costs.
function labelButtons(reset, cost) {
  touch.querySelectorAll("button.muscle").forEach((b) => {
    const i = Number(b.dataset.index);
    const letter = document.createElement("span"), name = document.createElement("span");
    letter.className = "key"; letter.textContent = keys[i];
    name.className = "name"; name.textContent = names[i].split(" ").pop();
    b.replaceChildren(letter, name);
    b.setAttribute("aria-label", keys[i] + " " + names[i]);
    b.dataset.key = keys[i];
  });
  touch.querySelector("#reset .key").textContent = reset;
  touch.querySelector("#reset .name").textContent = cost;
}
// What the tests read of the page as it is played: the keys held, each muscle's activation, the resets, and the
// canvas's box as the last resize saw it.
Object.defineProperty(canvas, "debug", { get: () => (lab !== null ? { ...lab.debug, page: phase, box: [box.w, box.h] }
  : { phase, held: [...held], activation: game ? game.muscleActivation : [], resets: game ? game.resets : 0,
    box: [box.w, box.h] }) });
// A touch anywhere shows the buttons (a laptop with a touch screen too); so does a coarse pointer at load.
function showTouch() {
  if (!touch.hidden) return;
  touch.hidden = false;
  document.body.classList.add("touch");  // play.css gives the buttons their cells
  touchMode = true;
  if (lab !== null) lab.touched();
}
window.addEventListener("pointerdown", (e) => { if (e.pointerType === "touch") showTouch(); }, true);
canvas.addEventListener("pointerdown", () => { if (phase === "countdown") start(); });
if (matchMedia("(pointer: coarse)").matches) showTouch();

// ------------------------------------------------------------------ the frame loop
function frame() {
  requestAnimationFrame(frame);
  const began = performance.now();
  const elapsed = last === null ? 0 : (began - last) / 1000;
  last = began;
  if (phase === "lab") {
    lab.frame(elapsed);
    if (lab.over) finishLab();
  } else if (phase === "countdown") {
    countdownLeft -= Math.max(elapsed, 0);
    if (countdownLeft <= 0) start();
  } else if (phase === "playing") {
    // Real time consumed in fixed steps, kept as a running total (RealTimeDriver in game/session.py): a
    // 30 Hz and a 144 Hz display reach the same step at the same moment.
    const dt = game.dt;
    clock += Math.min(Math.max(elapsed, 0), MAX_FRAME);
    const due = Math.floor(clock / dt + 1e-9);
    if (due > taken) {
      game.advance(due - taken);
      taken = due;
    }
    alpha = Math.min(Math.max(clock / dt - due, 0), 1);
    noteHits();
    if (game.over) { alpha = 1; finish(); }
  }
  paint();
  const times = canvas.frameTimes;
  times.push(performance.now() - began);
  if (times.length > 600) times.splice(0, times.length - 600);
}

function noteHits() {
  const now = game.steps * game.dt;
  if (game.hits > seenHits && lastTarget !== null) hits.push([lastTarget.x, lastTarget.y, now]);
  seenHits = game.hits;
  lastTarget = game.target;
  hits = hits.filter((h) => now - h[2] < Math.max(PLUS_ONE_TIME, FADE_IN));
}

// ------------------------------------------------------------------ drawing (ui/render.py's GameRenderer)
function textSizes(w, h) {
  const m = Math.min(w, h), u = m / 720;
  const minText = Math.max(Math.round(MIN_TEXT_AT_720 * m / 720), Math.round(MIN_TEXT_FRACTION * h));
  const small = Math.max(12, Math.round(18 * u), minText);
  return { small, normal: Math.max(Math.max(13, Math.round(22 * u)), small + 2), big: Math.max(18, Math.round(40 * u)) };
}

function font(size, bold) { return (bold ? "bold " : "") + size + "px " + FONT; }

function width(text, size, bold) { ctx.font = font(size, bold); return ctx.measureText(text).width; }

function fit(text, size, room) {
  if (width(text, size) <= room) return text;
  while (text && width(text + "…", size) > room) text = text.slice(0, -1);
  return text + "…";
}

function clockText(seconds) {
  if (seconds < 100) return seconds.toFixed(1).padStart(4, " ");
  const whole = Math.ceil(seconds);
  return Math.floor(whole / 60) + ":" + String(whole % 60).padStart(2, "0");
}

function layout(w, h) {
  // The canvas is its own cell: the buttons and the status line have cells of their own (play.css).
  const u = Math.min(w, h) / 720;
  const pad = Math.max(6, Math.round(16 * u)), gap = Math.max(4, Math.round(8 * u));
  const { small, normal, big } = textSizes(w, h);
  const landscape = w >= 1.15 * h;
  let hud, scene;
  if (landscape) {
    const needed = width("Time 00.0", big, true) + 2 * pad;
    const side = Math.min(Math.max(Math.round(w * 0.27), 200, needed), Math.max(480, needed), w - Math.round(h * 0.55));
    hud = { x: pad, y: pad, w: side - 2 * pad, h: h - 2 * pad };
    scene = { x: side, y: pad, w: w - side - pad, h: h - 2 * pad };
  } else {
    hud = { x: pad, y: pad, w: w - 2 * pad, h: h - 2 * pad };
    scene = { x: pad, y: 0, w: w - 2 * pad, h: 0 };
  }
  return { w, h, u, pad, gap, small, normal, big, landscape, hud, scene };
}

// The scene shows the arm's whole reach, every target in it, and a margin for the palm and a target's flash at its
// edge. The game's view (ui/render.py's) runs 0.4 m above the reach, where nothing is drawn, and cuts its bottom.
const REACH_MARGIN = 0.04;
function sceneWorld() {
  const r = config.arm.l1 + config.arm.l2 + REACH_MARGIN;
  return [-r, r, -r, r];
}

function viewport(scene, world) {
  const [xmin, xmax, ymin, ymax] = world;
  const scale = Math.min(scene.w / (xmax - xmin), scene.h / (ymax - ymin));
  const left = scene.x + (scene.w - scale * (xmax - xmin)) / 2, top = scene.y + (scene.h - scale * (ymax - ymin)) / 2;
  return { scale, ox: left - xmin * scale, oy: top + ymax * scale };
}

function roundRect(x, y, w, h, r, fill, stroke, line) {
  ctx.beginPath();
  ctx.roundRect(x, y, w, h, r);
  if (fill) { ctx.fillStyle = fill; ctx.fill(); }
  if (stroke) { ctx.lineWidth = line; ctx.strokeStyle = stroke; ctx.stroke(); }
}

// What never moves (the window, the scene, the reachable annulus, the torso): drawn once per size.
function drawBackground(lay, view, sx, sy) {
  const off = document.createElement("canvas");
  off.width = canvas.width; off.height = canvas.height;
  const g = off.getContext("2d", { alpha: false });
  g.fillStyle = PALETTE.window;
  g.fillRect(0, 0, off.width, off.height);  // every device pixel, the last row of a fractional box too
  g.scale(sx, sy);
  const s = lay.scene;
  g.beginPath();
  g.roundRect(s.x, s.y, s.w, s.h, Math.max(4, Math.round(12 * lay.u)));
  g.fillStyle = PALETTE.scene;
  g.fill();
  g.save();
  g.beginPath();
  g.rect(s.x, s.y, s.w, s.h);
  g.clip();
  const { l1, l2 } = config.arm;
  const line = Math.max(MIN_LINE, Math.round(2 * lay.u));
  circle(g, view.ox, view.oy, (l1 + l2) * view.scale, PALETTE.workspace, PALETTE.edge, line);
  circle(g, view.ox, view.oy, Math.abs(l1 - l2) * view.scale, PALETTE.scene, PALETTE.edge, line);
  drawTorso(g, view, PALETTE);
  g.restore();
  return off;
}

// The canvas's box (CSS px), as play.css's grid sizes its cell; its bitmap follows it in device pixels.
let box = { w: 0, h: 0 };
const resized = new ResizeObserver(([entry]) => {
  const device = entry.devicePixelContentBoxSize?.[0];
  const dpr = window.devicePixelRatio || 1;
  box = { w: entry.contentRect.width, h: entry.contentRect.height };
  const w = device ? device.inlineSize : Math.round(box.w * dpr), h = device ? device.blockSize : Math.round(box.h * dpr);
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; backgroundKey = ""; }
  if (paint()) return;  // before the page is painted: never blank
  ctx.setTransform(1, 0, 0, 1, 0, 0);  // no game yet (the join form over it): the window's colour, not black
  ctx.fillStyle = PALETTE.window;
  ctx.fillRect(0, 0, canvas.width, canvas.height);
});
// Its device pixels watched too, where the browser can (a window moved to a screen of another density); Safari
// watches the CSS box only.
try { resized.observe(canvas, { box: "device-pixel-content-box" }); } catch { resized.observe(canvas); }

// The lab's scene or the game's, whichever is on: false when neither is.
function paint() {
  if (lab !== null && member !== null) {
    lab.draw(box.w, box.h, canvas.width / Math.max(box.w, 1), canvas.height / Math.max(box.h, 1));
    return true;
  }
  if (game !== null && member !== null) { draw(); return true; }  // "not me?" forgets the name while the last game is on screen
  return false;
}

function draw() {
  const { w, h } = box;
  if (w < 1 || h < 1) return;
  const sx = canvas.width / w, sy = canvas.height / h;  // the device pixels a CSS px has, as the bitmap has them
  const lay = layout(w, h);
  const p = PALETTE, { hud, gap, small, normal, big } = lay;
  ctx.setTransform(sx, 0, 0, sy, 0, 0);
  ctx.textBaseline = "top";
  ctx.textAlign = "left";
  // The HUD's top: the mode, the score and the clock.
  const labels = [];
  let y = hud.y;
  // The mode's parts share a line where they fit (a long name goes on a line of its own), as in the window.
  const modeLines = [];
  for (const part of ["PLAY", "seed " + member.seed, member.name]) {
    const line = modeLines.length ? modeLines[modeLines.length - 1] + "   " + part : null;
    if (line !== null && width(line, normal) <= hud.w) modeLines[modeLines.length - 1] = line;
    else modeLines.push(fit(part, normal, hud.w));
  }
  for (const line of modeLines) {
    labels.push([line, hud.x, y, normal, p.ink, false]);
    y += Math.round(normal * 1.2) + gap / 2;
  }
  y += gap / 2;
  let head = big;
  const score = "Score " + game.score, clockLine = "Time " + clockText(game.timeLeft);
  const warn = game.timeLeft > 0 && game.timeLeft <= WARN_SECONDS;
  if (lay.landscape) {
    labels.push([score, hud.x, y, head, p.ink, true]);
    y += Math.round(head * 1.2) + gap;
    labels.push([clockLine, hud.x, y, head, warn ? p.warn : p.ink, true]);
  } else {
    while (head > normal && width("Score 000", head, true) + 2 * gap + width("Time 00.0", head, true) > hud.w) head -= 1;
    labels.push([score, hud.x, y, head, p.ink, true]);
    labels.push([clockLine, hud.x + hud.w - width("Time 00.0", head, true), y, head, warn ? p.warn : p.ink, true]);
  }
  y += Math.round(head * 1.2) + 2 * gap;
  // The muscle bars: one column beside the scene, two above it on a tall window.
  const columns = lay.landscape ? 1 : 2;
  const colW = (hud.w - (columns - 1) * 2 * lay.pad) / columns;
  const barH = Math.max(5, Math.round(10 * lay.u));
  const rowH = Math.round(small * 1.2) + gap / 2 + barH + gap;
  const short = names.some((n, i) => width(keys[i] + "  " + n, small) > colW);
  const bars = [];
  const activation = game.muscleActivation;
  for (let i = 0; i < 4; i++) {
    const cx = hud.x + (i % columns) * (colW + 2 * lay.pad), ry = y + Math.floor(i / columns) * rowH;
    const name = short ? names[i].split(" ").pop() : names[i];
    labels.push([fit(keys[i] + "  " + name, small, colW), cx, ry, small, p.ink, false]);
    bars.push([cx, ry + Math.round(small * 1.2) + gap / 2, colW, barH, i, Math.min(Math.max(activation[i], 0), 1)]);
  }
  y += rowH * (4 / columns) + gap;
  // The help line(s), at the bottom of the HUD (the touch buttons say what they do themselves).
  const items = touchMode ? ["the buttons pull the muscles", "reset costs " + config.reset_cost]
    : [keys[0] + "/" + keys[1] + " shoulder", keys[2] + "/" + keys[3] + " elbow", "space reset (-" + config.reset_cost + ")",
      "tab hide arm"];
  const lines = [];
  for (const item of items) {
    if (lines.length && width(lines[lines.length - 1] + "    " + item, small) <= hud.w) lines[lines.length - 1] += "    " + item;
    else lines.push(fit(item, small, hud.w));
  }
  const lineH = Math.round(small * 1.2);
  const helpTop = hud.y + hud.h - lines.length * (lineH + gap / 2);
  lines.forEach((line, i) => {
    const ly = helpTop + i * (lineH + gap / 2);
    labels.push([line, lay.landscape ? hud.x : (w - width(line, small)) / 2, ly, small, p.faint, false]);
  });
  if (!lay.landscape) { lay.scene.y = y; lay.scene.h = Math.max(helpTop - gap - y, 10); }
  const view = viewport(lay.scene, sceneWorld());
  const key = [w, h, canvas.width, canvas.height, lay.scene.x, lay.scene.y, lay.scene.w, lay.scene.h].join(",");
  if (key !== backgroundKey) { background = drawBackground(lay, view, sx, sy); backgroundKey = key; }
  // The reach's outer circle, in CSS px of the canvas's box: the tests hold it inside the screen, clear of the buttons.
  const reach = (config.arm.l1 + config.arm.l2) * view.scale;
  canvas.workspace = { x: view.ox - reach, y: view.oy - reach, width: 2 * reach, height: 2 * reach };
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.drawImage(background, 0, 0);
  ctx.setTransform(sx, 0, 0, sy, 0, 0);
  // The scene: target, arm, hand, clipped to it.
  const s = lay.scene;
  ctx.save();
  ctx.beginPath();
  ctx.rect(s.x, s.y, s.w, s.h);
  ctx.clip();
  const now = game.steps * game.dt;
  drawTarget(view, now);
  const [q1, q2] = game.interpolatedAngles(alpha);
  const { l1, l2 } = config.arm;
  const elbow = [l1 * Math.cos(q1), l1 * Math.sin(q1)];
  const hand = [elbow[0] + l2 * Math.cos(q1 + q2), elbow[1] + l2 * Math.sin(q1 + q2)];
  if (game.armVisible) drawArm(ctx, view, q1, q2, l1, l2, activation, PALETTE);
  circle(ctx, view.ox + hand[0] * view.scale, view.oy - hand[1] * view.scale, Math.max(1, 0.02 * view.scale), p.hand);
  for (const [x, yy, t] of hits) {
    const age = now - t;
    if (age < PLUS_ONE_TIME) {
      const r = game.target.radius * view.scale;
      labels.push(["+1", view.ox + x * view.scale + r + gap, view.oy - yy * view.scale - age / PLUS_ONE_TIME * 2 * r - big / 2,
        big, p.ink, true]);
    }
  }
  ctx.restore();
  if (phase === "over") {  // the end card is HTML, over the veiled game
    ctx.fillStyle = "rgba(255,255,255,0.67)";
    ctx.fillRect(0, 0, w, h);
  }
  for (const [x, by, bw, bh, i, a] of bars) {
    roundRect(x, by, bw, bh, bh / 2, p.barBack);
    if (a > 0.002) roundRect(x, by, Math.max(bh, Math.round(bw * a)), bh, bh / 2, rgb(p.muscles[i]));
  }
  for (const [text, x, ly, size, colour, bold] of labels) {
    ctx.font = font(size, bold);
    ctx.fillStyle = colour;
    ctx.fillText(text, x, ly);
  }
  if (phase === "countdown") drawCountdown(lay);
}

function drawTarget(view, now) {
  const t = game.target, k = view.scale;
  const x = view.ox + t.x * k, y = view.oy - t.y * k, r = Math.max(1, t.radius * k);
  const newest = hits.length ? now - hits[hits.length - 1][2] : null;
  const fade = newest === null ? 1 : Math.min(Math.max(newest / FADE_IN, 0), 1);
  const colour = rgb(blend([255, 255, 255], PALETTE.target, fade));
  circle(ctx, x, y, r - Math.max(MIN_LINE, r / 3) / 2, null, colour, Math.max(MIN_LINE, r / 3));
  circle(ctx, x, y, Math.max(2, r / 4), colour);
  for (const [hx, hy, when] of hits) {
    const age = now - when;
    if (age < FLASH_TIME) {
      const rr = r * (1 + 0.8 * age / FLASH_TIME);
      circle(ctx, view.ox + hx * k, view.oy - hy * k, rr, PALETTE.flash, rgb(PALETTE.target), Math.max(2, r / 5));
    }
  }
}

function drawCountdown(lay) {
  const s = lay.scene, size = Math.max(lay.big, Math.round(s.h * 0.2));
  const number = String(Math.max(1, Math.ceil(countdownLeft)));
  const hint = touchMode ? "a tap starts" : "any key starts";
  const w = Math.max(width(number, size, true), width(hint, lay.normal)) + 6 * lay.gap;
  const h = size * 1.2 + lay.normal * 1.2 + 4 * lay.gap;
  const x = s.x + s.w / 2 - w / 2, y = s.y + s.h / 2 - h / 2;
  roundRect(x, y, w, h, Math.max(4, Math.round(12 * lay.u)), PALETTE.panel, PALETTE.edge, Math.max(MIN_LINE, Math.round(2 * lay.u)));
  ctx.textAlign = "center";
  ctx.fillStyle = PALETTE.ink;
  ctx.font = font(size, true);
  ctx.fillText(number, s.x + s.w / 2, y + 1.5 * lay.gap);
  ctx.font = font(lay.normal, false);
  ctx.fillText(hint, s.x + s.w / 2, y + 1.5 * lay.gap + size * 1.2 + lay.gap);
  ctx.textAlign = "left";
}

// ------------------------------------------------------------------ the start
async function begin() {
  showOutbox();
  requestAnimationFrame(frame);
  if (member === null) { askToJoin(""); flushOutbox().then(showAnswers); return; }
  const answer = await join(member.code, member.name, member.token, null, member.class);
  if (answer.status === 200 && answer.data && answer.data.ok) {
    joined(member.code, answer.data);
  } else if (answer.status === 0 || answer.status === 503 || answer.status === 429) {
    // Not reached (or busy): the class's seed is known from before, so the game is played, kept, and
    // handed in when the class answers again.
    joinForm.hidden = true;
    newGame();
    statusLine.textContent = answer.status === 0 ? "the class cannot be reached: your games are kept and handed in later"
      : "the class is busy: your games are kept and handed in later";
    scheduleRetry();
  } else {
    askToJoin(refusal(answer));
    if (answer.status === ANOTHER_CLASS) {  // last week's code is no use here: today's is typed afresh
      document.getElementById("code").value = "";
      document.getElementById("code").focus();
    }
  }
}

begin();
