// What the browser game keeps on this machine (localStorage): the name playing now, every name this browser
// joined a class under with its token, and the games the class has not taken yet. The store is another page's
// to write too (a damaged one, a planted one, last week's code): every read is checked field by field, and what
// fails is left out, never thrown, so a bad store can cost a kept game at worst, never the next game.

// The name playing now and its class: a reload, or the next game, plays under the same name.
const MEMBER = "armgame.play.member";
// Each game finished but not yet taken by the class, under a key of its own (GAME + its id): two tabs finishing at
// once each write their own key, and a game taken is one key removed, so no tab writes back a list of games another
// tab has just changed (a shared list lost a game so: issue 54). Handed in at the next chance (the next page load,
// the next game's end, a timer while the page is open).
const GAME = "armgame.play.game.";
// Before, every kept game was in one list under this key: moved to keys of their own when the outbox is read.
const OUTBOX = "armgame.play.outbox";
// Every name this browser joined a class under, each with its token, by the class's code, the newest first:
// {CODE: [{name, token, at}]}. A token is what proves a name is this browser's, and the class gives it once,
// so "not Ann?" and a join under another name never cost Ann hers. At most MAX_NAMES a class and MAX_CLASSES
// classes, those joined longest ago dropped (as memberships.json keeps them, classroom/memberships.py).
const NAMES = "armgame.play.names";
const MAX_NAMES = 8, MAX_CLASSES = 40;
// A kept game's replay: far larger than any 60 s game's (about 20 KB), far smaller than a browser's store.
const MAX_GAME_BYTES = 1 << 20, MAX_KEPT_GAMES = 50;
const CODE = /^[A-Z]{4}$/, TOKEN = /^[A-Za-z0-9_-]{1,200}$/, ID = /^[a-z0-9]{1,40}$/, CLASS = /^[0-9a-f]{1,64}$/;
// A start ticket (the class's answer to POST /api/start): a game handed in with it may count in a round.
const TICKET = /^[A-Za-z0-9_-]{1,64}$/;

function load(key, fallback) {
  try { return JSON.parse(localStorage.getItem(key)) ?? fallback; } catch { return fallback; }
}
function save(key, value) {
  try { localStorage.setItem(key, JSON.stringify(value)); return true; } catch { return false; }
}

// ------------------------------------------------------------------ the name playing now
// {code, name, token, seed, duration, class}, or null (class: the class's id, null when joined before it said it). The seed is a number or a decimal string (a seed past 2^53).
export function loadMember() {
  const m = load(MEMBER, null);
  if (m === null || typeof m !== "object" || typeof m.code !== "string" || !CODE.test(m.code.toUpperCase()) ||
      typeof m.name !== "string" || typeof m.token !== "string" || !TOKEN.test(m.token) ||
      !((Number.isFinite(m.seed) && m.seed >= 0) || (typeof m.seed === "string" && /^[0-9]{1,19}$/.test(m.seed)))) {
    return null;
  }
  if (tokenFor(m.code, m.name) === null) keepName(m.code, m.name, m.token);  // kept before every name was
  // A class from before it said its clock, or a damaged one: the standard game's (the class checks the game).
  const duration = Number.isFinite(m.duration) && m.duration > 0 && m.duration <= 3600 ? m.duration : 60;
  const cls = typeof m.class === "string" && CLASS.test(m.class) ? m.class : null;
  return { code: m.code, name: m.name, token: m.token, seed: m.seed, duration, class: cls };
}

export function saveMember(member) {
  save(MEMBER, member);
  keepName(member.code, member.name, member.token);
}

export function forgetMember() {
  try { localStorage.removeItem(MEMBER); } catch { /* nothing was kept */ }
}

// ------------------------------------------------------------------ every name joined
// Names as the class tells them apart, near enough (the class decides: a token sent for another name is unused).
function nameKey(name) { return name.normalize("NFKC").toLowerCase().split(/\s+/).filter(Boolean).join(" "); }

function knownNames() {
  const kept = load(NAMES, {});
  const out = {};
  if (kept === null || typeof kept !== "object" || Array.isArray(kept)) return out;
  for (const [code, list] of Object.entries(kept).slice(0, 2 * MAX_CLASSES)) {
    if (!CODE.test(code) || !Array.isArray(list)) continue;
    const names = list.slice(0, MAX_NAMES).filter((n) => n !== null && typeof n === "object" &&
      typeof n.name === "string" && [...n.name].length <= 40 && typeof n.token === "string" && TOKEN.test(n.token) &&
      Number.isFinite(n.at));
    if (names.length > 0) out[code] = names;
  }
  return out;
}

export function tokenFor(code, name) {
  const key = nameKey(name);
  const found = (knownNames()[code.toUpperCase()] || []).find((n) => nameKey(n.name) === key);
  return found ? found.token : null;
}

export function keepName(code, name, token) {
  if (typeof token !== "string" || !TOKEN.test(token)) return;
  const all = knownNames();
  code = code.toUpperCase();
  const others = (all[code] || []).filter((n) => nameKey(n.name) !== nameKey(name));
  all[code] = [{ name, token, at: Date.now() }, ...others].slice(0, MAX_NAMES);
  const codes = Object.keys(all).sort((a, b) => all[b][0].at - all[a][0].at).slice(0, MAX_CLASSES);
  save(NAMES, Object.fromEntries(codes.map((c) => [c, all[c]])));
}

// ------------------------------------------------------------------ the games not yet taken
// A kept game: {id, code, token, class, body, at, start}. ``class`` is what the class said of itself at the join (the
// server's class id; null for a game kept before classes said it): a game is handed in only to its own class.
// Games the browser would not store (private browsing, a full store): kept here while the page is open.
const unstored = new Map();

function keptGame(g) {
  return g !== null && typeof g === "object" && !Array.isArray(g) && typeof g.id === "string" && ID.test(g.id) &&
    typeof g.code === "string" && CODE.test(g.code.toUpperCase()) && typeof g.token === "string" &&
    TOKEN.test(g.token) && typeof g.body === "string" && g.body.length <= MAX_GAME_BYTES &&
    (g.class === undefined || g.class === null || (typeof g.class === "string" && CLASS.test(g.class)));
}

function asGame(g, at) {
  return { id: g.id, code: g.code, token: g.token, class: g.class ?? null, body: g.body,
    at: Number.isFinite(g.at) ? g.at : at, start: typeof g.start === "string" && TICKET.test(g.start) ? g.start : null };
}

function store(game) {
  try { localStorage.setItem(GAME + game.id, JSON.stringify(game)); return true; } catch { return false; }
}

// The old list's games moved to keys of their own (the same ids: two tabs moving them at once write the same keys),
// and the list removed once every game in it is stored; what is not a game ({}, 5, [null]) is left out.
function moveOldOutbox() {
  let raw = null;
  try { raw = localStorage.getItem(OUTBOX); } catch { return; }
  if (raw === null) return;
  let box = null;
  try { box = JSON.parse(raw); } catch { box = null; }
  let stored = true;
  if (Array.isArray(box)) {
    box.slice(0, MAX_KEPT_GAMES).filter(keptGame).forEach((g, i) => {
      const game = asGame(g, i);  // older than any game kept since: handed in first, as before
      if (!store(game)) { unstored.set(game.id, game); stored = false; }
    });
  }
  if (stored) { try { localStorage.removeItem(OUTBOX); } catch { /* read again next time */ } }
}

// The kept games, oldest first. A key of the outbox's that is not a game (another page's, a damaged store) is left
// out, never thrown: it can cost that game at worst, never the next one.
export function outbox() {
  moveOldOutbox();
  const games = new Map(unstored);
  let keys = [];
  try {
    for (let i = 0; i < localStorage.length; i++) {
      const key = localStorage.key(i);
      if (typeof key === "string" && key.startsWith(GAME)) keys.push(key);
    }
  } catch { keys = []; }
  for (const key of keys) {
    let raw = null;
    try { raw = localStorage.getItem(key); } catch { raw = null; }
    if (typeof raw !== "string" || raw.length > 2 * MAX_GAME_BYTES + 4096) continue;  // not parsed: no game is
    let g = null;
    try { g = JSON.parse(raw); } catch { g = null; }
    if (keptGame(g) && key === GAME + g.id) games.set(g.id, asGame(g, 0));
  }
  return [...games.values()].sort((a, b) => a.at - b.at || (a.id < b.id ? -1 : a.id > b.id ? 1 : 0));
}

// Kept before it is sent; false when the browser would not store it (it is kept for as long as the page is open).
// Past MAX_KEPT_GAMES the oldest go.
export function keepGame(game) {
  const kept = { ...asGame(game, 0), at: Date.now() };
  const stored = store(kept);
  if (!stored) unstored.set(kept.id, kept);
  const box = outbox();
  for (const old of box.slice(0, Math.max(box.length - MAX_KEPT_GAMES, 0))) dropGame(old.id);
  return stored;
}

export function dropGame(id) {
  unstored.delete(id);
  try { localStorage.removeItem(GAME + id); } catch { /* the browser stores nothing: it kept nothing */ }
}
