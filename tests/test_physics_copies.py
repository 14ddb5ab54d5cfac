"""docs/development.md's table "The physics' copies" names every file that holds a copy of the arm's physics.

A file holds one where its code has RK4's weights (``2.0 * (v + u)``, or ``dt`` times a sixth), the muscles' first-order
step (``a += (g - a) * r``, its one form in every language), or the arm's sine's reduction constant (``INV_PIO2``).
A new copy, or a copy moved to another file, fails here until the table says where it is and which test holds it.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "development.md"

MARKERS = {
    "RK4's weights": re.compile(r"2\.0 \* \(\w+(\[\w+\])? \+ \w+(\[\w+\])?\)|\bdt \* \(1\.0 / 6\.0\)|\bdt / 6\.0"
                                r"|\b_?SIXTH\b"),
    "the muscles' step": re.compile(r"([\w.>-]+(\[[^\]]+\])*) \+= \(([\w.>-]+(\[[^\]]+\])*) - \1\) \* \w"),
    "the arm's sine": re.compile(r"INV_PIO2"),
}


def table_files() -> set[str]:
    """The files the table names (the ``armgame/...`` paths in its third column)."""
    text = DOC.read_text(encoding="utf-8")
    section = text.split("## The physics' copies", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ") and not line.startswith("| copy ")]
    assert len(rows) >= 10, "the table of the physics' copies is missing or cut short"
    files: set[str] = set()
    for row in rows:
        cells = [cell.strip() for cell in row.strip("|").split("|")]
        named = re.findall(r"`(armgame/[^`]+)`", cells[2])
        assert named, f"a row names no file: {row}"
        files.update(named)
    return files


@functools.cache
def holders() -> dict[str, list[str]]:
    """Every source file under armgame/ with a marker, and which."""
    found = {}
    for path in sorted((ROOT / "armgame").rglob("*")):
        if path.suffix not in (".py", ".c", ".h", ".js", ".mjs") or "__pycache__" in path.parts:
            continue
        code = path.read_text(encoding="utf-8")
        which = [name for name, marker in MARKERS.items() if marker.search(code)]
        if which:
            found[path.relative_to(ROOT).as_posix()] = which
    return found


def test_every_copy_of_the_physics_is_in_the_table():
    listed = table_files()
    missing = {path: which for path, which in holders().items() if path not in listed}
    assert not missing, f"docs/development.md's table of the physics' copies does not name: {missing}"


def test_the_table_names_files_that_exist_and_tests_that_exist():
    for path in table_files():
        assert (ROOT / path).is_file(), path
    section = DOC.read_text(encoding="utf-8").split("## The physics' copies", 1)[1].split("\n## ", 1)[0]
    for test in set(re.findall(r"`(tests/[\w/]+\.py)`", section)):
        assert (ROOT / test).is_file(), test


def test_the_markers_find_each_kind_of_copy():
    """The negative control: each marker finds the copies it is for, in each language (so a marker that stopped
    matching would not pass the table by finding nothing)."""
    found = holders()
    assert "RK4's weights" in found["armgame/physics/integrators.py"]
    assert "RK4's weights" in found["armgame/game/_cstep.h"] and "RK4's weights" in found["armgame/game/_lanes.h"]
    assert "RK4's weights" in found["armgame/classroom/static/engine.js"]
    assert "the muscles' step" in found["armgame/game/_lanes.h"]
    assert "the muscles' step" in found["armgame/lab/session.py"]
    assert "the arm's sine" in found["armgame/physics/_trig.h"] and "the arm's sine" in found["armgame/physics/trig.py"]
    assert len(found) >= 13  # 15 before labengine.js and _ccenter.c took their loops from engine.js and _cstep.h
