// The class's API and the outbox, for the browser game (/play): the join, the class's state, the start ticket, the
// lab's plan, and every game kept on this machine (kept.js) handed in to its own class. No page here: what the
// student sees of it is play.js's (onChange, onAnswers). fetch, the store (kept.js's functions) and the timer are
// handed in, so tests/play_logic.test.mjs runs all of it in Node with a fake class and a fake localStorage.
import * as kept from "./kept.js";

// A hand-in the class did not answer (busy, unreachable) is tried again this long after.
export const RETRY_MS = 5000;
// The class's answer to a join or a game that names another class (app.py's OTHER_CLASS): the game stays kept.
export const ANOTHER_CLASS = 410;
// A start ticket (the class's answer to POST /api/start), as kept.js keeps it.
const TICKET = /^[A-Za-z0-9_-]{1,64}$/;

// A join or a hand-in the class took.
export function accepted(answer) { return answer.status === 200 && Boolean(answer.data && answer.data.ok); }

export function refusal(answer) {
  return answer.data && typeof answer.data.error === "string" ? answer.data.error : "the class refused (" + answer.status + ")";
}

// A refusal that will be the same every time (a game the class does not take): dropped from the outbox.
export function final(status) {
  return status >= 400 && status < 500 && status !== 408 && status !== 429 && status !== ANOTHER_CLASS;
}

// Not reached, or too busy to answer now: asked again later.
function busy(status) { return status === 0 || status === 408 || status === 429 || status >= 500; }

export function classOf(data) {
  return typeof data.class === "string" && /^[0-9a-f]{1,64}$/.test(data.class) ? data.class : null;
}

export function startHeader(t) { return typeof t === "string" && TICKET.test(t) ? { "X-Armgame-Start": t } : {}; }

// What the student is told of a game's (or a lab run's) hand-in: {line, kind, data}; kind "kept" when it waits.
export function handInLine(answer, what) {
  if (accepted(answer)) return { line: answer.data.message, kind: "", data: answer.data };
  if (answer.status === 0) return { line: `the class could not be reached: your ${what} is kept and will be handed in`, kind: "kept" };
  if (answer.status === ANOTHER_CLASS) {
    return { line: `kept, not handed in: the class here is not the one your ${what} was played for`, kind: "kept" };
  }
  if (answer.status === 503 || answer.status === 429 || answer.status === 408 || answer.status >= 500) {
    return { line: `the class is busy, your ${what} is kept and will be handed in`, kind: "kept" };
  }
  return { line: "not handed in: " + refusal(answer), kind: "kept" };
}

export class ClassLink {
  // ``onChange()``: the outbox or the class here changed (play.js shows the status line again);
  // ``onAnswers(results)``: kept games handed in by a retry, [{id, answer}], oldest first.
  constructor({ fetch = (...a) => globalThis.fetch(...a), store = kept, timer = (...a) => globalThis.setTimeout(...a),
    retryMs = RETRY_MS, onChange = () => {}, onAnswers = () => {} } = {}) {
    this.fetch = fetch;
    this.store = store;
    this.timer = timer;
    this.retryMs = retryMs;
    this.onChange = onChange;
    this.onAnswers = onAnswers;
    // {code, name, token, seed, duration, class}: the name playing now, or null.
    this.member = store.loadMember();
    // The class this page's last join reached: {class: its id, code: the code it took}. Only its games are handed
    // in, with that code; null until a join answers, and nothing kept is sent before (a game from another class
    // never is).
    this.here = null;
    this.flushing = null;
    this.retrying = false;
  }

  // The class's API: same origin only, no cookies. {status, data}; status 0 when nothing answered.
  async post(path, body, headers = {}) {
    let response;
    try {
      response = await this.fetch(path, { method: "POST", body, credentials: "omit",
        headers: { "Content-Type": "application/json", ...headers } });
    } catch {
      return { status: 0, data: null };  // not reached: no answer at all
    }
    let data = null;
    try { data = await response.json(); } catch { data = null; }
    return { status: response.status, data };
  }

  // ``state``: the class's state asked before a new name joins. With the teacher's switch on, the join says it is
  // for the lab (a closed class takes a new name for it). A name this browser has is known to the class: it rejoins
  // as it always did, and the lab's own join follows if the switch is on (play.js's startLab).
  join(code, name, token, state, cls = null) {
    const body = { code, name };
    if (token) body.token = token;
    if (cls) body.class = cls;  // a name kept from another class at this address is refused, and no guess counted
    if (state && state.lab) body.for = "lab";
    return this.post("/api/join", JSON.stringify(body));
  }

  // A name the student typed: its token if this browser joined under it before (the class knows it), else none.
  tokenFor(code, name) { return this.store.tokenFor(code, name); }

  // The class's answer to a join taken: the name playing now, kept for the next page load.
  joined(code, data) {
    // The class's game: its seed and its clock (a rehearsal's games are 15 s; a class that does not say: 60 s).
    this.member = { code, name: data.name, token: data.token, seed: data.seed, duration: data.duration ?? 60,
      class: classOf(data) };
    this.here = { class: this.member.class, code };
    this.store.saveMember(this.member);
  }

  // "not Ann?": another name plays next; Ann's token stays (kept.js's names), for when she joins here again.
  forget() {
    this.member = null;
    this.store.forgetMember();
  }

  // What the class says of itself now (public: the projector's standings): closed, and whether the teacher has
  // every browser run the lab. Not reached: {closed: false, lab: false}, and the game is played, kept, handed in
  // later.
  async classState() {
    try {
      const r = await this.fetch("/api/standings", { cache: "no-store" });
      const s = r.ok ? await r.json() : {};
      return { closed: s.closed === true, lab: typeof s.browser_lab === "string" && s.browser_lab !== "" };
    } catch {
      return { closed: false, lab: false };
    }
  }

  // The lab's join says it is for the lab (a closed class takes it; in a classroom experiment it assigns the
  // student's condition), then the plan of the student's run (/api/labplan, asked as the student: the plan of their
  // condition). {answer: the join's, plan: null when either failed}.
  async labPlan() {
    const m = this.member;
    const answer = await this.post("/api/join", JSON.stringify({ code: m.code, name: m.name, token: m.token,
      for: "lab", ...(m.class ? { class: m.class } : {}) }));
    let plan = null;
    if (accepted(answer)) {
      this.here = { class: classOf(answer.data), code: m.code };
      try {
        const r = await this.fetch("/api/labplan", { cache: "no-store", credentials: "omit",
          headers: { Authorization: "Bearer " + m.token, "X-Armgame-Code": m.code } });
        plan = r.ok ? await r.json() : null;
      } catch { plan = null; }
    }
    return { answer, plan };
  }

  // The class's start ticket for the game beginning now: its hand-in sends it back, and a round counts only games
  // begun during it. Never waited for by the game; no ticket (an older class, no answer) is a game kept on the
  // board but not in a round.
  async startTicket() {
    const m = this.member;
    const answer = await this.post("/api/start", "{}", { Authorization: "Bearer " + m.token, "X-Armgame-Code": m.code });
    const t = answer.status === 200 && answer.data ? answer.data.ticket : null;
    return typeof t === "string" && TICKET.test(t) ? t : null;
  }

  // A kept game is the class's here by the class's id; one kept before classes said it, by its code.
  belongsHere(game) {
    if (this.here === null) return false;
    if (game.class !== null && this.here.class !== null) return game.class === this.here.class;
    return game.code.toUpperCase() === this.here.code.toUpperCase();
  }

  toHandIn() { return this.store.outbox().filter((g) => this.belongsHere(g)); }

  // A kept game sent with the code the class here took at the join (its own class's, whatever code it was kept
  // with).
  send(game) {
    const headers = { Authorization: "Bearer " + game.token, "X-Armgame-Code": this.here.code };
    if (game.class !== null) headers["X-Armgame-Class"] = game.class;
    return this.post("/api/handin", game.body, { ...headers, ...startHeader(game.start) });
  }

  // Every kept game handed in, oldest first; returns the answers ({id, answer}) to show.
  flush() {
    if (this.flushing === null) this.flushing = this.doFlush().finally(() => { this.flushing = null; });
    return this.flushing;
  }

  async doFlush() {
    const results = [];
    for (;;) {
      const box = this.toHandIn();
      if (box.length === 0) break;
      const item = box[0];
      const answer = await this.send(item);
      results.push({ id: item.id, answer });
      if (answer.status === ANOTHER_CLASS) { this.here = null; break; }  // another class is here now: it is sent nothing
      if (!accepted(answer) && !final(answer.status)) {
        this.scheduleRetry();
        break;  // busy or unreachable: the rest wait with it
      }
      this.store.dropGame(item.id);
    }
    this.onChange();
    return results;
  }

  scheduleRetry() {
    if (this.retrying) return;
    this.retrying = true;
    this.timer(async () => {
      this.retrying = false;
      if (this.here === null) await this.rejoin();
      if (this.here !== null) this.flush().then(this.onAnswers);
    }, this.retryMs);
  }

  // The name playing now joined again, to learn which class is here (the page played on while the class was away).
  // It names its class: another class at this address refuses it without counting a guess. Returns the answer.
  async rejoin() {
    const m = this.member;
    if (m === null) return { status: 0, data: null };
    const answer = await this.join(m.code, m.name, m.token, null, m.class);
    if (accepted(answer)) {
      this.here = { class: classOf(answer.data), code: m.code };
      if (m.class === null && this.here.class !== null) { m.class = this.here.class; this.store.saveMember(m); }
    } else if (busy(answer.status)) {
      this.scheduleRetry();
    }
    this.onChange();
    return answer;
  }

  // A game's or a lab run's replay kept first, then sent: a page closed while the answer is on its way hands it in
  // next time. Returns the line to show ({line, kind, data}); ``showing`` is told the line while it is on its way.
  async handIn(body, what, showing, start = null) {
    const m = this.member;
    const id = Date.now().toString(36) + Math.random().toString(36).slice(2, 8);
    const game = { id, code: m.code, token: m.token, class: m.class, body, ...(start ? { start } : {}) };
    const stored = this.store.keepGame(game);
    if (!stored && showing) showing("handing in (this browser keeps nothing: stay on the page)…");
    // This game first, by itself: another tab's hand-in may send it too, and the class takes a game once.
    const answer = this.here === null ? await this.rejoin() : null;
    if (this.here === null) return handInLine(answer, what);
    if (!this.belongsHere(game)) return handInLine({ status: ANOTHER_CLASS, data: null }, what);
    const mine = await this.send(game);
    if (mine.status === ANOTHER_CLASS) this.here = null;
    else if (accepted(mine) || final(mine.status)) this.store.dropGame(id);
    else this.scheduleRetry();
    this.onAnswers(this.here !== null && mine.status === 200 ? await this.flush() : []);
    this.onChange();
    return handInLine(mine, what);
  }
}
