// The class's game in a browser tab (/play): the controller. It holds the page's phases (join, countdown, playing,
// over, closed; lab-loading, lab, lab-over for the teacher's switch) and the input (keys and fingers), and ties the
// three parts together, as PhET's Screen(createModel, createView) does: the model (model.js: engine.js's game, bit
// for bit the Python's, on the page's clock), the view (view.js: the canvas), and the class (outbox.js: the API,
// and the games kept until the class takes them). Everything a student or the server wrote is set as text
// (textContent, fillText), never as HTML.
import { PlayedGame } from "./model.js";
import { ANOTHER_CLASS, ClassLink, RETRY_MS, accepted, handInLine, refusal } from "./outbox.js";
import { Hud, View } from "./view.js";

// ------------------------------------------------------------------ the page's parts
const canvas = document.getElementById("game");
const touch = document.getElementById("touch");
const joinForm = document.getElementById("join");
const endCard = document.getElementById("end");
const statusLine = document.getElementById("status");
// The last frames' times (ms of script and drawing each): benchmarks/browser_page.py and the tests read them.
canvas.frameTimes = [];

const view = new View(canvas);
const hud = new Hud(document);
const link = new ClassLink({ onChange: () => showOutbox(), onAnswers: (results) => showAnswers(results) });
let phase = "join";  // join, countdown, playing, over, closed; lab-loading, lab, lab-over (the teacher's switch)
let played = null;  // the game on screen (model.js), or null
let lab = null;  // the lab's screen (labpage.js) while the class runs the lab in every browser
let names = [], keys = [];  // the muscles' names and keys, the game's or the lab's
let touchMode = false;
let last = null;  // the last frame's time (ms)
const held = new Set();  // keys this page has pressed in the game and not yet released
const fingers = new Map();  // pointer id -> the key its button holds

// ------------------------------------------------------------------ the status line: who plays, what is kept
function showOutbox() {
  const member = link.member, box = link.store.outbox();
  const mine = link.here === null ? box : box.filter((g) => link.belongsHere(g));
  const elsewhere = box.filter((g) => !mine.includes(g));
  const between = phase !== "playing" && phase !== "lab" && phase !== "lab-loading";
  statusLine.replaceChildren();
  if (phase === "closed") statusLine.append(CLOSED + " · ");
  if (member) statusLine.append((lab !== null ? "in the lab as " : "playing as ") + member.name + " ");
  if (mine.length > 0) statusLine.append("· " + games(mine.length) + (link.here === null ? " kept " : " kept, to hand in "));
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
    for (const game of elsewhere) link.store.dropGame(game.id);
    showOutbox();
  });
  return button;
}

// ------------------------------------------------------------------ joining
function askToJoin(error) {
  const member = link.member;
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

// "not Ann?": another name plays next; Ann's token stays (kept.js's names), for when she joins on this browser again.
function forget() {
  link.forget();
  askToJoin("");
}

joinForm.addEventListener("submit", async (event) => {
  event.preventDefault();
  const code = document.getElementById("code").value.trim();
  const name = document.getElementById("name").value.trim();
  const button = document.getElementById("join-button");
  button.disabled = true;
  // A name this browser joined under before keeps its token (the class knows it); a new one starts afresh.
  const state = await link.classState();
  const answer = await link.join(code, name, link.tokenFor(code, name), state);
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
  link.joined(code, data);
  joinForm.hidden = true;
  statusLine.textContent = "";
  if (state !== null) nextRun(state);
  else if (data.closed) nextRun();
  else {
    newGame();
    link.classState().then((s) => { if (s.lab && phase === "countdown") startLab(); });
  }
  link.flush().then(showAnswers);
}

// A closed class takes no games: none is started that could not be handed in. The page asks again every few
// seconds and starts one once the teacher opens the class.
let closedTimer = null;
const CLOSED = "the class is closed: it takes no more games (the game starts if the teacher opens it)";

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
  const state = known ?? await link.classState();
  if (state.lab) { startLab(); return; }
  if (state.closed) { waitWhileClosed(); return; }
  newGame();
}

async function playAgain() { await nextRun(); }

// The teacher's switch, looked for every few seconds while no game is under way: a student at the countdown goes to
// the lab at once; one looking at their score is told, and "Play again" starts it. A game under way is finished.
setInterval(async () => {
  if (link.member === null || (phase !== "countdown" && phase !== "over")) return;
  const state = await link.classState();
  if (!state.lab) return;
  if (phase === "countdown") startLab();
  else if (phase === "over") statusLine.textContent = "the teacher has started the lab: Play again starts it";
}, 5000);

// ------------------------------------------------------------------ the lab (the teacher's switch)
let labTimer = null;
async function startLab() {
  if (phase === "lab-loading" || phase === "lab") return;
  phase = "lab-loading";
  clearTimeout(closedTimer);
  clearTimeout(labTimer);
  endCard.hidden = true;
  document.getElementById("lab-end").hidden = true;
  statusLine.textContent = "the teacher has started the lab: loading it…";
  const { answer, plan } = await link.labPlan();
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
  played = null;
  lab = new LabScreen(plan, canvas, link.member.name, touchMode);
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
  const answer = await link.handIn(lab.replayJSON(), "run");
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
  played = new PlayedGame(link.member);
  names = played.names;
  keys = played.keys;
  labelButtons("reset", "-" + played.config.reset_cost);
  phase = "countdown";
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
  played.game.keyEvent(key, "down");
}

function lift(key) {
  if (phase === "lab" || phase === "lab-over") { lab.lift(key); return; }
  if (!held.delete(key)) return;
  if (phase === "playing") played.game.keyEvent(key, "up");
}

// Every held key let go, into the game as key-ups (the tab lost focus; a finger left the screen unseen).
function releaseAll() {
  if (lab !== null) lab.releaseAll();
  for (const key of [...held]) lift(key);
  fingers.clear();
  touch.querySelectorAll("button.held").forEach((b) => b.classList.remove("held"));
}

// The class's start ticket for the game beginning now (outbox.js's startTicket): asked as the game starts, never
// waited for by it; the hand-in waits for it.
let ticket = null;
function start() {
  phase = "playing";
  ticket = link.startTicket();
  showOutbox();
}

async function finish() {
  const game = played.game;
  phase = "over";
  held.clear();
  fingers.clear();
  showEnd("handing in…", "");
  const body = game.replayJSON(link.member.name);  // any seed's digits exact (a seed past 2^53 is a BigInt)
  const given = ticket === null ? null : await ticket;
  ticket = null;
  const answer = await link.handIn(body, "game", (line) => showEnd(line, ""), given);
  if (answer.data) showEnd(answer.line, answer.kind, answer.data); else showEnd(answer.line, answer.kind);
}

function showHandIn(answer) {
  const said = handInLine(answer, "game");
  if (said.data) showEnd(said.line, said.kind, said.data); else showEnd(said.line, said.kind);
}

// Games from before (the outbox) handed in now: one line for the student, under whatever is on screen.
function showAnswers(results) {
  const accepts = results.filter((r) => accepted(r.answer));
  if (accepts.length > 0) {
    const newest = accepts[accepts.length - 1].answer.data;
    statusLine.textContent = (accepts.length === 1 ? "a kept game was " : accepts.length + " kept games were ") +
      newest.message;
  }
  if (phase === "lab-over" && link.toHandIn().length === 0 && accepts.length > 0 &&
      document.getElementById("lab-answer").className === "kept") {
    lab.answer(accepts[accepts.length - 1].answer.data.message, "");
  }
  if (phase === "over" && endCard.dataset.kept === "kept" && link.toHandIn().length === 0 && accepts.length > 0) {
    showHandIn(accepts[accepts.length - 1].answer);
  }
}

function showEnd(line, kind, data) {
  const game = played.game;
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
      for (const [text, column] of [[rank + ".", "rank"], [name, "name"], [String(score), "score"]]) {
        const cell = row.insertCell();
        cell.className = column;
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
Object.defineProperty(canvas, "debug", { get: () => (lab !== null ? { ...lab.debug, page: phase, box: [view.box.w, view.box.h] }
  : { phase, held: [...held], activation: played ? played.game.muscleActivation : [], resets: played ? played.game.resets : 0,
    box: [view.box.w, view.box.h] }) });
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
    if (played.countDown(elapsed)) start();
  } else if (phase === "playing") {
    if (played.advance(elapsed)) finish();
  }
  paint();
  const times = canvas.frameTimes;
  times.push(performance.now() - began);
  if (times.length > 600) times.splice(0, times.length - 600);
}

// The canvas's box (CSS px), as play.css's grid sizes its cell; its bitmap follows it in device pixels.
const resized = new ResizeObserver(([entry]) => {
  view.resized(entry, window.devicePixelRatio || 1);
  if (!paint()) view.blank();  // before the page is painted: never blank
});
// Its device pixels watched too, where the browser can (a window moved to a screen of another density); Safari
// watches the CSS box only.
try { resized.observe(canvas, { box: "device-pixel-content-box" }); } catch { resized.observe(canvas); }

// The lab's scene or the game's, whichever is on: false when neither is. The HUD is shown with the game's alone.
function paint() {
  const box = view.box;
  // "not me?" forgets the name while the last game is on screen
  const playing = lab === null && played !== null && link.member !== null;
  hud.show(playing ? hudState() : null);
  if (lab !== null && link.member !== null) {
    lab.draw(box.w, box.h, canvas.width / Math.max(box.w, 1), canvas.height / Math.max(box.h, 1));
    return true;
  }
  if (playing) { view.draw(sceneState()); return true; }
  return false;
}

// What the HUD says of the game now (view.js's hudWords).
function hudState() {
  const member = link.member, game = played.game;
  return { seed: member.seed, name: member.name, score: game.score, timeLeft: game.timeLeft, keys, names,
    activation: game.muscleActivation, touchMode, resetCost: played.config.reset_cost, phase,
    countdownLeft: played.countdownLeft };
}

// What view.js draws of the scene now: its moving parts.
function sceneState() {
  const game = played.game;
  return { arm: played.config.arm, phase, now: played.now, target: game.target,
    angles: game.interpolatedAngles(played.alpha), armVisible: game.armVisible, activation: game.muscleActivation,
    hits: played.hits };
}

// ------------------------------------------------------------------ the start
async function begin() {
  showOutbox();
  requestAnimationFrame(frame);
  const member = link.member;
  if (member === null) { askToJoin(""); link.flush().then(showAnswers); return; }
  const answer = await link.join(member.code, member.name, member.token, null, member.class);
  if (accepted(answer)) {
    joined(member.code, answer.data);
  } else if (answer.status === 0 || answer.status === 503 || answer.status === 429) {
    // Not reached (or busy): the class's seed is known from before, so the game is played, kept, and
    // handed in when the class answers again.
    joinForm.hidden = true;
    newGame();
    statusLine.textContent = answer.status === 0 ? "the class cannot be reached: your games are kept and handed in later"
      : "the class is busy: your games are kept and handed in later";
    link.scheduleRetry();
  } else {
    askToJoin(refusal(answer));
    if (answer.status === ANOTHER_CLASS) {  // last week's code is no use here: today's is typed afresh
      document.getElementById("code").value = "";
      document.getElementById("code").focus();
    }
  }
}

begin();
