"""Draw the live class's pages as a projector shows them: docs/img/class_page.png (thirty students) and
class_lab.png, and a round's end, class_round.png; the browser game (/play) as a student's laptop shows
it, mid-game and at its end: class_play.png, class_play_end.png; and mid-game on a phone and a tablet, played
with fingers on the touch buttons: class_play_phone.png (390x844), class_play_tablet.png (820x1180); and the
lab in the browser (the teacher's switch "Everyone's browser runs the lab" on), a reach's path just after it and
the end screen at 1024x768, class_lab_play.png and class_lab_play_end.png, and a reach on a phone with the
touch buttons, class_lab_phone.png (390x844).

    python docs/make_class_screenshots.py             # writes docs/img/class_*.png
    python docs/make_class_screenshots.py --out DIR   # somewhere else, at 1024x768 and 1920x1080 both
    python docs/make_class_screenshots.py --out DIR --quick   # a smaller class (the tests: it cannot rot)

A real class on loopback (a thread of this process) takes a class's games, a few programs' and four
volunteers' lab runs, and Debian's chromium (driven by Playwright, as in the tests) draws the pages.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from browser import FLAGS, chromium_path  # noqa: E402
from class_server import keyboard_game, running_class  # noqa: E402
from play_page import PATTERN, join, open_page, play_keys, run_for, to_the_end  # noqa: E402

from armgame.classroom import client  # noqa: E402
from armgame.cli import main  # noqa: E402
from armgame.records.replay import Replay  # noqa: E402

STUDENTS = [("Amira", 42), ("Ben", 30), ("Chloé", 55), ("Dmitri", 18), ("Eun-ji", 48), ("Farah", 25),
            ("Gabriel", 36), ("Hana", 12), ("Ife", 58), ("Jonas", 22), ("Kai", 40), ("Lucía", 33), ("Mateo", 8),
            ("Nour", 45), ("Oskar", 28), ("Priya", 51), ("Quentin", 15), ("Rosa", 38), ("Sami", 21), ("Tariq", 44),
            ("Uma", 31), ("Viktor", 50), ("Wen", 27), ("Xavier", 10), ("Yara", 35), ("Zoë F", 47),
            ("Aleksandra Nowakowska", 39), ("Bruno", 24), ("Carmen", 53), ("Diego", 16)]
#: The games handed in during the round the pictures show: (student, seconds of the model bot's keys).
ROUND = [("Ben", 57), ("Hana", 49), ("Dmitri", 46), ("Amira", 26)]
#: The volunteers run the guide's own protocol (docs/teaching.md): the lesson preset.
LAB = "lesson"
#: The washout one trial long: the after-effect's label at the curve's right edge, where it must stay inside.
QUICK_LAB = ('name = "quick"\ntargets = 2\ntimeout = 1.5\n[[blocks]]\nname = "field"\ntrials = 2\n'
             'perturbation = "curl"\nb = -2.0\n[[blocks]]\nname = "washout"\ntrials = 1\n')
#: What the script draws, by name: docs/img holds these (tests/test_docs.py checks the rest of docs/img).
PICTURES = ("class_page.png", "class_lab.png", "class_round.png", "class_play.png", "class_play_end.png",
            "class_play_phone.png", "class_play_tablet.png", "class_lab_play.png", "class_lab_play_end.png",
            "class_lab_phone.png")
#: The touch screens drawn (each once, whatever the laptops' sizes): name, size, student.
TOUCH = (("class_play_phone.png", (390, 844), "Léa"), ("class_play_tablet.png", (820, 1180), "Sofía"))


def curve_protocol(work: Path, quick: bool) -> str:
    """The lab protocol the volunteers run, the class curve's (``--lab``)."""
    if not quick:
        return LAB
    (work / "quick.toml").write_text(QUICK_LAB)
    return str(work / "quick.toml")


def fill(opened, work: Path, quick: bool = False) -> None:
    address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
    code = opened.clerk.roster.code
    for i, (name, seconds) in enumerate(STUDENTS[:4] if quick else STUDENTS):
        os.environ[client.CLIENT_ENV] = str(work / f"m{i}")
        member = client.join(address, code, name)
        client.hand_in(member, keyboard_game(seconds * 0.7, player=name).to_bytes())
        if i % 3 == 0:
            client.hand_in(member, keyboard_game(seconds * 0.5 + 1, player=name).to_bytes())
    protocol = str(work / "quick.toml") if quick else LAB
    if quick:
        (work / "quick.toml").write_text(QUICK_LAB)
    for i, name in enumerate(("Amira", "Ben") if quick else ("Amira", "Ben", "Chloé", "Dmitri")):
        os.environ[client.CLIENT_ENV] = str(work / f"m{i}")
        record = work / f"lab{i}.json"
        main(["lab", protocol, "--bot", "adaptive", "--headless", "--seed", str(i + 1),
              "--record", str(record)])
        replay = dataclasses.replace(Replay.load(record), driven="keyboard", driver=None, player=name)
        client.hand_in(client.join(address, code, name), replay.to_bytes())
    for name, bot in (("Ife's robot", "model"),) if quick else (("Ife's robot", "model"), ("Robo", "naive")):
        os.environ[client.CLIENT_ENV] = str(work / f"bot-{bot}")
        main(["play", "--headless", "--bot", bot, "--join", f"127.0.0.1:{opened.port}", "--code", code,
              "--name", name])


def play(browser, opened, size: tuple[int, int], out: Path, suffix: str) -> None:
    """A student on a Chromebook joins the class in the browser and plays: mid-game, then the end."""
    page = browser.new_page(viewport={"width": size[0], "height": size[1]})
    errors = open_page(page, f"http://127.0.0.1:{opened.port}")
    join(page, opened.clerk.roster.code, "Pablo" if size[0] < 1500 else "Quinn")
    play_keys(page, rounds=3)
    page.keyboard.down("j")  # a muscle held as the picture is taken: its bar and its belly show it
    run_for(page, 300)
    page.screenshot(path=str(out / f"class_play{suffix}.png"))
    page.keyboard.up("j")
    to_the_end(page)
    page.wait_for_selector("#end-answer:has-text('handed in')")
    page.screenshot(path=str(out / f"class_play_end{suffix}.png"))
    page.close()
    if errors:
        raise SystemExit(f"the browser game at {size[0]}x{size[1]} logged {errors}")


def touch_play(browser, opened, size: tuple[int, int], path: Path, name: str) -> None:
    """A student on a phone or a tablet joins and plays with fingers on the touch buttons: mid-game, a muscle held."""
    context = browser.new_context(viewport={"width": size[0], "height": size[1]}, has_touch=True, is_mobile=True)
    page = context.new_page()
    errors = open_page(page, f"http://127.0.0.1:{opened.port}")
    join(page, opened.clerk.roster.code, name)
    page.dispatch_event("#game", "pointerdown", {"pointerId": 1, "pointerType": "touch"})  # "a tap starts"
    for finger, (key, hold, rest) in enumerate(PATTERN * 3, start=2):
        button = "#reset" if key == "space" else f"#touch button[data-key='{key}']"
        page.dispatch_event(button, "pointerdown", {"pointerId": finger, "pointerType": "touch"})
        run_for(page, hold or 20)
        page.dispatch_event(button, "pointerup", {"pointerId": finger, "pointerType": "touch"})
        run_for(page, rest)
    page.dispatch_event("#touch button[data-key='j']", "pointerdown", {"pointerId": 99, "pointerType": "touch"})
    run_for(page, 300)  # the biceps held as the picture is taken: its button, its bar and its belly show it
    page.screenshot(path=str(path))
    context.close()
    if errors:
        raise SystemExit(f"the browser game at {size[0]}x{size[1]} with touch logged {errors}")


def lab_reach(page, key: str, press, touch: bool = False) -> None:
    """One trial of the lab in the browser: past a card if one is up, the hold at home to the go cue, a muscle pulled
    for a moment (``press(key, ms)``), the hand brought home, and the trial left to end (its path then shown)."""
    if page.is_visible("#lab-card"):
        if touch:
            page.tap("#lab-go")
        else:
            page.keyboard.press(" ")
    run_for(page, 1100)
    press(key, 260)
    for _ in range(40):  # the time-out at the latest
        if page.evaluate("document.getElementById('game').debug.phase") != "reach":
            return
        run_for(page, 100)


def bot_reaches(opened) -> list[list[tuple[int, str, str]]]:
    """The adapting bot's keys on the class's lab (the class's protocol on the class's seed), each trial's as (steps
    after its go cue, key, action): the pictures show reaches a student makes, not keys pressed at random."""
    from armgame.game.bots import Autopilot
    from armgame.lab.bots import make_lab_bot
    from armgame.lab.presets import preset
    from armgame.lab.session import LabSession, lab_config

    protocol = opened.clerk.curve_protocol() or preset("lesson")
    bot = LabSession(lab_config(protocol, opened.clerk.roster.seed, person=True), protocol, sine="arm")
    Autopilot(bot, make_lab_bot("adaptive")).play()
    return [[(e.step - o.go_step, e.key, e.action) for e in bot.timeline
             if o.go_step <= e.step < o.end_step and e.key in "dfjk"] for o in bot.outcomes]


def lab_play(browser, opened, size: tuple[int, int], out: Path, suffix: str) -> None:
    """A student on a Chromebook runs the class's lab in the browser, each trial's keys the adapting bot's at its steps
    after the go cue (the page's clock moved to each): a reach's path just after it, then the end screen."""
    page = browser.new_page(viewport={"width": size[0], "height": size[1]})
    errors = open_page(page, f"http://127.0.0.1:{opened.port}")
    join(page, opened.clerk.roster.code, "Paula" if size[0] < 1500 else "Quirin")  # names of their own
    page.wait_for_selector("#lab-card", state="visible")
    state = "document.getElementById('game').debug"
    for trial, keys in enumerate(bot_reaches(opened)):
        d = page.evaluate(state)
        while d["phase"] != "end" and not (d["phase"] == "reach" and d["done"] == trial and d["go"] is not None):
            if page.is_visible("#lab-card"):
                page.keyboard.press("Enter")
            page.clock.fast_forward(16)
            d = page.evaluate(state)
        if d["phase"] == "end":
            break
        for offset, key, action in keys:
            while d["phase"] == "reach" and d["steps"] < d["go"] + offset:
                page.clock.fast_forward(16)
                d = page.evaluate(state)
            if d["phase"] != "reach":
                break
            (page.keyboard.down if action == "down" else page.keyboard.up)(key)
        for key in "dfjk":
            page.keyboard.up(key)
        if trial == 2:
            while page.evaluate(state)["phase"] == "reach":
                run_for(page, 50)
            run_for(page, 100)
            page.screenshot(path=str(out / f"class_lab_play{suffix}.png"))
    while not page.is_visible("#lab-end"):
        if page.is_visible("#lab-card"):
            page.keyboard.press("Enter")
        run_for(page, 260)
    page.wait_for_selector("#lab-answer:has-text('handed in')")
    page.screenshot(path=str(out / f"class_lab_play_end{suffix}.png"))
    page.close()
    if errors:
        raise SystemExit(f"the browser's lab at {size[0]}x{size[1]} logged {errors}")


def touch_lab(browser, opened, size: tuple[int, int], path: Path, name: str) -> None:
    """A student on a phone runs the lab with the touch buttons: a reach's path just after it."""
    context = browser.new_context(viewport={"width": size[0], "height": size[1]}, has_touch=True, is_mobile=True)
    page = context.new_page()
    errors = open_page(page, f"http://127.0.0.1:{opened.port}")
    join(page, opened.clerk.roster.code, name)
    page.wait_for_selector("#lab-card", state="visible")
    fingers = iter(range(2, 1000))

    def press(key: str, ms: int) -> None:
        button = "#reset" if key == " " else f"#touch button[data-key='{key}']"
        finger = next(fingers)
        page.dispatch_event(button, "pointerdown", {"pointerId": finger, "pointerType": "touch"})
        run_for(page, ms)
        page.dispatch_event(button, "pointerup", {"pointerId": finger, "pointerType": "touch"})

    lab_reach(page, "j", press, touch=True)
    run_for(page, 200)
    page.screenshot(path=str(path))
    context.close()
    if errors:
        raise SystemExit(f"the browser's lab at {size[0]}x{size[1]} with touch logged {errors}")


def teacher(opened, path: str, body: dict) -> None:
    """A teacher's action, from the teacher's machine (which needs no secret)."""
    import json
    import urllib.request

    req = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}", method="POST",
                                 data=json.dumps(body).encode(), headers={"Content-Type": "application/json"})
    urllib.request.urlopen(req, timeout=10).close()


def round_end(browser, opened, work: Path, size: tuple[int, int], out: Path, suffix: str) -> None:
    """A three-minute round with a few games handed in during it, and the projector at its end (the round's record
    moved back, as a restart would read it, so the picture need not wait three minutes)."""
    from datetime import datetime, timedelta

    from armgame.classroom.rounds import GRACE_SECONDS

    teacher(opened, "/api/teacher/round", {"minutes": 3})
    address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
    machines = {name: f"m{i}" for i, (name, _) in enumerate(STUDENTS)}  # each student on their own machine
    for name, seconds in ROUND:
        os.environ[client.CLIENT_ENV] = str(work / machines[name])
        client.hand_in(client.join(address, opened.clerk.roster.code, name),
                       keyboard_game(seconds * 0.7 + size[0] / 10_000, player=name).to_bytes())  # each size its game
    last = max(datetime.fromisoformat(e.entered_at) for e in opened.clerk.entries if e.entered_at)
    moved = {**opened.clerk.roster.round, "minutes": 1,
             "start": (last - timedelta(minutes=1, seconds=GRACE_SECONDS - 1)).isoformat(timespec="seconds")}
    opened.clerk.roster.changed(round=moved)
    page = browser.new_page(viewport={"width": size[0], "height": size[1]})
    page.goto(f"http://127.0.0.1:{opened.port}/")
    page.wait_for_selector("body[data-round='over']", state="attached", timeout=15_000)
    page.screenshot(path=str(out / f"class_round{suffix}.png"))
    page.close()
    teacher(opened, "/api/teacher/round", {"stop": True})


def main_(argv: list[str] | None = None) -> int:
    from playwright.sync_api import sync_playwright

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--quick", action="store_true", help="a smaller class, one size")
    args = parser.parse_args(argv)
    sizes = [(1024, 768)] if args.out is None or args.quick else [(1024, 768), (1920, 1080)]
    out = args.out or HERE / "img"
    with tempfile.TemporaryDirectory() as tmp, \
            running_class(Path(tmp) / "class", lab=curve_protocol(Path(tmp), args.quick)) as opened:
        fill(opened, Path(tmp), args.quick)
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=chromium_path(), args=FLAGS)
            for width, height in sizes:
                page = browser.new_page(viewport={"width": width, "height": height})
                suffix = "" if args.out is None or args.quick else f"-{width}x{height}"
                page.goto(f"http://127.0.0.1:{opened.port}/")
                page.wait_for_selector("#students tr:nth-child(4)")
                page.wait_for_timeout(300)  # the columns measured at the page's final size
                page.screenshot(path=str(out / f"class_page{suffix}.png"))
                page.goto(f"http://127.0.0.1:{opened.port}/lab")
                page.wait_for_selector(f"body[data-students='{2 if args.quick else 4}']", state="attached")
                clipped = page.eval_on_selector_all(
                    "svg text", "(texts) => { const box = texts[0].ownerSVGElement.getBoundingClientRect();"
                    " return texts.filter(t => { const b = t.getBoundingClientRect();"
                    " return b.left < box.left - 0.5 || b.right > box.right + 0.5; }).map(t => t.textContent); }")
                if clipped:  # a label drawn past the curve's edge (the after-effect beside a short washout)
                    raise SystemExit(f"the class curve at {width}x{height} cuts {clipped}")
                page.screenshot(path=str(out / f"class_lab{suffix}.png"))
                page.close()
                round_end(browser, opened, Path(tmp), (width, height), out, suffix)
                play(browser, opened, (width, height), out, suffix)
                print(f"wrote {out / f'class_page{suffix}.png'}, class_lab{suffix}.png and class_play*{suffix}.png")
            for name, size, student in TOUCH:
                touch_play(browser, opened, size, out / name, student)
                print(f"wrote {out / name}")
            teacher(opened, "/api/teacher/browserlab", {"on": True})  # every browser runs the lab from here on
            for width, height in sizes:
                suffix = "" if args.out is None or args.quick else f"-{width}x{height}"
                lab_play(browser, opened, (width, height), out, suffix)
                print(f"wrote {out / f'class_lab_play{suffix}.png'} and class_lab_play_end{suffix}.png")
            touch_lab(browser, opened, (390, 844), out / "class_lab_phone.png", "Lina")
            print(f"wrote {out / 'class_lab_phone.png'}")
            browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main_())
