"""The browser game (/play) on every screen a student brings: phones and tablets, upright and sideways. At each
size, in a real chromium with touch: every control lies wholly on the screen and nothing covers it (the join
form, the touch buttons, reset, "not NAME?", "Play again"); no control overlaps another or the status line; each
touch button is at least 44 x 44 CSS px (Apple's 44 pt, Material's 48 dp) with its label whole; the arm's reach
(the outer circle of the workspace) lies whole inside the canvas and the screen, under no control; and a finger
on each muscle's button pulls that muscle, and on reset resets. One browser context per kind of device,
resized through its sizes, the game played on the page's own clock."""

from __future__ import annotations

import pytest
from browser import browser_page
from class_server import running_class
from play_page import join, open_page, run_for, to_the_end

PHONES = [(390, 844), (360, 640), (412, 915), (640, 360), (844, 390)]
TABLETS = [(820, 1180), (768, 1024), (1180, 820), (1366, 768)]
#: Apple's Human Interface Guidelines: 44 pt a target (Material: 48 dp).
MIN_TARGET = 44
MUSCLES = "dfjk"

#: Every control shown, its box, and whether the point at its centre is itself (nothing over it); the status
#: line's box; the canvas's box and the reach's, in the viewport's px; the labels' boxes in their buttons.
LOOK = """() => {
  const shown = (e) => e !== null && e.getClientRects().length > 0 && getComputedStyle(e).visibility !== "hidden";
  const box = (e) => { const b = e.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; };
  const controls = [...document.querySelectorAll(
      "#touch button, #not-me, #again, #join input, #join button, #lab-go, #lab-again")].filter(shown).map((e) => {
    const [l, t, r, b] = box(e);
    const hit = document.elementFromPoint((l + r) / 2, (t + b) / 2);
    return { name: e.id || e.dataset.key || e.textContent, box: [l, t, r, b], onTop: hit !== null && e.contains(hit),
      labels: [...e.querySelectorAll("span")].map((s) => ({ box: box(s), size: parseFloat(getComputedStyle(s).fontSize),
        cls: s.className, text: s.textContent })) };
  });
  const canvas = document.getElementById("game"), c = box(canvas), w = canvas.workspace;
  const head = document.getElementById("lab-head");
  return { controls, status: box(document.getElementById("status")), canvas: c, head: shown(head) ? box(head) : null,
    reach: w ? [c[0] + w.x, c[1] + w.y, c[0] + w.x + w.width, c[1] + w.y + w.height] : null,
    view: [window.innerWidth, window.innerHeight], scroll: [document.documentElement.scrollWidth,
      document.documentElement.scrollHeight] };
}"""


def _inside(inner, outer, slack: float = 0.5) -> bool:
    return (inner[0] >= outer[0] - slack and inner[1] >= outer[1] - slack and inner[2] <= outer[2] + slack
            and inner[3] <= outer[3] + slack)


def _overlap(a, b) -> bool:
    return min(a[2], b[2]) - max(a[0], b[0]) > 0.5 and min(a[3], b[3]) - max(a[1], b[1]) > 0.5


def _resize(page, size: tuple[int, int]) -> None:
    """The page at ``size``, laid out, its canvas's bitmap following its new box and drawn (ResizeObserver)."""
    page.set_viewport_size({"width": size[0], "height": size[1]})
    page.wait_for_function("([w, h]) => window.innerWidth === w && window.innerHeight === h", arg=list(size))
    run_for(page, 100)
    page.wait_for_function("() => { const c = document.getElementById('game'), b = c.getBoundingClientRect(),"
                           " [w, h] = c.debug.box; return Math.abs(b.width - w) < .5 && Math.abs(b.height - h) < .5; }")
    run_for(page, 100)


def _check(page, size: tuple[int, int], phase: str) -> dict:
    """The layout's promises at ``size``: returns what the page showed."""
    look = page.evaluate(LOOK)
    where = f"{size[0]}x{size[1]} ({phase})"
    screen = [0, 0, *look["view"]]
    assert look["view"] == list(size), where
    assert look["scroll"][0] <= size[0] and look["scroll"][1] <= size[1], f"{where}: the page scrolls: {look['scroll']}"
    controls = look["controls"]
    assert controls, where
    for i, c in enumerate(controls):
        assert _inside(c["box"], screen), f"{where}: {c['name']!r} is not wholly on the screen: {c['box']}"
        assert c["onTop"], f"{where}: something lies over {c['name']!r}"
        for other in controls[i + 1:]:
            assert not _overlap(c["box"], other["box"]), f"{where}: {c['name']!r} overlaps {other['name']!r}"
        if c["name"] != "not-me":  # the status line holds it
            assert not _overlap(c["box"], look["status"]), f"{where}: the status line lies over {c['name']!r}"
    touch = [c for c in controls if c["labels"]]
    for c in touch:
        left, top, right, bottom = c["box"]
        assert right - left >= MIN_TARGET and bottom - top >= MIN_TARGET, f"{where}: {c['name']!r} is {c['box']}"
        for label in c["labels"]:  # the key's letter and the muscle's name, whole inside their button
            assert _inside(label["box"], c["box"], 0), f"{where}: {c['name']!r}'s {label['text']!r} is cut"
            assert label["size"] >= (19 if label["cls"] == "key" else 14), f"{where}: {label}"
    if phase == "playing":
        assert {c["name"] for c in touch} == {*MUSCLES, "reset"}, where
        reach = look["reach"]
        assert reach is not None, f"{where}: the page does not say where the arm's reach is drawn"
        assert _inside(reach, look["canvas"]) and _inside(reach, screen), f"{where}: the reach {reach} is cut"
        for c in controls:
            assert not _overlap(reach, c["box"]), f"{where}: {c['name']!r} lies over the arm's reach"
        assert not _overlap(reach, look["status"]), f"{where}: the status line lies over the arm's reach"
        if look["head"] is not None:  # the lab's head: the trial, the instruction, what was said of the last reach
            assert _inside(look["head"], screen), f"{where}: the lab's head is cut: {look['head']}"
            assert not _overlap(reach, look["head"]), f"{where}: the lab's head lies over the scene"
            for c in controls:
                assert not _overlap(look["head"], c["box"]), f"{where}: {c['name']!r} lies over the lab's head"
        _arranged(look, size, {c["name"]: c["box"] for c in touch}, where)
    return look


def _arranged(look, size: tuple[int, int], boxes: dict, where: str) -> None:
    """The buttons where docs/teaching.md says: the shoulder's (d, f) under the left thumb and the elbow's (j, k)
    under the right, reset between; down both sides of the game on a phone held sideways, under it otherwise,
    one row on a tablet."""
    canvas = look["canvas"]
    if size[0] > size[1] and size[1] <= 600:  # a phone held sideways
        assert all(boxes[k][2] <= canvas[0] for k in "df") and all(boxes[k][0] >= canvas[2] for k in "jk"), where
        return
    assert all(b[1] >= canvas[3] for b in boxes.values()), f"{where}: a button is not under the game"
    if size[0] > 600:  # a tablet: one row, d f reset j k
        order = sorted(boxes, key=lambda k: boxes[k][0])
        assert order == ["d", "f", "reset", "j", "k"] and len({round(b[1]) for b in boxes.values()}) == 1, where
    else:  # a phone held upright: the thumbs' columns, reset between them
        assert max(boxes[k][2] for k in "df") <= boxes["reset"][0] <= boxes["reset"][2] <= min(
            boxes[k][0] for k in "jk"), where


def _debug(page) -> dict:
    return page.evaluate("document.getElementById('game').debug")


def _in_a_trial(page) -> None:
    """The lab's page moved on (its clock, a card's button) until a trial takes keys: one ending, its result
    shown, or a block's card ignores them."""
    for _ in range(200):
        if _debug(page)["phase"] == "reach":
            return
        if page.is_visible("#lab-go"):
            page.tap("#lab-go")
        run_for(page, 100)
    raise AssertionError(f"no trial took keys: {_debug(page)}")


def _fingers_drive_their_muscles(page, where: str, finger: list[int], lab: bool = False) -> None:
    """A finger on each muscle's button holds its key and pulls that muscle alone; one on reset resets (``lab``:
    each in a trial, where the lab's keys count)."""
    for i, key in enumerate(MUSCLES):
        if lab:
            _in_a_trial(page)
        finger[0] += 1
        button = f"#touch button[data-key='{key}']"
        page.dispatch_event(button, "pointerdown", {"pointerId": finger[0], "pointerType": "touch"})
        run_for(page, 200)
        held = _debug(page)
        page.dispatch_event(button, "pointerup", {"pointerId": finger[0], "pointerType": "touch"})
        run_for(page, 400)  # let go: the muscle relaxes before the next
        activation = held["activation"]
        assert held["held"] == [key], f"{where}: {key}: {held}"
        others = [a for j, a in enumerate(activation) if j != i]
        assert activation[i] > 0.5 and max(others) < 0.2, f"{where}: {key}: {held}"
        assert _debug(page)["held"] == [], where
    if lab:
        _in_a_trial(page)
    before = _debug(page)["resets"]
    finger[0] += 1
    page.dispatch_event("#reset", "pointerdown", {"pointerId": finger[0], "pointerType": "touch"})
    page.dispatch_event("#reset", "pointerup", {"pointerId": finger[0], "pointerType": "touch"})
    run_for(page, 100)
    assert _debug(page)["resets"] == before + 1, where


def _every_size(tmp_path, sizes: list[tuple[int, int]], end: bool = True, **device: object) -> None:
    """Joining, playing and (``end``) the end card at each of ``sizes`` in turn, in one context of ``device``."""
    with running_class(tmp_path / "class") as opened, \
            browser_page(*sizes[0], has_touch=True, is_mobile=True, **device) as page:
        errors = open_page(page, f"http://127.0.0.1:{opened.port}", still=True)
        page.wait_for_selector("#touch", state="visible")  # a coarse pointer at load shows the buttons
        for size in sizes:
            _resize(page, size)
            _check(page, size, "joining")
        _resize(page, sizes[0])
        join(page, opened.clerk.roster.code, "Aleksandra Nowakowska")
        page.dispatch_event("#game", "pointerdown", {"pointerId": 1, "pointerType": "touch"})  # "a tap starts"
        finger = [1]
        for size in sizes:
            _resize(page, size)
            _check(page, size, "playing")
            assert _debug(page)["phase"] == "playing"
            _fingers_drive_their_muscles(page, f"{size[0]}x{size[1]}", finger)
        if not end:
            assert errors == [] and page.dialogs == []
            return
        to_the_end(page)  # a whole game of the page's time: the costly part
        page.wait_for_selector("#end-answer:has-text('handed in: ')")
        for size in sizes:
            _resize(page, size)
            look = _check(page, size, "over")
            assert {c["name"] for c in look["controls"]} >= {"again", "not-me"}, look["controls"]
        assert errors == [] and page.dialogs == []


def _lab_every_size(tmp_path, sizes: list[tuple[int, int]], end: bool = True, **device: object) -> None:
    """The lab's screen (the teacher's switch on) at each of ``sizes``: its first card, the trials (the whole scene
    on the screen, under no control and under no words), each muscle's button pulling its muscle, home bringing the
    hand home, and (``end``) the end screen with its learning curve."""
    import json
    import urllib.request

    with running_class(tmp_path / "class") as opened, \
            browser_page(*sizes[0], has_touch=True, is_mobile=True, **device) as page:
        req = urllib.request.Request(f"http://127.0.0.1:{opened.port}/api/teacher/browserlab",
                                     data=json.dumps({"on": True}).encode(),
                                     headers={"Content-Type": "application/json"})
        urllib.request.urlopen(req, timeout=10).close()
        errors = open_page(page, f"http://127.0.0.1:{opened.port}", still=True)
        page.wait_for_selector("#touch", state="visible")
        join(page, opened.clerk.roster.code, "Aleksandra Nowakowska")
        page.wait_for_selector("#lab-card", state="visible")
        for size in sizes:
            _resize(page, size)
            look = _check(page, size, "lab card")
            assert "lab-go" in {c["name"] for c in look["controls"]}, f"{size}: the card's button is not on the screen"
        page.tap("#lab-go")
        finger = [1]
        for i, size in enumerate(sizes):
            _resize(page, size)
            _check(page, size, "playing")
            assert _debug(page)["phase"] in ("reach", "feedback"), _debug(page)
            if end or i == 0:  # the suite's cheap part drives the muscles at its first size only
                _fingers_drive_their_muscles(page, f"{size[0]}x{size[1]} (lab)", finger, lab=True)
        if end:
            for _ in range(3000):
                if page.is_visible("#lab-end"):
                    break
                if page.is_visible("#lab-card"):
                    page.tap("#lab-go")
                run_for(page, 260)
            page.wait_for_selector("#lab-answer:has-text('handed in: ')")
            for size in sizes:
                _resize(page, size)
                look = _check(page, size, "lab over")
                assert "lab-again" in {c["name"] for c in look["controls"]}, look["controls"]
                curve = page.evaluate("(() => { const b = document.getElementById('lab-curve').getBoundingClientRect();"
                                      " return [b.left, b.top, b.right, b.bottom]; })()")
                assert _inside(curve, [0, 0, *size]) and curve[3] - curve[1] > 40, f"{size}: the curve {curve}"
        assert errors == [] and page.dialogs == []


@pytest.mark.slow  # a whole lesson in chromium at every size (about 6 s); the suite's look is test_lab_page's
def test_the_labs_screen_on_every_phone_and_tablet_to_its_end(tmp_path):
    _lab_every_size(tmp_path, PHONES + TABLETS, device_scale_factor=2)


@pytest.mark.slow  # chromium (about 2 s): CI's slow tier, so the suite launches no chromium
def test_a_phone_upright_and_sideways_has_every_control_and_the_whole_reach_on_its_screen(tmp_path):
    """The quick part: the two ways a phone is held, joining and playing (the rest is CI's, below)."""
    _every_size(tmp_path, [(390, 844), (844, 390)], end=False, device_scale_factor=3)


@pytest.mark.slow  # a whole game in chromium (about 4 s): CI's slow tier
def test_on_every_phone_every_control_and_the_whole_reach_are_on_the_screen(tmp_path):
    _every_size(tmp_path, PHONES, device_scale_factor=3)


@pytest.mark.slow  # a whole game in chromium (about 3 s): CI's slow tier
def test_on_every_tablet_every_control_and_the_whole_reach_are_on_the_screen(tmp_path):
    _every_size(tmp_path, TABLETS, device_scale_factor=2)
