"""The class's browser game (/play) in headless chromium: what a frame costs, and what the page weighs.

    python benchmarks/browser_page.py                # 1024x768 and 1920x1080, 4 s of play each; the lab
    python benchmarks/browser_page.py --seconds 10 --json

The lab (the teacher's switch "Everyone's browser runs the lab" on): the same page running the class's ``lesson`` at
1024x768 under Chromium's CPU slowdown (CDP ``Emulation.setCPUThrottlingRate``, 4x by default: a Chromebook's),
keys held in turn and the hand brought home with space, its frames counted from its first card on; the goal is a
frame under 4 ms.

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
LAB_SIZE = (1024, 768)


def switch_lab_on(port: int) -> None:
    """The teacher's switch, from the teacher's own machine (loopback needs no secret)."""
    import urllib.request

    req = urllib.request.Request(f"http://127.0.0.1:{port}/api/teacher/browserlab", data=b'{"on": true}',
                                 headers={"Content-Type": "application/json"})
    urllib.request.urlopen(req, timeout=10).close()


def measure_lab(browser, base: str, code: str, seconds: float, throttle: float) -> dict[str, object]:
    """The lab's frames at LAB_SIZE under ``throttle`` x CPU slowdown, for ``seconds`` of real time: at each go cue a
    muscle pulled for a moment, the trial left to time out (its path shown), and the hand brought home."""
    page = browser.new_page(viewport={"width": LAB_SIZE[0], "height": LAB_SIZE[1]})
    weights: dict[str, int] = {}
    page.on("response", lambda r: weights.__setitem__(r.url.removeprefix(base), len(r.body())))
    cdp = page.context.new_cdp_session(page)
    cdp.send("Emulation.setCPUThrottlingRate", {"rate": throttle})
    page.goto(f"{base}/play")
    page.fill("#code", code)
    page.fill("#name", "bench lab")
    page.click("#join-button")
    page.wait_for_selector("#lab-card", state="visible")
    page.keyboard.press(" ")
    page.evaluate("document.getElementById('game').frameTimes.length = 0")  # the lab's frames only
    end = time.monotonic() + seconds
    i = 0
    while time.monotonic() < end:
        if page.is_visible("#lab-card"):
            page.keyboard.press(" ")
        page.wait_for_timeout(1100)  # the hold at home: the go cue
        page.keyboard.down(KEYS[i % 4])
        page.wait_for_timeout(250)
        page.keyboard.up(KEYS[i % 4])
        page.wait_for_timeout(3000)  # the time-out, then the path shown
        page.keyboard.press(" ")  # the hand home
        i += 1
    frames = page.evaluate("document.getElementById('game').frameTimes.slice()")
    trials = page.evaluate("document.getElementById('game').debug.done")
    page.close()
    frames.sort()
    lab_files = ("/static/labpage.js", "/static/labview.js", "/static/labmeasure.js", "/static/labengine.js")
    return {"size": f"{LAB_SIZE[0]}x{LAB_SIZE[1]} lab", "throttle": throttle, "frames": len(frames), "trials": trials,
            "lab_bytes": sum(weights.get(f, 0) for f in lab_files), "plan_bytes": weights.get("/api/labplan", 0),
            "frame_ms_median": round(statistics.median(frames), 3),
            "frame_ms_p95": round(frames[int(0.95 * (len(frames) - 1))], 3), "frame_ms_max": round(frames[-1], 3)}


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
    parser.add_argument("--throttle", type=float, default=4.0, help="the lab's CPU slowdown (CDP), 4x by default")
    parser.add_argument("--lab-seconds", type=float, default=20.0, help="real seconds of the lab")
    args = parser.parse_args(argv)
    if not args.throttle >= 1.0:
        parser.error(f"--throttle must be 1 or more, got {args.throttle:g}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp, running_class(Path(tmp) / "class") as opened, \
            sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path(), args=FLAGS)
        base = f"http://127.0.0.1:{opened.port}"
        for size in SIZES:
            rows.append(measure(browser, base, opened.clerk.roster.code, size, args.seconds))
        switch_lab_on(opened.port)
        lab = measure_lab(browser, base, opened.clerk.roster.code, args.lab_seconds, args.throttle)
        version = browser.version
        browser.close()
    if args.json:
        print(json.dumps({"chromium": version, "machine": platform.processor() or platform.machine(),
                          "rows": rows, "lab": lab}, indent=1))
        return 0
    print(f"chromium {version}, {platform.machine()}, {args.seconds:g} s of play at each size")
    for r in rows:
        print(f"{r['size']:>10}: frame {r['frame_ms_median']:.2f} ms median, {r['frame_ms_p95']:.2f} ms p95, "
              f"{r['frame_ms_max']:.2f} ms max ({r['frames']} frames); a frame every {r['interval_ms_median']:.1f} ms")
    print(f"{lab['size']:>14}: frame {lab['frame_ms_median']:.2f} ms median, {lab['frame_ms_p95']:.2f} ms p95, "
          f"{lab['frame_ms_max']:.2f} ms max ({lab['frames']} frames, {lab['trials']} trials) at "
          f"{lab['throttle']:g}x CPU slowdown; the lab's modules {lab['lab_bytes']:,} bytes, its plan "
          f"{lab['plan_bytes']:,}")
    files = rows[0]["files"]
    print(f"page over the wire: {rows[0]['page_bytes']:,} bytes, " +
          ", ".join(f"{name} {size:,}" for name, size in files.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
