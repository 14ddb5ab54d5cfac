// The projector's standings: filled from the event stream, every name set as text, never as HTML.
"use strict";

let lastArrival = null;
let newsTimer = null;

function cell(row, text, kind) {
  const td = document.createElement("td");
  td.className = kind;
  td.textContent = text;
  row.appendChild(td);
}

function gamesText(n) { return n === 1 ? "1 game" : n + " games"; }

// Seconds each page of students stays up when a class does not fit the projector at once.
const PAGE_SECONDS = 8;
// The smallest text the students' rows take (px), and a column's narrowest width (in that text's ems): the rank,
// the score and the count of games (about 10 em) and room for a name.
const MIN_TEXT = 19;
const COLUMN_EMS = 17;
let page = 0;
let pageTimer = null;

function table(rows, programs, fresh, withGames) {
  const t = document.createElement("table");
  for (const r of rows) {
    const tr = document.createElement("tr");
    tr.dataset.name = r.name;
    if (fresh !== null && r.name === fresh) tr.className = "fresh";
    cell(tr, String(r.rank), "rank");
    cell(tr, r.name, "name");
    if (programs) {  // which program, under its name
      const driver = document.createElement("span");
      driver.className = "driver";
      driver.textContent = r.driver || "";
      tr.lastChild.appendChild(driver);
    }
    cell(tr, String(r.score), "score");
    if (withGames) cell(tr, gamesText(r.games), "games");
    t.appendChild(tr);
  }
  return t;
}

function empty(container, programs) {
  const div = document.createElement("div");
  div.className = "empty";
  div.textContent = programs ? "none yet" : "no games yet: play, and yours appears here";
  container.appendChild(div);
}

// The programs: as many as fit, the rest summed up in one line (they are not the lesson).
function fillPrograms(container, rows, fresh) {
  container.replaceChildren();
  if (rows.length === 0) { empty(container, true); return; }
  const t = table(rows, true, fresh, false);
  container.appendChild(t);
  let hidden = 0;
  while (t.rows.length > 1 && container.scrollHeight > container.clientHeight + 1) {
    t.deleteRow(-1);
    hidden += 1;
  }
  if (hidden > 0) {
    t.deleteRow(-1);
    const more = document.createElement("div");
    more.className = "more";
    more.textContent = "and " + (hidden + 1) + " more";
    container.appendChild(more);
  }
}

// Every student's name on the projector: in as many columns as the width allows (a column never narrower
// than a long name at the page's size), and where even those do not hold the class, in pages that turn by
// themselves every PAGE_SECONDS (the page that holds a new arrival first). Never scrolled, never cut.
function fillStudents(container, rows, fresh) {
  container.replaceChildren();
  container.style.removeProperty("--columns");
  delete container.dataset.pages;
  if (rows.length === 0) { empty(container, false); return; }
  // The largest text (down to the 19 px a back row reads) at which the whole class fits in the columns the
  // width allows; pages only where even 19 px does not hold it.
  container.style.fontSize = "";
  const base = parseFloat(getComputedStyle(container).fontSize);
  let perColumn = 1, columns = 1;
  for (let size = base; ; size = Math.max(MIN_TEXT, size - 1)) {
    container.style.fontSize = size + "px";
    const probe = table(rows.slice(0, 1), false, null, true);
    container.appendChild(probe);
    const rowHeight = probe.rows[0].getBoundingClientRect().height;
    container.replaceChildren();
    perColumn = Math.max(1, Math.floor(container.clientHeight / rowHeight));
    const widest = Math.max(1, Math.floor(container.clientWidth / (COLUMN_EMS * size)));
    columns = Math.min(widest, Math.max(1, Math.ceil(rows.length / perColumn)));
    if (columns * perColumn >= rows.length || size <= MIN_TEXT) break;
  }
  const pages = Math.ceil(rows.length / (perColumn * columns));
  if (pages === 1) perColumn = Math.ceil(rows.length / columns);  // columns of even length
  const perPage = perColumn * columns;
  if (fresh !== null) {
    const at = rows.findIndex((r) => r.name === fresh);
    if (at >= 0) page = Math.floor(at / perPage);
  }
  page = page % pages;
  const shown = rows.slice(page * perPage, (page + 1) * perPage);
  const grid = document.createElement("div");
  grid.className = "columns";
  grid.style.setProperty("--columns", String(columns));
  for (let c = 0; c < columns; c++) {
    const part = shown.slice(c * perColumn, (c + 1) * perColumn);
    if (part.length > 0) grid.appendChild(table(part, false, fresh, true));  // each student's games, in any column
  }
  container.appendChild(grid);
  container.dataset.pages = String(pages);
  container.dataset.page = String(page + 1);
  container.dataset.columns = String(columns);
  const note = document.getElementById("page");
  note.hidden = pages < 2;
  note.textContent = "\u00b7 page " + (page + 1) + " of " + pages + " of the students, turning by itself";
  clearTimeout(pageTimer);
  if (pages > 1) {
    pageTimer = setTimeout(() => { page += 1; if (latest) fillStudents(container, latest.students, null); },
      PAGE_SECONDS * 1000);
  }
}

// Who joined, as the class counts them (views.who_joined): the students, then the names that only ran the lab
// (the lesson's volunteers) and the programs where there are any, so a class of thirty reads as thirty.
function showPeople(box, people) {
  const parts = [[people.students, people.students === 1 ? "student" : "students"]];
  if (people.lab_only) parts.push([people.lab_only, "in the lab only"]);
  if (people.programs) parts.push([people.programs, people.programs === 1 ? "program" : "programs"]);
  box.replaceChildren();
  parts.forEach(([n, words], i) => {
    const b = document.createElement("b");
    b.textContent = String(n);
    box.append(i ? " \u00b7 " : "", b, " " + words);
  });
}

function showJoin(line) {
  const join = document.getElementById("join");
  const at = line.lastIndexOf("--code ");
  join.replaceChildren();
  if (at < 0) { join.textContent = line; return; }
  join.append(line.slice(0, at + 7));
  const code = document.createElement("span");
  code.className = "code";
  code.textContent = line.slice(at + 7);
  join.appendChild(code);
  join.append(" --name ");
  const you = document.createElement("span");
  you.className = "you";
  you.textContent = "NAME";
  join.appendChild(you);
  // The whole line on one line, as large as fits: students type it from the back row.
  join.style.fontSize = "";
  join.style.whiteSpace = "nowrap";
  let size = parseFloat(getComputedStyle(join).fontSize);
  while (join.scrollWidth > join.clientWidth && size > 19) {
    size -= 1;
    join.style.fontSize = size + "px";
  }
  if (join.scrollWidth > join.clientWidth) join.style.whiteSpace = "normal";
}

function announce(a) {
  const news = document.getElementById("news");
  news.textContent = a.name + ": " + a.score + ", " + a.note;
  news.hidden = false;
  clearTimeout(newsTimer);
  newsTimer = setTimeout(() => { news.hidden = true; }, 6000);
}

// The browser game's address (and its QR code, /play.svg) for students with no Python: without "http://",
// which every browser adds, so it is short enough to type.
function showPlay(url) {
  document.getElementById("play").hidden = !url;
  document.getElementById("play-url").textContent = (url || "").replace(/^http:\/\//, "")
    .replace(/\/play$/, "\u200b/play");  // if the column is narrow, the line breaks there and nowhere else
}

// A round: its clock counted down on the projector, its own standings while it runs, and its winners, large,
// for as long as the class says once it is over (its hold: a minute and a half, a rehearsal's 15 s). The clock is
// the class's (the round's end, as the server set it).
let roundTimer = null;

function mmss(seconds) {
  const s = Math.max(0, Math.ceil(seconds));
  return Math.floor(s / 60) + ":" + String(s % 60).padStart(2, "0");
}

function roundShown(r) {
  return r && !(r.over && (Date.now() - Date.parse(r.end)) / 1000 > r.hold);
}

function showRound(r) {
  const banner = document.getElementById("round");
  const winners = document.getElementById("winners");
  clearInterval(roundTimer);
  document.body.dataset.round = r && roundShown(r) ? (r.over ? "over" : "on") : "";
  banner.hidden = !(r && roundShown(r) && !r.over);
  winners.hidden = !(r && roundShown(r) && r.over);
  if (!r || !roundShown(r)) return;
  if (!r.over) {
    document.getElementById("round-title").textContent = "Round " + r.number + ": play now!";
    const tick = () => {
      const left = (Date.parse(r.end) - Date.now()) / 1000;
      document.getElementById("round-clock").textContent = left > 0 ? mmss(left) + " left"
        : "time! the last games are coming in";
    };
    tick();
    roundTimer = setInterval(tick, 250);
    return;
  }
  document.getElementById("winners-title").textContent = "Round " + r.number + ": " +
    (r.winners.length ? "the winners" : "no games handed in");
  document.getElementById("winners-players").textContent =
    r.players === 1 ? "1 student played in the round" : r.players + " students played in the round";
  const list = document.getElementById("winners-list");
  list.replaceChildren();
  for (const w of r.winners) {
    const li = document.createElement("li");
    li.dataset.rank = String(w.rank);
    const place = document.createElement("span");
    place.className = "place";
    place.textContent = ["", "1st", "2nd", "3rd"][w.rank] || w.rank + "th";
    const name = document.createElement("span");
    name.className = "name";
    name.textContent = w.name;
    const score = document.createElement("span");
    score.className = "score";
    score.textContent = String(w.score);
    li.append(place, name, score);
    list.appendChild(li);
  }
  // Back to the class's standings once the moment has passed.
  roundTimer = setTimeout(() => { if (latest) render(latest); }, r.hold * 1000);
}

function render(s) {
  // The join line comes only to the projector's own link (its key) and the teacher's machine: a page
  // anyone on the network opens shows the standings without the code.
  showJoin(s.join || "armgame play --join \u2026 (the code is on the teacher's projector)");
  showPlay(s.play);
  showPeople(document.getElementById("people"), s.people || {students: s.joined});
  document.getElementById("games").textContent = String(s.games);
  document.getElementById("seed").textContent = String(s.seed);
  document.getElementById("closed").hidden = !s.closed;
  document.getElementById("browser-lab").hidden = !s.browser_lab;
  document.getElementById("browser-lab-protocol").textContent = s.browser_lab || "";
  document.getElementById("rehearsal").hidden = !s.rehearsal;
  const a = s.arrival;
  const isNew = a && lastArrival !== null && a.seq > lastArrival;
  if (a) lastArrival = Math.max(lastArrival || 0, a.seq); else if (lastArrival === null) lastArrival = 0;
  showRound(s.round);
  const during = s.round && roundShown(s.round) && !s.round.over;
  document.getElementById("students-title").textContent = during
    ? "Round " + s.round.number + ": best game each, handed in during the round" : "Students: best game each";
  fillStudents(document.getElementById("students"), during ? s.round.students : s.students,
    isNew && !a.program ? a.name : null);
  fillPrograms(document.getElementById("programs"), s.programs, isNew && a.program ? a.name : null);
  if (isNew) announce(a);
  document.body.dataset.version = String(s.version);
}

let latest = null;
const key = new URLSearchParams(location.search).get("key");
const source = new EventSource(key ? "/events?key=" + encodeURIComponent(key) : "/events");
source.addEventListener("standings", (e) => {
  latest = JSON.parse(e.data);
  document.getElementById("link").hidden = true;
  render(latest);
});
source.onerror = () => { document.getElementById("link").hidden = false; };
window.addEventListener("resize", () => { if (latest) render(latest); });
