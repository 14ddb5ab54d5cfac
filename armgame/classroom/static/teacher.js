// The teacher's controls: every call carries the secret typed here (kept for this tab only).
"use strict";

const $ = (id) => document.getElementById(id);
let secret = sessionStorage.getItem("armgame-secret") || "";

// What the last action did, in ink; only a refusal or a failure in red.
function say(text, failed = false) {
  $("status").textContent = text;
  $("status").classList.toggle("failed", failed);
}

async function call(path, body) {
  // On the teacher's own laptop no secret is needed (the class knows its own machine); elsewhere it is typed.
  const options = {headers: secret ? {Authorization: "Bearer " + secret} : {}};
  if (body !== undefined) {
    options.method = "POST";
    options.headers["Content-Type"] = "application/json";
    options.body = JSON.stringify(body);
  }
  const r = await fetch(path, options);
  if (!r.ok) {
    let message = r.status + "";
    try { message = (await r.json()).error; } catch (e) { /* not JSON */ }
    throw new Error(message);
  }
  return r;
}

function row(table, r, kind) {
  const tr = document.createElement("tr");
  const games = r.games === 1 ? "1 game" : r.games + " games";
  for (const text of [kind, r.name, String(r.score), games, r.hidden ? "hidden on the projector" : "shown"]) {
    const td = document.createElement("td");
    td.textContent = text;
    tr.appendChild(td);
  }
  const td = document.createElement("td");
  const hide = document.createElement("button");
  hide.textContent = r.hidden ? "Show" : "Hide";
  hide.addEventListener("click", async () => {
    try { say((await (await call("/api/teacher/hide", {name: r.name, hidden: !r.hidden})).json()).message); }
    catch (e) { say(e.message, true); }
    refresh();
  });
  td.appendChild(hide);
  tr.appendChild(td);
  table.appendChild(tr);
}

function button(text, action) {
  const b = document.createElement("button");
  b.textContent = text;
  b.addEventListener("click", async () => {
    try { say((await (await action()).json()).message); } catch (e) { say(e.message, true); }
    refresh();
  });
  return b;
}

// Who joined, as the projector counts them (views.who_joined): students, the lab's volunteers, programs.
function joinedWords(people) {
  const words = [people.students + (people.students === 1 ? " student" : " students")];
  if (people.lab_only) words.push(people.lab_only + " in the lab only");
  if (people.programs) words.push(people.programs + (people.programs === 1 ? " program" : " programs"));
  return words.join(", ") + " joined";
}

// What a name has handed in: its games and its lab runs (a volunteer's run is not "no game yet").
function handedIn(n) {
  const parts = [];
  if (n.games > 0) parts.push(n.games === 1 ? "1 game" : n.games + " games");
  if (n.lab.length > 0) {
    parts.push("lab: " + (n.lab.length === 1 ? "1 run" : n.lab.length + " runs") + " (" +
      [...new Set(n.lab)].join(", ") + ")");
  }
  return parts.length ? parts.join("; ") : "joined, no game yet";
}

function machines(view) {
  const box = $("machines");
  box.replaceChildren();
  $("waiting").textContent = joinedWords(view.people) + "; " + view.waiting +
    (view.waiting === 1 ? " name has" : " names have") + " handed nothing in yet (no game, no lab run).";
  $("list-state").textContent = view.locked ? "The list is locked: no new names." : "New names can join.";
  // The switch for the whole class: a game under way is finished first, then the page at /play runs the lab.
  $("browser-lab-state").textContent = view.browser_lab
    ? "On: every browser at /play runs the lab of the curve's protocol, and hands it in." : "Off: the browsers play the game.";
  const select = $("lab-protocol");
  if (select.options.length === 0) {
    for (const name of view.presets) {
      const option = document.createElement("option");
      option.value = name;
      option.textContent = name;
      select.appendChild(option);
    }
  }
  if (view.lab && !view.presets.includes(view.lab)) {
    const option = document.createElement("option");
    option.value = "";
    option.textContent = view.lab + " (the class's own file)";
    select.appendChild(option);
    select.value = "";
  } else {
    select.value = view.lab || "";
  }
  for (const m of view.machines) {
    const group = document.createElement("div");
    group.className = "machine";
    const head = document.createElement("p");
    const count = m.names.length === 1 ? "1 name" : m.names.length + " names";
    head.textContent = "Machine " + m.address + ": " + count + " ";
    if (m.names.length > 1) {
      head.appendChild(button("Remove all " + m.names.length,
        () => call("/api/teacher/remove", {names: m.names.map((n) => n.name)})));
    }
    group.appendChild(head);
    const table = document.createElement("table");
    for (const n of m.names) {
      const tr = document.createElement("tr");
      for (const text of [n.name, handedIn(n), n.hidden ? "hidden on the projector" : "shown"]) {
        const td = document.createElement("td");
        td.textContent = text;
        tr.appendChild(td);
      }
      const td = document.createElement("td");
      td.appendChild(button("Remove", () => call("/api/teacher/remove", {names: [n.name]})));
      tr.appendChild(td);
      table.appendChild(tr);
    }
    group.appendChild(table);
    box.appendChild(group);
  }
}

async function refresh() {
  try {
    machines(await (await call("/api/teacher/roster")).json());
    const s = await (await call("/api/teacher/standings")).json();
    $("controls").hidden = false;
    const table = $("everyone");
    table.replaceChildren();
    for (const r of s.students) row(table, r, "student");
    for (const r of s.programs) row(table, r, "program");
    say(s.closed ? "The class is closed to new games; the lab's volunteers still join, and their runs count."
      : "The class takes games.");
  } catch (e) {
    $("controls").hidden = true;
    $("ask-secret").hidden = false;
    say(e.message, true);
  }
}

async function download(path, filename) {
  try {
    const blob = await (await call(path)).blob();
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob);
    a.download = filename;
    a.click();
    URL.revokeObjectURL(a.href);
  } catch (e) { say(e.message, true); }
}

$("unlock").addEventListener("click", () => {
  secret = $("secret").value.trim();
  sessionStorage.setItem("armgame-secret", secret);
  refresh();
});
$("close").addEventListener("click", async () => { try { await call("/api/teacher/close", {closed: true}); } catch (e) { say(e.message, true); } refresh(); });
$("open").addEventListener("click", async () => { try { await call("/api/teacher/close", {closed: false}); } catch (e) { say(e.message, true); } refresh(); });
$("release").addEventListener("click", async () => {
  try { say((await (await call("/api/teacher/release", {name: $("release-name").value.trim()})).json()).message); }
  catch (e) { say(e.message, true); }
});
$("lock").addEventListener("click", async () => { try { say((await (await call("/api/teacher/lock", {locked: true})).json()).message); } catch (e) { say(e.message, true); } refresh(); });
$("unlock-list").addEventListener("click", async () => { try { say((await (await call("/api/teacher/lock", {locked: false})).json()).message); } catch (e) { say(e.message, true); } refresh(); });
$("lab-protocol").addEventListener("change", async () => {
  if (!$("lab-protocol").value) return;
  try { say((await (await call("/api/teacher/lab", {protocol: $("lab-protocol").value})).json()).message); }
  catch (e) { say(e.message, true); }
  refresh();
});
for (const [id, on] of [["browser-lab-on", true], ["browser-lab-off", false]]) {
  $(id).addEventListener("click", async () => {
    try { say((await (await call("/api/teacher/browserlab", {on})).json()).message); } catch (e) { say(e.message, true); }
    refresh();
  });
}
$("round-start").addEventListener("click", async () => {
  try { say((await (await call("/api/teacher/round", {minutes: Number($("round-minutes").value)})).json()).message); }
  catch (e) { say(e.message, true); }
});
$("round-stop").addEventListener("click", async () => {
  try { say((await (await call("/api/teacher/round", {stop: true})).json()).message); } catch (e) { say(e.message, true); }
});
$("rename").addEventListener("click", async () => {
  try {
    say((await (await call("/api/teacher/rename", {name: $("rename-name").value.trim(),
      to: $("rename-to").value.trim()})).json()).message);
  } catch (e) { say(e.message, true); }
  refresh();
});
$("games-csv").addEventListener("click", () => download("/api/teacher/games.csv", "class-games.csv"));
$("lab-csv").addEventListener("click", () => download("/api/teacher/lab.csv", "class-lab-reaches.csv"));
$("students-csv").addEventListener("click", () => download("/api/teacher/students.csv", "class-lab-students.csv"));
$("lab-png").addEventListener("click", () => download("/api/teacher/lab.png", "class-lab-curve.png"));
refresh();

// The browser game's address (public: the projector shows it too), for students who cannot install Python.
fetch("/api/standings").then((r) => r.json()).then((s) => {
  $("rehearsal").hidden = !s.rehearsal;  // said plainly, so nobody takes a rehearsal for the class
  if (!s.play) return;
  $("play-url").textContent = s.play;
  $("play").hidden = false;
}).catch(() => { /* the class is not reached: the terminal's banner has the address too */ });
