// What the browser game keeps on this machine (localStorage): the name playing now, every name this browser
// joined a class under with its token, and the games the class has not taken yet. The store is another page's
// to write too (a damaged one, a planted one, last week's code): every read is checked field by field, and what
// fails is left out, never thrown, so a bad store can cost a kept game at worst, never the next game.

// The name playing now and its class: a reload, or the next game, plays under the same name.
const MEMBER = "armgame.play.member";
// Games finished but not yet taken by the class, oldest first: handed in at the next chance (the next page load,
// the next game's end, a timer while the page is open).
const OUTBOX = "armgame.play.outbox";
// Every name this browser joined a class under, each with its token, by the class's code, the newest first:
// {CODE: [{name, token, at}]}. A token is what proves a name is this browser's, and the class gives it once,
// so "not Ann?" and a join under another name never cost Ann hers. At most MAX_NAMES a class and MAX_CLASSES
// classes, those joined longest ago dropped (as memberships.json keeps them, classroom/memberships.py).
const NAMES = "armgame.play.names";
const MAX_NAMES = 8, MAX_CLASSES = 40;
// A kept game's replay: far larger than any 60 s game's (about 20 KB), far smaller than a browser's store.
const MAX_GAME_BYTES = 1 << 20, MAX_KEPT_GAMES = 50;
const CODE = /^[A-Z]{4}$/, TOKEN = /^[A-Za-z0-9_-]{1,200}$/, ID = /^[a-z0-9]{1,40}$/;

function load(key, fallback) {
  try { return JSON.parse(localStorage.getItem(key)) ?? fallback; } catch { return fallback; }
}
function save(key, value) {
  try { localStorage.setItem(key, JSON.stringify(value)); return true; } catch { return false; }
}

// ------------------------------------------------------------------ the name playing now
// {code, name, token, seed, duration}, or null. The seed is a number or a decimal string (a seed past 2^53).
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
  return { code: m.code, name: m.name, token: m.token, seed: m.seed, duration };
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
// A browser that refuses to store (private browsing, a full store) keeps its games here while the page is open.
let unstored = null;

function keptGame(g) {
  return g !== null && typeof g === "object" && typeof g.id === "string" && ID.test(g.id) &&
    typeof g.code === "string" && CODE.test(g.code.toUpperCase()) && typeof g.token === "string" &&
    TOKEN.test(g.token) && typeof g.body === "string" && g.body.length <= MAX_GAME_BYTES;
}

// The kept games, oldest first: a store that is not a list of games ({}, 5, [null]) reads as the games in it.
export function outbox() {
  if (unstored !== null) return unstored.slice();
  const box = load(OUTBOX, []);
  return Array.isArray(box) ? box.slice(0, MAX_KEPT_GAMES).filter(keptGame) : [];
}

// Kept before it is sent; false when the browser would not store it (it is kept for as long as the page is open).
export function keepGame(game) {
  const box = [...outbox(), game].slice(-MAX_KEPT_GAMES);
  if (unstored === null && save(OUTBOX, box)) return true;
  unstored = box;
  return false;
}

export function dropGame(id) {
  const box = outbox().filter((g) => g.id !== id);
  if (unstored !== null) unstored = box; else save(OUTBOX, box);
}
