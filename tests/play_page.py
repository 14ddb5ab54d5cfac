"""Driving the class's browser game (/play) in a real chromium: joining, and playing a whole game on the page's
own clock (Playwright's ``page.clock``), so a 60 s game takes about a second and every run is the same game."""

from __future__ import annotations

import datetime

#: The page clamps a frame to 0.25 s (a stalled tab slows the game rather than jumping it): the clock is moved
#: on in jumps just over that, each one frame.
JUMP_MS = 260
#: (key, held for ms, then released for ms): the shoulder and the elbow in turn, and a reset, enough to move
#: the arm round the workspace.
PATTERN = (("d", 520, 260), ("j", 780, 260), ("f", 520, 0), ("k", 520, 520), ("space", 0, 260))


#: How far ahead of the wall clock a still page's clock is paused (``open_page``): more than any test lasts, so the
#: pause is never a jump into the page's past however slowly the machine runs.
STILL_AHEAD = datetime.timedelta(hours=1)


def open_page(page, base: str, still: bool = False) -> list[str]:
    """``/play`` at ``base`` on a clock the test moves; returns the list its console errors are added to.

    Playwright's installed clock also runs on by itself with the wall clock, so the game moves on between the
    test's steps by however long the machine took over them. ``still``: the clock paused before the page loads,
    so the page's time moves only when the test moves it (``run_for``) and the same steps play the same game on
    a machine under load as on an idle one."""
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"uncaught: {e}"))
    page.clock.install()
    if still:  # no page yet: the jump fires nothing
        page.clock.pause_at(datetime.datetime.now() + STILL_AHEAD)
    page.goto(f"{base}/play")
    return errors


def join(page, code: str, name: str) -> None:
    page.fill("#code", code)
    page.fill("#name", name)
    page.click("#join-button")
    page.wait_for_selector("#join", state="hidden")


def run_for(page, ms: int) -> None:
    """``ms`` of the page's time, in frames of at most ``JUMP_MS``."""
    while ms > 0:
        page.clock.fast_forward(min(ms, JUMP_MS))
        ms -= JUMP_MS


def play_keys(page, rounds: int = 2) -> None:
    """The countdown skipped by a key (not the game's input), then ``rounds`` of ``PATTERN`` on the keyboard."""
    page.keyboard.press("x")
    for _ in range(rounds):
        for key, hold, rest in PATTERN:
            name = " " if key == "space" else key
            page.keyboard.down(name)
            run_for(page, hold or 20)
            page.keyboard.up(name)
            run_for(page, rest)


def to_the_end(page) -> None:
    """The clock run out (61 s of page time at the most); the end card shown."""
    for _ in range(61_000 // JUMP_MS + 2):
        if page.is_visible("#end"):
            return
        page.clock.fast_forward(JUMP_MS)
    page.wait_for_selector("#end")
