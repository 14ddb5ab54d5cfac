"""The demo window (pygame): plays a demo's run at real time, with pause, restart and playback speed.

The only demo module that imports pygame. Physics advances in fixed steps from an accumulator of real
time (``time.perf_counter``, injectable so tests never sleep), scaled by the playback speed; the drawing
interpolates joint angles between the last two steps. The scene is drawn on a surface 800 px high and
as wide as the window's shape (``scene_shape``), then scaled to the (resizable) window, so a projector's
resolution changes nothing but sharpness and no band of the window is left empty; the arm's reach is
framed in the room the texts leave (``frame_content``). The window opens as large as the desktop
allows, and F11 fills the screen. The arm is the game's (``armgame.ui.body``). Every text drawn is recorded
(``text_boxes``), so the tests check that none is cut or overlaps another at any window size.
"""

from __future__ import annotations

import itertools
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
from .body import draw_arm, draw_torso
from .display import open_window, toggle_fullscreen
from .playback import MAX_FRAME, PLAYBACK_HELP, SKIP_SECONDS, skip_sign, speed_after
from .render import PALETTES

SCENE_SIZE = (800, 800)
#: The scene's shorter side, in pixels: the longer one follows the window's shape.
SCENE_SIDE = 800
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0)
#: The arrows skip SKIP_SECONDS in simulated time; a snapshot is kept every SKIP_SECONDS, so a skip back
#: restores one and runs at most SKIP_SECONDS again, however long the demo has run.
#: The keys every demo window offers, as its help line says them (one set with the replays').
HELP = ("p pause", "r restart", *PLAYBACK_HELP, "F11 fullscreen", "Esc quit")

BACKGROUND = (255, 255, 255)
INK = (20, 20, 28)
FAINT = (85, 85, 95)  # help text: 7:1 on white, still 4.5:1 once smoothscaled
LINK = (45, 50, 62)
# Lines a class must see: 3:1 or more on white (WCAG's rule for graphics), 4 px in the scene.
ARM_B = (213, 94, 0)
TRAIL = (30, 136, 200)
TRAIL_B = (213, 94, 0)
PATH = (120, 126, 138)
LINE = 4
SPEED_PLOT_SIZE = (220, 170)
BODY_PALETTE = PALETTES["okabe-ito"]
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
        self.size = size
        self.fullscreen = fullscreen
        self.windowed_size = self.size or SCENE_SIZE
        #: Every text of the last frame: (text, rectangle in scene pixels).
        self.placed: list[tuple[str, Any]] = []
        self.paused = False
        self.accumulator = 0.0
        self.last_time: float | None = None
        self.scene_size = SCENE_SIZE
        self.help_extra = 0
        self.shoulder, self.pixels_per_metre = (400.0, 450.0), 400.0
        self.speed_plot = pygame.Rect((560, 290), SPEED_PLOT_SIZE)
        self.reach = self.content_box()
        self.trails: list[deque[tuple[float, float]]] = []
        self.parted_at: float | None = None
        self.screen: Any = None
        self._snapshots: dict[int, tuple[Any, Any]] = {}

    # ------------------------------------------------------------------ lifecycle
    def open(self) -> None:
        self.screen = open_window(self.size, self.fullscreen, self.info.title, (1200, 800))
        self.size = self.windowed_size = self.screen.get_size()
        # Sized so that the smallest text is 2.5% of the window's height or more (20 px of the scene's 800).
        self.caption_font = pygame.font.Font(None, 40)
        self.status_font = pygame.font.Font(None, 34)
        self.small_font = pygame.font.Font(None, 30)
        self.frame_content()
        self.restart()

    @staticmethod
    def scene_shape(size: tuple[int, int]) -> tuple[int, int]:
        """The scene's size for a window of ``size``: 800 px on its shorter side, the window's shape."""
        w, h = max(size[0], 1), max(size[1], 1)
        return (round(SCENE_SIDE * w / h), SCENE_SIDE) if w >= h else (SCENE_SIDE, round(SCENE_SIDE * h / w))

    def content_box(self) -> tuple[float, float, float, float]:
        """What the arm can cover, in metres (xmin, xmax, ymin, ymax) about the shoulder: the whole reach
        for a swinging arm, the cycle's arm and paths for a prescribed reach; and the body's width."""
        run = self.run
        if self.info.vertical:
            points = run.arm_points(*run.initials[0][:2])
            reach = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
            return -reach - 0.06, reach + 0.06, -reach - 0.06, reach + 0.06
        xs, ys = [0.0], [0.0]
        for table in run.tabulated_states():
            for q1, q2 in table[:: max(1, len(table) // 60), :2]:
                for x, y in run.arm_points(float(q1), float(q2)):
                    xs.append(x)
                    ys.append(y)
        pad = 0.06
        return min(xs) - pad, max(xs) + pad, min(min(ys), -0.12) - pad, max(ys) + pad

    def frame_content(self) -> None:
        """Lay the scene out for the window's shape: the texts at the edges, and the arm's reach scaled
        into the room they leave, centred."""
        self.scene_size = self.scene_shape(self.size or SCENE_SIZE)
        w, h = self.scene_size
        self.scene = pygame.Surface(self.scene_size)
        self.caption_lines = self._wrap(self.info.caption, self.caption_font, w - 40)
        top = 12 + 31 * len(self.caption_lines) + 76
        self.help_extra = 26 * (len(self.help_lines()) - 1)  # a help line that wraps pushes the rest up
        bottom = h - 44 - self.help_extra
        right = w - 20
        if isinstance(self.run, ReachRun):
            bottom -= (len(self._bar_rows(self.run)) + 1) * self._row_height(self.run) + 54
        if self.name == "planning":
            bottom = h - 104 - self.help_extra
            right = w - SPEED_PLOT_SIZE[0] - 60
            self.speed_plot = pygame.Rect((w - SPEED_PLOT_SIZE[0] - 20, top + 40), SPEED_PLOT_SIZE)
        xmin, xmax, ymin, ymax = self.reach
        room = pygame.Rect(20, top, right - 20, max(bottom - top, 40))
        k = min(room.width / (xmax - xmin), room.height / (ymax - ymin))
        self.pixels_per_metre = k
        self.shoulder = (room.centerx - (xmin + xmax) / 2 * k, room.centery + (ymin + ymax) / 2 * k)
        self.room = room

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
        elif (speed := speed_after(pygame.key.name(key).lower(), self.speed, SPEEDS)) is not None:
            self.speed = speed
        elif skip_sign(pygame.key.name(key).lower()):
            self.skip(SKIP_SECONDS * skip_sign(pygame.key.name(key).lower()))
        return True

    # ------------------------------------------------------------------- physics
    def advance(self) -> None:
        now = self.clock()
        if self.last_time is None or self.paused:
            self.last_time = now
            return
        elapsed = min(max(now - self.last_time, 0.0), MAX_FRAME)
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

    def reach_rect(self) -> Any:
        """The framed reach, in window pixels (the tests check it against the texts and the window)."""
        xmin, xmax, ymin, ymax = self.reach
        (x0, y0), (x1, y1) = self.to_window((xmin, ymax)), self.to_window((xmax, ymin))
        return pygame.Rect(x0, y0, x1 - x0, y1 - y0)

    def view(self) -> tuple[float, tuple[int, int]]:
        """Scale from scene to window and the scene's top-left corner in the window."""
        w, h = self.size or SCENE_SIZE
        sw, sh = self.scene_size
        scale = min(w / sw, h / sh)
        return scale, (round((w - sw * scale) / 2), round((h - sh * scale) / 2))

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

    def help_lines(self) -> list[str]:
        """The keys that work (actions: "p resume" while paused), on as few lines as the scene's width
        holds (a narrow window: two)."""
        lines: list[str] = []
        for item in ("p resume", *HELP[1:]) if self.paused else HELP:
            if lines and self.small_font.size(lines[-1] + "   " + item)[0] <= self.scene_size[0] - 24:
                lines[-1] += "   " + item
            else:
                lines.append(item)
        return lines

    def _draw_body(self, pose: tuple[float, float], points: list[tuple[int, int]]) -> None:
        """The game's arm (``armgame.ui.body``): seen from above with its torso in the horizontal demos,
        hanging from a fixed shoulder in the vertical ones; its muscles at rest (nothing drives them)."""
        q1, q2 = pose
        k = self.pixels_per_metre
        world = self.run.arm_points(q1, q2)
        if len(world) < 3:  # the pendulum: one link, no elbow
            pygame.draw.circle(self.scene, FAINT, self.shoulder, 11)
            self._draw_arm(points, LINK, 14, 12)
            return
        l1, l2 = math.dist(world[0], world[1]), math.dist(world[1], world[2])
        if not self.info.vertical:
            draw_torso(self.scene, self.shoulder, k, BODY_PALETTE)
        else:
            pygame.draw.circle(self.scene, FAINT, self.shoulder, max(11, round(0.06 * k)))
        draw_arm(self.scene, self.shoulder, k, q1, q2, l1, l2, (0.0, 0.0, 0.0, 0.0), BODY_PALETTE,
                 torso=not self.info.vertical)
        pygame.draw.aacircle(self.scene, INK, points[-1], max(8, round(0.018 * k)))

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

    @staticmethod
    def _bar_rows(run: ReachRun) -> list[str]:
        return [k for k, _, _ in COMPONENTS if (k != "gravity" or run.gravity) and k != "damping"] + ["TOTAL"]

    @classmethod
    def _row_height(cls, run: ReachRun) -> int:
        return 28 if len(cls._bar_rows(run)) <= 4 else 25

    def _draw_bars(self, run: ReachRun) -> None:
        parts, total = run.torques_now()
        # One N m scale for both joints, as in the figure, so the shoulder's larger torques look larger.
        scale = max(run.torque_scales())
        rows = [(SHORT_LABELS[k], parts[k], _rgb(c)) for k, _, c in COMPONENTS
                if (k != "gravity" or run.gravity) and k != "damping"]
        rows.append(("TOTAL", total, INK))
        row_h, half = self._row_height(run), 120
        top = self.scene_size[1] - 58 - self.help_extra - (len(rows) + 1) * row_h
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
        box = self.speed_plot
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
        y = self.scene_size[1] - 92 - self.help_extra
        for colour, text in ((LINK, "minimum jerk: straight, bell-shaped speed"),
                             (ARM_B, "minimum torque change: the arm's dynamics curve it")):
            pygame.draw.line(self.scene, colour, (20, y + 9), (48, y + 9), 5)
            self._text(text, self.small_font, INK, (56, y))
            y += 26

    def draw(self) -> None:
        if self.scene_size != self.scene_shape(self.size or SCENE_SIZE):
            self.frame_content()  # a new window shape: the scene laid out again for it
            for trail in self.trails:
                trail.clear()
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
            pygame.draw.lines(scene, PATH, False, path, LINE)
            for end in (run.plan.home, run.plan.target):
                pygame.draw.circle(scene, PATH, self.to_scene(end), 14, LINE)
            self._draw_bars(run)
        if self.name == "planning":
            self._draw_planning(run)
        for trail, colour in zip(self.trails, (TRAIL, TRAIL_B), strict=False):
            if len(trail) > 1:
                pygame.draw.lines(scene, colour, False, list(trail), LINE)
        self._draw_body(poses[0], arms[0])
        if len(arms) > 1:
            self._draw_arm(arms[1], ARM_B, 6, 7)
        y = 12
        for line in self.caption_lines:
            self._text(line, self.caption_font, INK, (20, y))
            y += 31
        speed = f"{self.speed:g}x" + ("   PAUSED" if self.paused else "")
        self._text(f"t = {run.t:5.2f} s   speed {speed}", self.status_font, INK, (20, y + 8))
        self._text(self._status(), self.status_font, INK, (20, y + 36))
        y = self.scene_size[1] - 8
        for line in reversed(self.help_lines()):
            self._text(line, self.small_font, FAINT, (self.scene_size[0] - 12, y), "bottomright")
            y -= 26
        screen = pygame.display.get_surface()
        scale, offset = self.view()
        size = (round(self.scene_size[0] * scale), round(self.scene_size[1] * scale))
        shown = scene if size == self.scene_size else pygame.transform.smoothscale(scene, size)
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
