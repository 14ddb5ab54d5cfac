"""The lab in every student's browser (issue 50): the teacher's switch, the page at /play running the class's lab,
and what it tells the student.

- The switch ("Everyone's browser runs the lab") is kept in class.json (format 4; a format 3 file reads, off), is
  the teacher's alone, and the projector's facts and /play's public standings say it.
- What the page tells a student of each reach (``labmeasure.js``: the outcome word, the result's words) and the
  learning curve its end screen draws are Python's (``analysis.outcome_word``, ``result_words``,
  ``learning_curve`` on ``trial_rows``), on the adaptive bot's whole lesson and quick protocols
  with catch trials, channel trials and no-vision probes, played through ``labengine.js`` in ``node``.
- In chromium: the lab's first card and its go cue (default tier); a whole ``lesson`` at 1024x768 with keys and
  one on a phone (390x844) with the touch buttons, each handed in and in /lab's curve and n (slow tier).
"""

from __future__ import annotations

import json
import math
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from class_server import running_class
from node import run_node, skip_without_node
from test_browser_lab import own_protocols, quick, random_timeline

from armgame.classroom.intake import Clerk
from armgame.classroom.roster import Roster
from armgame.game.bots import Autopilot
from armgame.lab.analysis import figure_metric, learning_curve, outcome_word, result_words, trial_rows
from armgame.lab.bots import make_lab_bot
from armgame.lab.plan import lab_plan
from armgame.lab.presets import preset
from armgame.lab.session import LabSession, lab_config

ROOT = Path(__file__).resolve().parent.parent
RUNNER = ROOT / "tests" / "lab_page_runner.mjs"


def _post(port: int, path: str, body: dict, headers: dict | None = None) -> tuple[int, dict]:
    req = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=json.dumps(body).encode(),
                                 headers={"Content-Type": "application/json", **(headers or {})})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def _get(port: int, path: str) -> dict:
    with urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=10) as r:
        return json.loads(r.read())


# ---------------------------------------------------------------------------------------------- the switch
def test_the_switch_is_kept_in_the_class_record_and_an_older_record_reads_with_it_off(tmp_path):
    roster, _ = Roster.open(tmp_path, 7)
    clerk = Clerk(tmp_path, roster)
    assert roster.browser_lab is False
    assert "every browser runs the lab (lesson)" in clerk.browser_lab(True)
    record = json.loads((tmp_path / "class.json").read_text())
    assert record["format_version"] == 4 and record["browser_lab"] is True
    assert Roster.open(tmp_path, None)[0].browser_lab is True  # a restart keeps it
    clerk.choose_lab("curl")
    assert "(curl)" in clerk.browser_lab(True)
    assert clerk.browser_lab(False) == "the browsers play the game again"
    # A record from before the switch (format 3): read, the switch off; a bad value refused in one line.
    record = json.loads((tmp_path / "class.json").read_text())
    del record["browser_lab"]
    record["format_version"] = 3
    (tmp_path / "class.json").write_text(json.dumps(record))
    assert Roster.open(tmp_path, None)[0].browser_lab is False
    record["format_version"], record["browser_lab"] = 4, "yes"
    (tmp_path / "class.json").write_text(json.dumps(record))
    with pytest.raises(Exception, match="browser_lab must be true or false"):
        Roster.open(tmp_path, None)
    # A format 3 reader's keys: a switch in a format 3 record is a key it does not know.
    record["format_version"], record["browser_lab"] = 3, True
    (tmp_path / "class.json").write_text(json.dumps(record))
    with pytest.raises(Exception, match="browser_lab"):
        Roster.open(tmp_path, None)


def test_the_teacher_switches_it_and_the_pages_say_so(tmp_path):
    with running_class(tmp_path / "class") as opened:
        port = opened.port
        assert _get(port, "/api/standings")["browser_lab"] is False
        status, answer = _post(port, "/api/teacher/browserlab", {"on": True})
        assert status == 200 and answer["ok"], answer
        assert _get(port, "/api/standings")["browser_lab"] == "lesson"  # the projector's facts: on, and which lab
        assert opened.clerk.roster.browser_lab is True
        _post(port, "/api/teacher/browserlab", {"on": False})
        assert _get(port, "/api/standings")["browser_lab"] is False
    pages = ROOT / "armgame" / "classroom" / "static"
    assert "browser-lab" in (pages / "standings.html").read_text() and "s.browser_lab" in (
        pages / "standings.js").read_text()
    assert "Everyone's browser runs the lab" in (pages / "teacher.html").read_text()


def test_the_switch_is_the_teachers_alone(tmp_path, monkeypatch):
    """Another machine without the secret cannot switch the class's browsers to the lab."""
    from armgame.classroom import guard

    monkeypatch.setattr(guard.Guard, "is_own", lambda self, address: False)
    with running_class(tmp_path / "class") as opened:
        status, answer = _post(opened.port, "/api/teacher/browserlab", {"on": True})
        assert status in (401, 403), answer
        assert opened.clerk.roster.browser_lab is False
        status, answer = _post(opened.port, "/api/teacher/browserlab", {"on": True},
                               {"Authorization": "Bearer " + opened.clerk.roster.secret})
        assert status == 200 and opened.clerk.roster.browser_lab is True


# ------------------------------------------------------------------------------ what the page tells
def _runs() -> list[tuple[object, object, list]]:
    """(config, protocol, events): the adaptive bot's lesson, and quick protocols at random keys (catch and channel
    trials, endpoint feedback and no-vision probes, mixes, postures and displays)."""
    import random

    rng = random.Random(5)
    out = []
    for name in ("lesson",):  # a changed display's measure (the direction) is the postures protocol's, below
        protocol = preset(name)
        config = lab_config(protocol, 31, person=True)
        bot = LabSession(config, protocol, sine="arm")
        Autopilot(bot, make_lab_bot("adaptive")).play()
        out.append((config, protocol, [[e.step, e.key, e.action] for e in bot.timeline]))
    quick_ones = [quick(preset(name)) for name in ("generalization", "frames", "random-fields")]
    for protocol in [*quick_ones, *own_protocols()]:
        config = lab_config(protocol, rng.randrange(1000), person=True)
        out.append((config, protocol, random_timeline(rng, 6000)))
    return out


def test_the_page_tells_each_reach_and_draws_the_curve_as_python_measures_them():
    skip_without_node("the lab page's words and curve are not checked here")
    runs = _runs()
    stops = [c.total_steps if i == 0 else 6000 for i, (c, _, _) in enumerate(runs)]
    request = {"runs": [{"plan": lab_plan(c, p), "events": e, "stop": stop}
                        for (c, p, e), stop in zip(runs, stops, strict=True)]}
    answers = run_node(RUNNER, request)

    def close(mine: float | None, theirs: float) -> bool:
        if mine is None:
            return not math.isfinite(theirs)
        return math.isclose(mine, theirs, rel_tol=1e-9, abs_tol=1e-12)

    told = set()
    for (config, protocol, events), stop, got in zip(runs, stops, answers, strict=True):
        session = LabSession(config, protocol, sine="arm")
        limit = min(stop, session.total_steps)
        for step, key, action in events:  # as the runner plays them (TimelineInput.run_to's way)
            if step > stop:
                break
            session.advance(step - session.steps)
            session.key_event(key, action)
        session.advance(limit - session.steps)
        rows = trial_rows(session)
        metric = figure_metric(protocol)
        assert got["metric"] == metric
        assert len(got["reaches"]) == len(rows) > 3, protocol.name
        for o, row, mine in zip(session.outcomes, rows, got["reaches"], strict=True):
            assert close(mine["perpendicular"], float(row["max_perpendicular_error_m"])), (protocol.name, row, mine)
            assert close(mine["direction"], float(row["initial_direction_error_deg"])), (protocol.name, row, mine)
            assert mine["word"] == outcome_word(session, o)
            assert mine["words"] == result_words(session, o), (protocol.name, mine)
            told.add((o.plan.feedback, mine["word"]))
        curve = learning_curve(rows, metric)
        mine = got["curve"]
        assert (mine["label"], mine["unit"]) == (curve.label, curve.unit)
        assert [(p["trial"], p["catch"]) for p in mine["points"]] == [(t, c) for t, _, c in curve.points], protocol.name
        assert all(close(p["value"], v) for p, (_, v, _) in zip(mine["points"], curve.points, strict=True))
        assert [(b["name"], b["first"], b["last"], b["perturbed"]) for b in mine["blocks"]] == [
            (b.name, b.first, b.last, b.perturbed) for b in curve.blocks], protocol.name
        assert all(close(b["mean"], c.mean) or math.isclose(b["mean"], c.mean, rel_tol=1e-12)
                   for b, c in zip(mine["blocks"], curve.blocks, strict=True))
        if curve.after_effect is None:
            assert mine["afterEffect"] is None, protocol.name
        else:
            assert mine["afterEffect"]["trial"] == curve.after_effect[0]
            assert close(mine["afterEffect"]["value"], curve.after_effect[1])
    # The runs told every kind of outcome (hits and time-outs, nothing at all) in both measures.
    assert {("full", "hit"), ("full", "time out"), ("none", None)} <= told, told
    assert {got["metric"] for got in answers} == {"max_perpendicular_error_m", "initial_direction_error_deg"}


# ------------------------------------------------------------------------------------------ in chromium
def _lab_class(tmp_path, **options):
    return running_class(tmp_path / "class", **options)


def _switch_on(port: int) -> None:
    status, answer = _post(port, "/api/teacher/browserlab", {"on": True})
    assert status == 200, answer


@pytest.mark.slow  # chromium (1.6 s); the whole lesson in chromium, keys and touch, is in the slow tier beside it
def test_a_joined_student_gets_the_labs_first_card_and_its_go_cue(tmp_path):
    """The default tier's look: with the switch on (and the class closed to games), /play joins for the lab, shows
    the first card (what to do and the keys, never what will happen), and space brings the go cue: a target."""
    from browser import browser_page
    from play_page import join, open_page, run_for

    with _lab_class(tmp_path) as opened, browser_page(1024, 768) as page:
        _switch_on(opened.port)
        _post(opened.port, "/api/teacher/close", {"closed": True})  # a closed class takes the lab
        # The page's clock still but for run_for: a moving one runs on with the wall clock, and 3.5 s of a busy
        # machine between the go cue and the phase read below took the trial on past its reach ("feedback").
        errors = open_page(page, f"http://127.0.0.1:{opened.port}", still=True)
        join(page, opened.clerk.roster.code, "Ann")
        page.wait_for_selector("#lab-card", state="visible")
        card = page.inner_text("#lab-card")
        assert "The reaching lab" in card and "d/f turn the shoulder" in card and "space starts" in card
        assert "24 trials in 3 blocks" in card
        for told in ("field", "force", "change", "washout", "exposure"):  # what to do, never what will happen
            assert told not in card.lower(), told
        assert page.is_visible("#lab-head") and page.is_hidden("#end")
        assert page.inner_text("#lab-trial") == "Trial 1 of 24 · baseline"
        page.keyboard.press(" ")
        assert page.is_hidden("#lab-card")
        run_for(page, 1100)  # the hold at home (0.5 to 1 s) brings the go cue
        # The words over the scene, never on it: the head above the scene's box, both inside the window.
        head = page.eval_on_selector("#lab-head",
                                     "e => { const b = e.getBoundingClientRect(); return [b.top, b.bottom]; }")
        scene = page.evaluate("(() => { const c = document.getElementById('game'), b = c.getBoundingClientRect(),"
                              " w = c.workspace; return [b.top + w.y, b.top + w.y + w.height, b.bottom]; })()")
        assert 0 <= head[0] < head[1] <= scene[0] < scene[1] <= scene[2] <= 768, (head, scene)
        debug = page.evaluate("document.getElementById('game').debug")
        assert debug["lab"] and debug["phase"] == "reach" and debug["steps"] > 0
        assert page.evaluate("(() => { const c = document.getElementById('game'); const g = c.getContext('2d');"
                             " const d = g.getImageData(0, 0, c.width, c.height).data; let red = 0;"
                             " for (let i = 0; i < d.length; i += 4) if (d[i] === 200 && d[i + 1] === 0) red++;"
                             " return red; })()") > 100, "no target drawn after the hold at home"
        assert opened.clerk.roster.players  # the lab's join, into a closed class
        assert errors == [] and page.dialogs == []


def _run_the_lab(page, touch: bool) -> None:
    """The whole lab on the page's clock: past each card (space, or the card's button on a touch screen), now and then
    a muscle pulled for a moment and the hand brought home (space, or the home button), so the next go cue comes; the
    trials time out when the keys miss."""
    from play_page import JUMP_MS

    frames, finger = 0, 10

    def tap(key: str, hold: int) -> None:
        nonlocal finger
        if touch:
            finger += 1
            button = "#reset" if key == " " else f"#touch button[data-key='{key}']"
            page.dispatch_event(button, "pointerdown", {"pointerId": finger, "pointerType": "touch"})
            page.clock.fast_forward(hold)
            page.dispatch_event(button, "pointerup", {"pointerId": finger, "pointerType": "touch"})
        else:
            page.keyboard.down(key)
            page.clock.fast_forward(hold)
            page.keyboard.up(key)

    while not page.is_visible("#lab-end"):
        if page.is_visible("#lab-card"):
            page.tap("#lab-go") if touch else page.keyboard.press(" ")
        elif frames % 7 == 3:
            tap("dfjk"[frames // 7 % 4], JUMP_MS)
            page.clock.fast_forward(JUMP_MS)
            tap(" ", 20)  # the hand home: the next trial's hold at home can begin
        page.clock.fast_forward(JUMP_MS)
        frames += 1
        assert frames < 3000, page.evaluate("document.getElementById('game').debug")


def _a_whole_lesson(tmp_path, size: tuple[int, int], touch: bool) -> None:
    from browser import browser_page
    from play_page import join, open_page

    device = {"has_touch": True, "is_mobile": True, "device_scale_factor": 3} if touch else {}
    with _lab_class(tmp_path) as opened, browser_page(*size, **device) as page:
        _switch_on(opened.port)
        errors = open_page(page, f"http://127.0.0.1:{opened.port}")
        join(page, opened.clerk.roster.code, "Ann B")
        page.wait_for_selector("#lab-card", state="visible")
        if touch:
            assert page.is_visible("#touch") and "buttons turn the shoulder" in page.inner_text("#lab-card")
            assert page.inner_text("#reset .key") == "home"
        _run_the_lab(page, touch)
        page.wait_for_selector("#lab-answer:has-text('lab run handed in: in the class curve')", timeout=30_000)
        end = page.inner_text("#lab-end")
        assert "lesson: 24 trials" in end and "Block means: baseline" in end
        assert page.locator("#lab-curve circle").count() + page.locator("#lab-curve text").count() > 4
        curve = _get(opened.port, "/api/lab")
        assert curve["students"] == 1 and curve["trials"], curve  # in the class curve, n = 1
        assert [run.player for run in opened.clerk.lab_runs] == ["Ann B"]
        assert errors == [] and page.dialogs == []


@pytest.mark.slow  # a whole lesson in chromium (about 4 s)
def test_a_whole_lesson_with_keys_at_1024x768_is_handed_in_and_in_the_class_curve(tmp_path):
    _a_whole_lesson(tmp_path, (1024, 768), touch=False)


@pytest.mark.slow  # a whole lesson in chromium (about 5 s)
def test_a_whole_lesson_with_the_touch_buttons_on_a_phone_is_handed_in_and_in_the_class_curve(tmp_path):
    _a_whole_lesson(tmp_path, (390, 844), touch=True)


def test_what_teaching_md_says_the_switch_and_the_page_say_is_what_they_say():
    """docs/teaching.md's words for the teacher's page, the projector and the student's screen are the pages' own."""
    guide = " ".join((ROOT / "docs" / "teaching.md").read_text(encoding="utf-8").split())
    static = ROOT / "armgame" / "classroom" / "static"
    pages = " ".join(" ".join((static / name).read_text(encoding="utf-8").split()) for name in (
        "teacher.html", "standings.html", "play.js", "labpage.js", "play.html"))
    for words in ("Everyone's browser runs the lab", "Back to the game", "LAB in every browser",
                  "the teacher has started the lab", "Play again", "Run the lab again"):
        assert words in guide and words in pages, words
    # The class's answer and the measure's words, as the tests above see them said.
    assert "lab run handed in: in the class curve" in guide
    assert "cm off the line (right)" in guide
