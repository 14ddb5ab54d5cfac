"""Which characters a class's name check takes that Chromium draws as nothing: the whole-plane scan (issue 54).

    python benchmarks/name_scan.py                  # every code point; writes benchmarks/results/name_scan.json
    python benchmarks/name_scan.py --bmp --every 8  # a reduced scan (tests/test_names.py's slow one)

A class joins "Ann B"; for every code point c of Unicode (surrogates aside) the class's own join check
(``Clerk.check_new_name``) is asked about "Ann B" + c, with ``records.lookalikes.DRAWN_AS_NOTHING`` emptied, so
the characters this scan found before are scanned again. Each name it takes is drawn in headless Chromium (Debian's,
driven by Playwright as in the tests: ``tests/browser.py``), in the projector's fonts (the font stack of
``classroom/static/class.css``) at 32 px, black on white, as the text of an element (a canvas's ``fillText`` is
not the page's text: it draws U+FFFC as a box, which the page's text draws as nothing), and its pixels compared
with "Ann B" drawn alone: a name drawn the same is a character drawn as nothing after a name, which a classmate
could join beside it. Names are drawn many to a page, each in its own cell of a grid, clipped to it, at whole
pixel places, so each cell's pixels are those of the name alone: a batch is one screenshot, compared with numpy.

The result names the characters drawn as nothing, the counts, Chromium's version, the fonts asked for and the
time taken. Which characters are drawn as nothing depends on the fonts installed: the result says which machine.
"""

from __future__ import annotations

import argparse
import json
import platform
import re
import subprocess
import sys
import tempfile
import time
from datetime import date
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "tests"))

from browser import browser_page, close_shared  # noqa: E402

BASE = "Ann B"
RESULT = HERE / "results" / "name_scan.json"
CSS = ROOT / "armgame" / "classroom" / "static" / "class.css"
SIZE = 32
CELL = (12 * SIZE, 3 * SIZE)  # a name and a character of up to 9 em (U+FDFD is about 7): nothing crosses its cell
COLUMNS, ROWS = 10, 24

PAGE = """<!doctype html><meta charset="utf-8"><style>
body {{ margin: 0; background: #fff; color: #000; font: {size}px {font}; }}
#grid {{ display: grid; grid-template-columns: repeat({columns}, {width}px); grid-auto-rows: {height}px; }}
#grid div {{ overflow: hidden; white-space: pre; padding-left: {pad}px; line-height: {height}px; }}
</style><div id="grid"></div>"""
FILL = """(names) => document.getElementById("grid").replaceChildren(...names.map((name) => {
  const cell = document.createElement("div");
  cell.textContent = name;
  return cell;
}))"""


def font_stack() -> str:
    """The projector's font stack, as class.css gives it to the page's text."""
    found = re.search(r"font-family:\s*([^;]+);", CSS.read_text(encoding="utf-8"))
    assert found, f"{CSS} names no font-family"
    return found.group(1).strip()


def accepted(codes: range | list[int]) -> list[int]:
    """The code points c a class that has "Ann B" takes as the new name "Ann B" + c, with ``DRAWN_AS_NOTHING`` (this
    scan's own findings) left out of the check."""
    from armgame.classroom.errors import RefusedError
    from armgame.classroom.intake import Clerk
    from armgame.classroom.roster import Roster
    from armgame.records import lookalikes

    with tempfile.TemporaryDirectory() as folder:
        clerk = Clerk(Path(folder), Roster.open(Path(folder), None)[0])
        clerk.join(BASE, None, "127.0.0.2")
        found = lookalikes.DRAWN_AS_NOTHING
        lookalikes.DRAWN_AS_NOTHING = frozenset()
        try:
            taken = []
            for code in codes:
                if 0xD800 <= code <= 0xDFFF:
                    continue
                try:
                    clerk.check_new_name(BASE + chr(code))
                except RefusedError:
                    continue
                taken.append(code)
        finally:
            lookalikes.DRAWN_AS_NOTHING = found
    return taken


def same_as_first(shot: bytes, rows: int) -> list[int]:
    """The cells of a screenshot of the grid (a PNG) whose pixels are the first cell's, by index (0 aside)."""
    import io

    import numpy as np
    from PIL import Image

    width, height = CELL
    pixels = np.asarray(Image.open(io.BytesIO(shot)).convert("RGB"))[:rows * height, :COLUMNS * width]
    cells = pixels.reshape(rows, height, COLUMNS, width, 3).transpose(0, 2, 1, 3, 4).reshape(-1, height, width, 3)
    same = (cells == cells[0]).all(axis=(1, 2, 3))
    return [int(i) for i in np.flatnonzero(same) if i]


def drawn_as_nothing(codes: list[int], progress: bool = False) -> tuple[list[int], str]:
    """Those of ``codes`` that Chromium draws as nothing after "Ann B"; and Chromium's version. Each name is the
    text of an element, as the class's pages show names (``textContent``), one to a cell of a grid, clipped to it;
    a batch is one screenshot, compared with the first cell, which holds "Ann B" alone."""
    width, height = CELL
    batch = COLUMNS * ROWS - 1
    nothing: list[int] = []
    # The chromium of tests/browser.py, which a test's process shares: a second Playwright cannot start in a process
    # that runs one (its event loop stays marked running between calls), as a test worker does after a page's test.
    with browser_page(COLUMNS * width, ROWS * height) as page:
        page.set_content(PAGE.format(size=SIZE, font=font_stack(), columns=COLUMNS, width=width, height=height,
                                     pad=SIZE // 2))

        def draw(names: list[str]) -> list[int]:
            page.evaluate(FILL, [BASE, *names])
            rows = -(-(len(names) + 1) // COLUMNS)
            shot = page.screenshot(clip={"x": 0, "y": 0, "width": COLUMNS * width, "height": rows * height})
            return [i - 1 for i in same_as_first(shot, rows)]

        # The check of the check: the name alone is drawn as itself, a full stop after it is not nothing.
        assert draw([BASE, BASE + "."]) == [0]
        for start in range(0, len(codes), batch):
            chunk = codes[start:start + batch]
            nothing += [chunk[i] for i in draw([BASE + chr(c) for c in chunk])]
            if progress and start // batch % 50 == 0:
                print(f"  {start + len(chunk):,} of {len(codes):,} drawn, {len(nothing)} as nothing", flush=True)
        return nothing, page.context.browser.version


def fonts_installed() -> int | None:
    """How many font files fontconfig lists (what Chromium falls back on), or None without fc-list."""
    try:
        return len(subprocess.run(["fc-list"], capture_output=True, text=True, timeout=30).stdout.splitlines())
    except (OSError, subprocess.SubprocessError):
        return None


def scan(bmp: bool = False, every: int = 1, progress: bool = False) -> dict[str, object]:
    started = time.perf_counter()
    codes = accepted(range(0, 0x10000 if bmp else 0x110000, every))
    checked = time.perf_counter()
    nothing, version = drawn_as_nothing(codes, progress)
    return {
        "what": f'"{BASE}" + each code point a class\'s join takes after "{BASE}", drawn in Chromium and compared',
        "command": "python benchmarks/name_scan.py" + (" --bmp" if bmp else "") + (f" --every {every}" if every > 1
                                                                                  else ""),
        "code_points": "U+0000 to U+FFFF" if bmp else "U+0000 to U+10FFFF", "every": every,
        "scanned": len(codes),
        "drawn_as_nothing": [f"{c:04X}" for c in nothing],
        "chromium": version, "font": f"{SIZE}px {font_stack()}", "fonts_installed": fonts_installed(),
        "check_s": round(checked - started, 1), "draw_s": round(time.perf_counter() - checked, 1),
        "machine": {"system": platform.system(), "python": platform.python_version(),
                    "date": date.today().isoformat()},
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bmp", action="store_true", help="only the Basic Multilingual Plane (U+0000 to U+FFFF)")
    parser.add_argument("--every", type=int, default=1, help="every Nth code point (a sample)")
    parser.add_argument("--out", type=Path, default=None, help=f"where to write the result (default: {RESULT}, for "
                                                               f"the whole scan)")
    args = parser.parse_args(argv)
    if args.every < 1:
        parser.error("--every must be 1 or more")
    try:
        result = scan(args.bmp, args.every, progress=True)
    finally:
        close_shared()
    out = args.out or (RESULT if not args.bmp and args.every == 1 else None)
    text = json.dumps(result, indent=1, ensure_ascii=False) + "\n"
    if out is not None:
        out.write_text(text, encoding="utf-8")
    print(text, end="")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
