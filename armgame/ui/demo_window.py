"""The demo window (pygame): plays a demo's run at real time, with pause, restart and playback speed.

The only demo module that imports pygame. Physics advances in fixed steps from an accumulator of real
time (``time.perf_counter``, injectable so tests never sleep), scaled by the playback speed; the drawing
interpolates joint angles between the last two steps. The scene is drawn on an 800 x 800 surface and
scaled to the (resizable) window, so a projector's resolution changes nothing but sharpness; the window
opens no larger than the desktop, and F11 fills the screen. Every text drawn is recorded
(``text_boxes``), so the tests check that none is cut or overlaps another at any window size.
"""

from __future__ import annotations

import math
import os
import time
from collections import deque
from collections.abc import Callable
from typing import Any

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
import numpy as np
import pygame

from ..demos.catalog import get_info
from ..demos.reach import COMPONENTS, ReachRun
from ..demos.runs import VISIBLY_APART
from .display import open_window, toggle_fullscreen

SCENE_SIZE = (800, 800)
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0)
#: The arrows skip this far in simulated time; a snapshot is kept every SKIP_SECONDS, so a skip back
#: restores one and runs at most SKIP_SECONDS again, however long the demo has run.
SKIP_SECONDS = 5.0
#: The keys every demo window offers, as its help line says them (one set with the replays').
HELP = ("p pause", "r restart", "-/+ speed", "1 real speed", f"left/right {SKIP_SECONDS:g} s", "F11 fullscreen",
        "Esc quit")
#: Longest real time one frame may account for: after a stall (a dragged window) the demo skips ahead
#: instead of running hundreds of catch-up steps in one frame.
MAX_FRAME_TIME = 0.25

BACKGROUND = (255, 255, 255)
INK = (20, 20, 28)
FAINT = (85, 85, 95)  # help text: 7:1 on white, still 4.5:1 once smoothscaled
LINK = (45, 50, 62)
ARM_B = (255, 127, 14)
TRAIL = (140, 180, 225)
TRAIL_B = (255, 200, 150)
PATH = (200, 200, 205)
# Vertical-plane arms hang from a shoulder near the centre; the horizontal reach uses the game's layout.
VERTICAL_LAYOUT = ((400, 450), 400.0)
HORIZONTAL_LAYOUT = ((400, 570), 500.0)  # the game's scale, raised to leave room for the bars
PLANNING_LAYOUT = ((330, 540), 450.0)  # the reach left of centre, its speed plot on the right
SPEED_PLOT = pygame.Rect(560, 290, 220, 170)
SHORT_LABELS = {
    "own_inertial": "own inertia",
    "interaction_inertial": "interaction, inertial",
    "coriolis_centrifugal": "interaction, Coriolis",
    "gravity": "gravity",
    "damping": "damping",
}


def _rgb(hex_colour: str) -> tuple[int, int, int]:
    return int(hex_colour[1:3], 16), int(hex_colour[3:5], 16), int(hex_colour[5:7], 16)


def _tick_step(scale: float) -> float:
    """A round tick spacing (1, 2 or 5 times a power of ten) giving one to three ticks each side of zero."""
    magnitude = 10.0 ** math.floor(math.log10(scale))
    return next(m * magnitude for m in (5.0, 2.0, 1.0, 0.5) if scale / (m * magnitude) >= 1.0)


class DemoWindow:
    """One demo on screen. ``frame()`` handles events, advances the physics and draws once."""

    def __init__(self, name: str, run: Any, speed: float = 1.0, clock: Callable[[], float] = time.perf_counter,
                 size: tuple[int, int] | None = None, fullscreen: bool = False) -> None:
        self.info = get_info(name)
        self.name = name
        self.run = run
        self.speed = speed
        self.clock = clock
        self.size = size or SCENE_SIZE
        self.fullscreen = fullscreen
        self.windowed_size = self.size
        #: Every text of the last frame: (text, rectangle in scene pixels).
        self.placed: list[tuple[str, Any]] = []
        self.paused = False
        self.accumulator = 0.0
        self.last_time: float | None = None
        self.shoulder, self.pixels_per_metre = VERTICAL_LAYOUT if self.info.vertical else HORIZONTAL_LAYOUT
        if name == "planning":
            self.shoulder, self.pixels_per_metre = PLANNING_LAYOUT
        self.trails: list[deque[tuple[float, float]]] = []
        self.parted_at: float | None = None
        self.screen: Any = None
        self._snapshots: dict[int, tuple[Any, Any]] = {}

    # ------------------------------------------------------------------ lifecycle
    def open(self) -> None:
        self.screen = open_window(self.size, self.fullscreen, self.info.title, SCENE_SIZE)
        self.size = self.windowed_size = self.screen.get_size()
        self.scene = pygame.Surface(SCENE_SIZE)
        # Sized so that the smallest text is still 14 px tall in a window 720 px high (the scene scaled 0.9).
        self.caption_font = pygame.font.Font(None, 36)
        self.status_font = pygame.font.Font(None, 32)
        self.small_font = pygame.font.Font(None, 26)
        self.caption_lines = self._wrap(self.info.caption, self.caption_font, SCENE_SIZE[0] - 40)
        self.restart()

    def close(self) -> None:
        pygame.display.quit()

    def restart(self) -> None:
        self.run.reset()
        self.accumulator = 0.0
        self.last_time = None
        self.parted_at = None
        self._snapshots = {}
        self._clear_trails()

    def _clear_trails(self) -> None:
        keep = 2500 if self.name == "passive" else 90
        self.trails = [deque(maxlen=keep) for _ in self.run.states]

    def _step(self) -> None:
        """One physics step, keeping a snapshot every SKIP_SECONDS for the arrows to come back to."""
        run = self.run
        if run.steps % self._skip_steps() == 0:
            self._snapshots[run.steps] = (run.states, run.previous)
        run.step()

    def _skip_steps(self) -> int:
        return max(1, round(SKIP_SECONDS / self.run.dt))

    def skip(self, seconds: float) -> None:
        """Left and right: SKIP_SECONDS back (from the last snapshot before) or forth (run at once)."""
        run = self.run
        target = max(0, run.steps + round(seconds / run.dt))
        if target < run.steps:
            base = max(k for k in self._snapshots if k <= target)  # step 0 is always there once run
            run.states, run.previous = self._snapshots[base]
            run.steps = base
            if self.parted_at is not None and self.parted_at > target * run.dt:
                self.parted_at = None
        while run.steps < target:
            self._step()
        self.accumulator = 0.0
        self._clear_trails()
        if self.name == "chaos" and self.parted_at is None and run.hand_distance() > VISIBLY_APART:
            self.parted_at = run.t

    # --------------------------------------------------------------------- input
    def handle(self, event: Any) -> bool:
        """Apply one pygame event; False means quit."""
        if event.type == pygame.QUIT:
            return False
        if event.type == pygame.VIDEORESIZE:
            self.size = (max(200, event.w), max(200, event.h))
            if not self.fullscreen:
                self.windowed_size = self.size
        if event.type != pygame.KEYDOWN:
            return True
        key = event.key
        if key == pygame.K_ESCAPE:
            return False
        if key == pygame.K_F11:
            self.screen = toggle_fullscreen(self.windowed_size)
            self.fullscreen = bool(self.screen.get_flags() & pygame.FULLSCREEN)
            self.size = self.screen.get_size()
        elif key == pygame.K_p:
            self.paused = not self.paused
            self.last_time = None  # a pause must not count as elapsed time
        elif key == pygame.K_r:
            self.restart()
        elif key in (pygame.K_PLUS, pygame.K_EQUALS, pygame.K_KP_PLUS):
            self.speed = next((s for s in SPEEDS if s > self.speed * 1.001), self.speed)
        elif key in (pygame.K_MINUS, pygame.K_KP_MINUS):
            self.speed = next((s for s in reversed(SPEEDS) if s < self.speed / 1.001), self.speed)
        elif key in (pygame.K_LEFT, pygame.K_RIGHT):
            self.skip(SKIP_SECONDS if key == pygame.K_RIGHT else -SKIP_SECONDS)
        elif key == pygame.K_1:
            self.speed = 1.0
        return True

    # ------------------------------------------------------------------- physics
    def advance(self) -> None:
        now = self.clock()
        if self.last_time is None or self.paused:
            self.last_time = now
            return
        elapsed = min(max(now - self.last_time, 0.0), MAX_FRAME_TIME)
        self.last_time = now
        self.accumulator += elapsed * self.speed
        dt = self.run.dt
        while self.accumulator >= dt:
            self._step()
            self.accumulator -= dt
        if self.name == "chaos" and self.parted_at is None and self.run.hand_distance() > VISIBLY_APART:
            self.parted_at = self.run.t

    def poses(self) -> list[tuple[float, float]]:
        """Joint angles of each arm, interpolated between the last two physics steps."""
        alpha = min(self.accumulator / self.run.dt, 1.0)
        return [(p[0] + alpha * (c[0] - p[0]), p[1] + alpha * (c[1] - p[1]))
                for p, c in zip(self.run.previous, self.run.states, strict=True)]

    # ---------------------------------------------------------------- geometry
    def to_scene(self, point: tuple[float, float]) -> tuple[int, int]:
        x, y = point
        k = self.pixels_per_metre
        return round(self.shoulder[0] + x * k), round(self.shoulder[1] - y * k)

    def view(self) -> tuple[float, tuple[int, int]]:
        """Scale from scene to window and the scene's top-left corner in the window."""
        w, h = self.size
        scale = min(w / SCENE_SIZE[0], h / SCENE_SIZE[1])
        return scale, (round((w - SCENE_SIZE[0] * scale) / 2), round((h - SCENE_SIZE[1] * scale) / 2))

    def to_window(self, point: tuple[float, float]) -> tuple[int, int]:
        """Where a point (m) of the arm's plane appears in the window, in pixels."""
        sx, sy = self.to_scene(point)
        scale, (ox, oy) = self.view()
        return round(ox + sx * scale), round(oy + sy * scale)

    # ------------------------------------------------------------------ drawing
    @staticmethod
    def _wrap(text: str, font: Any, width: int) -> list[str]:
        lines, line = [], ""
        for word in text.split():
            trial = f"{line} {word}".strip()
            if line and font.size(trial)[0] > width:
                lines.append(line)
                line = word
            else:
                line = trial
        return [*lines, line]

    def _text(self, text: str, font: Any, colour: tuple[int, int, int], pos: tuple[int, int],
              anchor: str = "topleft") -> None:
        surface = font.render(text, True, colour)
        rect = surface.get_rect(**{anchor: pos})
        self.scene.blit(surface, rect)
        self.placed.append((text, rect))

    def text_boxes(self) -> list[tuple[str, Any]]:
        """The last frame's texts and their rectangles in window pixels."""
        scale, (ox, oy) = self.view()
        return [(text, pygame.Rect(round(ox + r.left * scale), round(oy + r.top * scale),
                                   round(r.width * scale), round(r.height * scale))) for text, r in self.placed]

    def _draw_arm(self, points: list[tuple[int, int]], colour: tuple[int, int, int], width: int,
                  hand_radius: int) -> None:
        pygame.draw.lines(self.scene, colour, False, points, width)
        for p in points[1:-1]:
            pygame.draw.circle(self.scene, colour, p, width // 2 + 2)
        pygame.draw.circle(self.scene, INK if colour == LINK else colour, points[-1], hand_radius)

    def _status(self) -> str:
        run = self.run
        if self.name == "pendulum":
            q1, _, w1, _ = run.states[0]
            return f"angle {q1 * 57.29578 + 90:6.1f} deg from hanging   velocity {w1 * 57.29578:6.0f} deg/s"
        if self.name == "passive":
            q1, q2, _, _ = run.states[0]
            return f"shoulder {q1 * 57.29578:6.1f} deg   elbow {q2 * 57.29578:6.1f} deg"
        if self.name == "chaos":
            d = run.hand_distance()
            if self.parted_at is not None:
                return f"hands {d:.2f} m apart: parted at t = {self.parted_at:.1f} s"
            return f"hands {d:.1e} m apart"
        if self.name == "planning":
            jerk, torque_change = run.hand_speeds_now()
            return f"hand speed {jerk:4.2f} m/s (min jerk)   {torque_change:4.2f} m/s (min torque change)"
        return f"hand speed {run.hand_speed_now():.2f} m/s" + ("   (vertical plane, gravity on)" if run.gravity
                                                               else "   (horizontal plane)")

    def _draw_bars(self, run: ReachRun) -> None:
        parts, total = run.torques_now()
        # One N m scale for both joints, as in the figure, so the shoulder's larger torques look larger.
        scale = max(run.torque_scales())
        rows = [(SHORT_LABELS[k], parts[k], _rgb(c)) for k, _, c in COMPONENTS
                if (k != "gravity" or run.gravity) and k != "damping"]
        rows.append(("TOTAL", total, INK))
        row_h, half = (28 if len(rows) <= 4 else 25), 120
        top = SCENE_SIZE[1] - 58 - (len(rows) + 1) * row_h
        centres = (400, 660)
        for x, joint in zip(centres, ("shoulder", "elbow"), strict=True):
            self._text(f"{joint} (N m)", self.small_font, INK, (x, top), "midtop")
        for r, (label, values, colour) in enumerate(rows):
            y = top + row_h + r * row_h
            self._text(label, self.small_font, INK, (20, y + 3))
            for x, v in zip(centres, values, strict=True):
                length = round(half * v / scale)
                pygame.draw.rect(self.scene, colour, pygame.Rect(min(x, x + length), y, abs(length), row_h - 6))
                # The value on the side the bar leaves free, so it never runs into the other joint's bars.
                self._text(f"{v:+.1f}", self.small_font, INK, (x - 4, y + 3) if v >= 0 else (x + 4, y + 3),
                           "topright" if v >= 0 else "topleft")
        axis_y = top + (len(rows) + 1) * row_h - 2
        step = _tick_step(scale)
        for x in centres:
            pygame.draw.line(self.scene, FAINT, (x, top + row_h - 2), (x, axis_y), 1)
            pygame.draw.line(self.scene, FAINT, (x - half, axis_y), (x + half, axis_y), 1)
            for k in range(-int(scale // step), int(scale // step) + 1):
                tx = x + round(half * k * step / scale)
                pygame.draw.line(self.scene, FAINT, (tx, axis_y), (tx, axis_y + 5), 1)
                self._text(f"{k * step:g}", self.small_font, FAINT, (tx, axis_y + 6), "midtop")

    def _draw_planning(self, run: Any) -> None:
        """Both planned paths, the start and target, and the two speed profiles with a moving cursor."""
        for path, colour in zip(run.paths, (TRAIL, TRAIL_B), strict=True):
            pygame.draw.lines(self.scene, colour, False, [self.to_scene(tuple(p)) for p in path[::5]], 4)
        for end in (run.planning.start, run.planning.target):
            pygame.draw.circle(self.scene, PATH, self.to_scene(end), 14, 3)
        box = SPEED_PLOT
        top = max(float(np.max(s)) for s in run.speeds)
        pygame.draw.line(self.scene, FAINT, box.bottomleft, box.bottomright, 1)
        pygame.draw.line(self.scene, FAINT, box.bottomleft, box.topleft, 1)
        self._text("hand speed (m/s)", self.small_font, INK, (box.left, box.top - 6), "bottomleft")
        for value, y in ((0.0, box.bottom), (top, box.top)):
            self._text(f"{value:.1f}", self.small_font, FAINT, (box.left - 4, y), "midright")
        every = max(1, len(run.speeds[0]) // 220)
        for speeds, colour in zip(run.speeds, (LINK, ARM_B), strict=True):
            points = [(box.left + round(box.width * i / len(speeds)), box.bottom - round(box.height * v / top))
                      for i, v in list(enumerate(speeds))[::every]]
            pygame.draw.lines(self.scene, colour, False, points, 3)
        cursor = box.left + round(box.width * (run.steps % len(run.speeds[0])) / len(run.speeds[0]))
        pygame.draw.line(self.scene, FAINT, (cursor, box.top), (cursor, box.bottom), 1)
        self._text("out", self.small_font, FAINT, (box.left + box.width // 4, box.bottom + 4), "midtop")
        self._text("back", self.small_font, FAINT, (box.left + 3 * box.width // 4, box.bottom + 4), "midtop")
        y = SCENE_SIZE[1] - 92
        for colour, text in ((LINK, "minimum jerk: straight, bell-shaped speed"),
                             (ARM_B, "minimum torque change: the arm's dynamics curve it")):
            pygame.draw.line(self.scene, colour, (20, y + 9), (48, y + 9), 5)
            self._text(text, self.small_font, INK, (56, y))
            y += 26

    def draw(self) -> None:
        scene = self.scene
        scene.fill(BACKGROUND)
        self.placed = []
        run = self.run
        poses = self.poses()
        arms = [[self.to_scene(p) for p in run.arm_points(q1, q2)] for q1, q2 in poses]
        for trail, arm in zip(self.trails, arms, strict=True):
            trail.append(arm[-1])
        if isinstance(run, ReachRun):
            path = [self.to_scene(tuple(p)) for p in run.table.hand[:: max(1, len(run.table.hand) // 200)]]
            pygame.draw.lines(scene, PATH, False, path, 5)
            for end in (run.plan.home, run.plan.target):
                pygame.draw.circle(scene, PATH, self.to_scene(end), 14, 3)
            self._draw_bars(run)
        if self.name == "planning":
            self._draw_planning(run)
        for trail, colour in zip(self.trails, (TRAIL, TRAIL_B), strict=False):
            if len(trail) > 1:
                pygame.draw.lines(scene, colour, False, list(trail), 3)
        pygame.draw.circle(scene, FAINT, self.shoulder, 11)
        self._draw_arm(arms[0], LINK, 12, 10)
        if len(arms) > 1:
            self._draw_arm(arms[1], ARM_B, 5, 6)
        y = 12
        for line in self.caption_lines:
            self._text(line, self.caption_font, INK, (20, y))
            y += 31
        speed = f"{self.speed:g}x" + ("   PAUSED" if self.paused else "")
        self._text(f"t = {run.t:5.2f} s   speed {speed}", self.status_font, INK, (20, y + 8))
        self._text(self._status(), self.status_font, INK, (20, y + 36))
        self._text("   ".join(("p resume", *HELP[1:]) if self.paused else HELP), self.small_font, FAINT,
                   (SCENE_SIZE[0] - 12, SCENE_SIZE[1] - 8), "bottomright")
        screen = pygame.display.get_surface()
        scale, offset = self.view()
        size = (round(SCENE_SIZE[0] * scale), round(SCENE_SIZE[1] * scale))
        shown = scene if size == SCENE_SIZE else pygame.transform.smoothscale(scene, size)
        # Shrinking turns white into 252 grey; margins of the same colour hide the scene's edge.
        screen.fill(shown.get_at((0, 0)))
        screen.blit(shown, offset)

    def frame(self) -> bool:
        for event in pygame.event.get():
            if not self.handle(event):
                return False
        self.advance()
        self.draw()
        pygame.display.flip()
        return True


def run_window(name: str, run: Any, speed: float = 1.0, clock: Callable[[], float] = time.perf_counter,
               max_frames: int | None = None, frame_rate: float | None = 60.0, size: tuple[int, int] | None = None,
               fullscreen: bool = False) -> DemoWindow:
    """Open the window and play demo ``name`` until Esc or close (or ``max_frames`` frames)."""
    window = DemoWindow(name, run, speed=speed, clock=clock, size=size, fullscreen=fullscreen)
    window.open()
    # Clock.tick only paces the frames (it sleeps); the physics reads ``clock`` instead.
    pacer = pygame.time.Clock()
    frames = 0
    try:
        while window.frame():
            frames += 1
            if max_frames is not None and frames >= max_frames:
                break
            if frame_rate:
                pacer.tick(frame_rate)
    finally:
        window.close()
    return window
