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

function fill(container, rows, programs, fresh) {
  container.replaceChildren();
  if (rows.length === 0) {
    const empty = document.createElement("div");
    empty.className = "empty";
    empty.textContent = programs ? "none yet" : "no games yet: play, and yours appears here";
    container.appendChild(empty);
    return;
  }
  const table = document.createElement("table");
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
    if (!programs) cell(tr, gamesText(r.games), "games");
    table.appendChild(tr);
  }
  container.appendChild(table);
  // Rows that do not fit the projector are summed up in one line, never scrolled.
  let hidden = 0;
  while (table.rows.length > 1 && container.scrollHeight > container.clientHeight + 1) {
    table.deleteRow(-1);
    hidden += 1;
  }
  if (hidden > 0) {
    table.deleteRow(-1);
    hidden += 1;
    const more = document.createElement("div");
    more.className = "more";
    more.textContent = "and " + hidden + " more";
    container.appendChild(more);
  }
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

function render(s) {
  // The join line comes only to the projector's own link (its key) and the teacher's machine: a page
  // anyone on the network opens shows the standings without the code.
  showJoin(s.join || "armgame play --join \u2026 (the code is on the teacher's projector)");
  showPlay(s.play);
  document.getElementById("joined").textContent = String(s.joined);
  document.getElementById("games").textContent = String(s.games);
  document.getElementById("seed").textContent = String(s.seed);
  document.getElementById("closed").hidden = !s.closed;
  const a = s.arrival;
  const isNew = a && lastArrival !== null && a.seq > lastArrival;
  if (a) lastArrival = Math.max(lastArrival || 0, a.seq); else if (lastArrival === null) lastArrival = 0;
  fill(document.getElementById("students"), s.students, false, isNew && !a.program ? a.name : null);
  fill(document.getElementById("programs"), s.programs, true, isNew && a.program ? a.name : null);
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
