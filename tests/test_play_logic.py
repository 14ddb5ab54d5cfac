"""The browser game's modules in Node, in the default tier: tests/play_logic.test.mjs (``node --test``, no npm
packages) runs the class's API and the outbox (outbox.js, with a fake class and a fake store), the game on the
page's clock (model.js) and the scene's layout and the HUD's words (view.js) without a browser; and what the page
draws with is held to the Python's: view.js's palette to ``ui/palette.py``'s high-contrast one, as are the buttons'
and the HUD's bars' colours in play.css; its line, clock and hit times to ``ui/render.py``'s; body.js's sizes and
outlines to ``ui/body.py``'s.

Skipped only where ``node`` is missing and ``ARMGAME_REQUIRE_BROWSER`` is unset (CI sets it)."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest
from node import node, skip_without_node

ROOT = Path(__file__).resolve().parent.parent
STATIC = ROOT / "armgame" / "classroom" / "static"
skip_without_node("the browser game's modules are not checked here")


def test_the_pages_modules_pass_their_node_tests():
    done = node("--test", str(ROOT / "tests" / "play_logic.test.mjs"), cwd=STATIC)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert re.search(r"^# fail 0$", done.stdout, re.M) and not re.search(r"^# pass 0$", done.stdout, re.M), done.stdout


#: Poses and activations the outlines are compared at: (muscle, q1, q2, activation).
POSES = [(0, 0.785, 1.571, 0.0), (1, -0.3, 2.4, 0.5), (2, 1.9, 0.2, 1.0), (3, 0.1, 2.9, 0.25)]

LOOKS = """
import * as view from './view.js';
import * as model from './model.js';
import * as body from './body.js';
const poses = %s, l1 = 0.34, l2 = 0.46;
process.stdout.write(JSON.stringify({
  palette: view.PALETTE,
  render: {MIN_LINE: view.MIN_LINE, WARN_SECONDS: view.WARN_SECONDS, FLASH_TIME: model.FLASH_TIME,
    PLUS_ONE_TIME: model.PLUS_ONE_TIME, FADE_IN: model.FADE_IN},
  body: {UPPER_ARM: body.UPPER_ARM, FOREARM: body.FOREARM, HAND: body.HAND, MUSCLE_REST: body.MUSCLE_REST,
    MUSCLE_GAIN: body.MUSCLE_GAIN, BREADTH: body.BREADTH, MUSCLE_TINT: body.MUSCLE_TINT, TORSO: body.TORSO,
    HEAD: body.HEAD},
  spindle: body.SPINDLE,
  muscles: poses.map(([i, q1, q2, a]) => body.muscleOutline(i, q1, q2, l1, l2, a)),
  limbs: poses.map(([, q1]) => body.limbOutline([0, 0], [l1 * Math.cos(q1), l1 * Math.sin(q1)], body.UPPER_ARM)),
  palms: poses.map(([, q1, q2, a]) => body.palm([0.1, 0.2],
    [0.1 + 0.2 * Math.cos(q1 + q2), 0.2 + 0.2 * Math.sin(q1 + q2)], a)),
}));
"""


def _close(js, py, where: str) -> None:
    """Outlines to within a few ulps: JavaScript's ``**`` and sine need not round as the C library's do."""
    assert len(js) == len(py), where
    for a, b in zip(js, py, strict=True):
        assert a == pytest.approx(list(b), rel=1e-12, abs=1e-15), where


def test_the_pages_looks_are_the_pythons():
    pytest.importorskip("pygame")
    from armgame.ui import body, render
    from armgame.ui.palette import PALETTES

    done = node("--input-type=module", "-e", LOOKS % json.dumps(POSES), cwd=STATIC)
    assert done.returncode == 0, done.stderr
    looks = json.loads(done.stdout)
    high = PALETTES["high-contrast"]
    assert looks["palette"], "view.js has no palette"
    for name, colour in looks["palette"].items():
        python = getattr(high, name)
        assert colour == ([list(c) for c in python] if name == "muscles" else list(python)), name
    # The touch buttons' colours, the HUD's bars' and the warning's, in play.css, are the palette's too.
    css = (STATIC / "play.css").read_text(encoding="utf-8")
    muscles = dict(enumerate(map(list, high.muscles)))
    for where in (r"#touch button", r"#hud \.bar"):
        found = re.findall(where + r'\[data-index="(\d)"\][^{]*\{[^}]*background: rgb\((\d+), (\d+), (\d+)\)', css)
        assert {int(i): [int(c) for c in rgb] for i, *rgb in found} == muscles, where
    track = re.search(r"#hud \.track \{[^}]*background: rgb\((\d+), (\d+), (\d+)\)", css)
    assert [int(c) for c in track.groups()] == list(high.bar_back)
    warn = re.search(r"--warn: #([0-9a-f]{6})", css).group(1)
    assert [int(warn[k:k + 2], 16) for k in (0, 2, 4)] == list(high.warn)
    for name, value in looks["render"].items():
        assert value == getattr(render, name), name
    for name, value in looks["body"].items():
        assert value == json.loads(json.dumps(getattr(body, name))), name
    assert len(looks["spindle"]) == body.SPINDLE_POINTS
    _close(looks["spindle"], body._SPINDLE, "the spindle")
    l1, l2 = 0.34, 0.46
    for (i, q1, q2, a), js in zip(POSES, looks["muscles"], strict=True):
        _close(js, body.muscle_outline(i, q1, q2, l1, l2, a), f"muscle {i}")
    for (_, q1, _, _), js in zip(POSES, looks["limbs"], strict=True):
        _close(js, body.limb_outline((0.0, 0.0), (l1 * math.cos(q1), l1 * math.sin(q1)), body.UPPER_ARM), "limb")
    for (_, q1, q2, a), js in zip(POSES, looks["palms"], strict=True):
        hand = (0.1 + 0.2 * math.cos(q1 + q2), 0.2 + 0.2 * math.sin(q1 + q2))
        _close(js, body._palm((0.1, 0.2), hand, a), "palm")


LAB_LOOKS = """
import * as labview from './labview.js';
const named = Object.entries(labview).filter(([k]) => k === k.toUpperCase());  // its constants, not its functions
process.stdout.write(JSON.stringify(Object.fromEntries(named)));
"""
#: labview.js's colours and the Python lab window's each stands for: the high-contrast palette's (``ui/palette.py``,
#: by field) or ``ui/lab_window.py``'s own (by constant). One colour of the page draws what the window draws in
#: several of the palette's, all alike in the high-contrast one: INK the text, the targets' rings, the ideal line,
#: the hand and the cursor (lab_window.CURSOR); PAPER the scene and the panels.
LAB_COLOURS = {"INK": ("ink", "edge", "hand", "CURSOR"), "PAPER": ("scene", "panel"), "TARGET": ("target",),
               "TRAIL": ("trail",), "WARN": ("warn",), "BAR_BACK": ("bar_back",), "HOME": ("HOME",),
               "HIT": ("HIT",)}
#: labview.js's colours that differ from the Python's on purpose, by name, with why (none today).
LAB_DIFFERS: dict[str, str] = {}


def _rgb(colour) -> list[int]:
    """[r, g, b] of a page's colour: "rgb(r,g,b)" or [r, g, b]."""
    if isinstance(colour, str):
        found = re.fullmatch(r"rgb\((\d+), ?(\d+), ?(\d+)\)", colour)
        assert found, colour
        return [int(c) for c in found.groups()]
    return list(colour)


def test_the_labs_colours_are_the_lab_windows():
    """labview.js's hand-copied palette, held to the lab window's: each colour to the high-contrast palette's fields
    or lab_window.py's constants it stands for, the muscles' bars to the palette's muscles, and the learning curve's
    block shading to lab_panels.draw_curve's blend of the panel (a perturbed block towards the target, the others
    towards ``link`` by turns). A colour added to labview.js must be named here."""
    pytest.importorskip("pygame")
    from armgame.ui import lab_window
    from armgame.ui.body import blend
    from armgame.ui.palette import PALETTES

    done = node("--input-type=module", "-e", LAB_LOOKS, cwd=STATIC)
    assert done.returncode == 0, done.stderr
    looks = json.loads(done.stdout)
    high = PALETTES["high-contrast"]
    assert set(looks) == {*LAB_COLOURS, "MUSCLES", "BLOCK_SHADES"}, "labview.js's colours are not all named here"
    for name, stands_for in LAB_COLOURS.items():
        if name in LAB_DIFFERS:
            continue
        for python in stands_for:
            colour = getattr(lab_window, python) if python.isupper() else getattr(high, python)
            assert _rgb(looks[name]) == list(colour), f"labview.js's {name} is not the lab window's {python}"
    assert [_rgb(c) for c in looks["MUSCLES"]] == [list(c) for c in high.muscles], "the muscles' colours"
    shades = {"perturbed": blend(high.panel, high.target, 0.16), "even": blend(high.panel, high.link, 0.07),
              "odd": blend(high.panel, high.link, 0.11)}
    assert {k: _rgb(c) for k, c in looks["BLOCK_SHADES"].items()} == {k: list(c) for k, c in shades.items()}
