"""The class's browser game (/play) in headless chromium: what a frame costs, and what the page weighs.

    python benchmarks/browser_page.py                # 1024x768 and 1920x1080, 4 s of play each
    python benchmarks/browser_page.py --seconds 10 --json

A real class on loopback (a thread of this process); Debian's chromium, driven by Playwright as in the tests
(tests/browser.py), software-rendered (``--disable-gpu``, as on a school laptop without a usable GPU driver).
The page joins, its countdown is skipped, and keys are held in turn (the arm moving, the bars filling) for
``--seconds`` of real time on the page's real clock. "Frame" is the page's own count: the time from the start
of its ``requestAnimationFrame`` callback to the end of its drawing calls (the physics steps due, the layout,
the canvas drawn), the last 600 frames; the interval between frames says whether it keeps the display's rate
(headless chromium runs at 60 Hz). The raster of the canvas into the window happens after the callback, on the
compositor: not in these figures.

"Weight" is every response the page loads over the wire (its HTML, CSS, script, the engine and the icon),
bodies as sent: the class serves them uncompressed.
"""

from __future__ import annotations

import argparse
import itertools
import json
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from browser import FLAGS, chromium_path  # noqa: E402
from class_server import running_class  # noqa: E402

SIZES = ((1024, 768), (1920, 1080))
KEYS = ("d", "j", "f", "k")


def measure(browser, base: str, code: str, size: tuple[int, int], seconds: float) -> dict[str, object]:
    page = browser.new_page(viewport={"width": size[0], "height": size[1]})
    weights: dict[str, int] = {}
    page.on("response", lambda r: weights.__setitem__(r.url.removeprefix(base), len(r.body())))
    page.goto(f"{base}/play")
    page.fill("#code", code)
    page.fill("#name", f"bench {size[0]}")
    page.click("#join-button")
    page.wait_for_selector("#join", state="hidden")
    page.keyboard.press("x")  # the countdown skipped
    end = time.monotonic() + seconds
    i = 0
    while time.monotonic() < end:
        page.keyboard.down(KEYS[i % 4])
        page.wait_for_timeout(400)
        page.keyboard.up(KEYS[i % 4])
        i += 1
    frames = page.evaluate("document.getElementById('game').frameTimes.slice()")
    intervals = page.evaluate("new Promise(done => { const t = []; const tick = (now) => { t.push(now);"
                              " if (t.length < 121) requestAnimationFrame(tick); else done(t); };"
                              " requestAnimationFrame(tick); })")
    page.close()
    gaps = [b - a for a, b in itertools.pairwise(intervals)]
    frames.sort()
    return {"size": f"{size[0]}x{size[1]}", "frames": len(frames),
            "frame_ms_median": round(statistics.median(frames), 3),
            "frame_ms_p95": round(frames[int(0.95 * (len(frames) - 1))], 3), "frame_ms_max": round(frames[-1], 3),
            "interval_ms_median": round(statistics.median(gaps), 2),
            "page_bytes": sum(v for k, v in weights.items() if not k.startswith("/api/")),
            "files": {k: v for k, v in sorted(weights.items()) if not k.startswith("/api/")}}


def main(argv: list[str] | None = None) -> int:
    from playwright.sync_api import sync_playwright

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=4.0, help="real seconds of play at each size")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp, running_class(Path(tmp) / "class") as opened, \
            sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path(), args=FLAGS)
        base = f"http://127.0.0.1:{opened.port}"
        for size in SIZES:
            rows.append(measure(browser, base, opened.clerk.roster.code, size, args.seconds))
        version = browser.version
        browser.close()
    if args.json:
        print(json.dumps({"chromium": version, "machine": platform.processor() or platform.machine(),
                          "rows": rows}, indent=1))
        return 0
    print(f"chromium {version}, {platform.machine()}, {args.seconds:g} s of play at each size")
    for r in rows:
        print(f"{r['size']:>10}: frame {r['frame_ms_median']:.2f} ms median, {r['frame_ms_p95']:.2f} ms p95, "
              f"{r['frame_ms_max']:.2f} ms max ({r['frames']} frames); a frame every {r['interval_ms_median']:.1f} ms")
    files = rows[0]["files"]
    print(f"page over the wire: {rows[0]['page_bytes']:,} bytes, " +
          ", ".join(f"{name} {size:,}" for name, size in files.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
