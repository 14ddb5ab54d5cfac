"""The demo window (pygame): plays a demo's run at real time, with pause, restart and playback speed.

The only demo module that imports pygame. Physics advances in fixed steps from an accumulator of real
time (``time.perf_counter``, injectable so tests never sleep), scaled by the playback speed; the drawing
interpolates joint angles between the last two steps. The scene is drawn at the (resizable) window's
own size and pixels (``scene_shape``), its sizes in proportion to its shorter side (``px``: the pixels of
an 800 px one) and its text to its height (the smallest 2.5% of it, times the settings' ``text_scale``),
in the settings' palette; the arm's reach is framed in the room the texts leave (``frame_content``).
What never moves is drawn once per size (``_static_layer``). With no size asked, the window opens in the
desktop's shape, as large as it allows (a 4:3 projector, a 4:3 window), and F11 fills the screen. The
arm is the game's (``armgame.ui.body``). Every text drawn is recorded (``text_boxes``), so the tests
check that none is cut or overlaps another at any window size.
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
from .render import MIN_LINE, MIN_TEXT_FRACTION, PALETTES

SCENE_SIZE = (800, 800)
#: The scene's shorter side, in pixels: the longer one follows the window's shape.
SCENE_SIDE = 800
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0)
#: The arrows skip SKIP_SECONDS in simulated time; a snapshot is kept every SKIP_SECONDS, so a skip back
#: restores one and runs at most SKIP_SECONDS again, however long the demo has run.
#: The keys every demo window offers, as its help line says them (one set with the replays').
HELP = ("p pause", "r restart", *PLAYBACK_HELP, "F11 fullscreen", "Esc quit")

# The scene's colours are the settings' palette (``armgame.ui.palette``); these mark the second arm and
# its path, which the captions call orange whatever the palette.
# Lines a class must see: 3:1 or more on white (WCAG's rule for graphics), 4 px in the scene.
ARM_B = (213, 94, 0)
TRAIL_B = (213, 94, 0)
LINE = 4
SPEED_PLOT_SIZE = (220, 170)
#: The planning demo's legend: each path's colour (None: the palette's arm colour, dark) and what it shows.
LEGEND = ((None, "minimum jerk: straight, bell-shaped speed"),
          (ARM_B, "minimum torque change: the arm's dynamics curve it"))
#: The rows' labels in short words, for a narrow window (the caption names the interaction torques).
NARROW_LABELS = {
    "own_inertial": "own",
    "interaction_inertial": "inter. inertial",
    "coriolis_centrifugal": "inter. Coriolis",
    "gravity": "gravity",
}
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
    """One demo on screen. ``frame()`` handles events, advances the physics and draws once.

    What never moves (the background, the planned paths, the speed plot, the bars' axes, the caption
    and the help line) is drawn once per scene size into a layer of its own (``static_builds`` counts
    them); a frame copies it and draws only what moves over it."""

    def __init__(self, name: str, run: Any, speed: float = 1.0, clock: Callable[[], float] = time.perf_counter,
                 size: tuple[int, int] | None = None, fullscreen: bool = False, palette: str = "okabe-ito",
                 text_scale: float = 1.0) -> None:
        self.info = get_info(name)
        self.name = name
        self.run = run
        self.speed = speed
        self.clock = clock
        self.size = size
        self.fullscreen = fullscreen
        #: The settings' palette and text scale (a bright room's high-contrast, a large room's 1.5).
        self.palette = PALETTES.get(palette, PALETTES["okabe-ito"])
        self.text_scale = text_scale
        self.windowed_size = self.size or SCENE_SIZE
        #: Every text of the last frame: (text, rectangle in scene pixels).
        self.placed: list[tuple[str, Any]] = []
        self.paused = False
        self.accumulator = 0.0
        self.last_time: float | None = None
        self.scene_size = SCENE_SIZE
        self.shoulder, self.pixels_per_metre = (400.0, 450.0), 400.0
        self.speed_plot = pygame.Rect((560, 290), SPEED_PLOT_SIZE)
        self.reach = self.content_box()
        self.trails: list[deque[tuple[float, float]]] = []
        self.parted_at: float | None = None
        self.screen: Any = None
        self._snapshots: dict[int, tuple[Any, Any]] = {}
        self._fonts: dict[int, Any] = {}
        self._sized: tuple = (None, (40, 34, 30))
        self._rendered: dict[tuple[str, int, tuple[int, int, int]], Any] = {}
        self._static: Any = None
        self._static_key: tuple | None = None
        self._static_placed: list[tuple[str, Any]] = []
        #: How many times the static layer was drawn (once per scene size and pause state).
        self.static_builds = 0
        self._laid_out: tuple | None = None

    # ------------------------------------------------------------------ lifecycle
    def open(self) -> None:
        # A 4:3 projector gets a 4:3 window: the desktop's own shape, as large as it allows.
        self.screen = open_window(self.size, self.fullscreen, self.info.title, None)
        self.size = self.windowed_size = self.screen.get_size()
        self.frame_content()
        self.restart()

    @staticmethod
    def scene_shape(size: tuple[int, int]) -> tuple[int, int]:
        """The scene's size for a window of ``size``: the window's own, drawn at its pixels (never scaled:
        text scaled up to a 1920 x 1080 projector came out blurred, and the scaling cost a frame 1.4 ms)."""
        return max(size[0], 1), max(size[1], 1)

    def px(self, pixels: float) -> int:
        """``pixels`` of a scene 800 px on its shorter side, in this scene's pixels."""
        return max(1, round(pixels * min(self.scene_size) / SCENE_SIDE))

    @property
    def line(self) -> int:
        """Paths and trails: 4 px at 800 lines, never under MIN_LINE."""
        return max(MIN_LINE, self.px(LINE))

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

    # -------------------------------------------------------------------- text
    def font(self, size: int) -> Any:
        """pygame's default font at ``size`` (its nominal size; lines are about 0.7 of it high)."""
        font = self._fonts.get(size)
        if font is None:
            font = self._fonts[size] = pygame.font.Font(None, size)
        return font

    def _nominal(self, height: int) -> int:
        """The smallest nominal size whose lines are ``height`` px or more."""
        size = max(1, round(height / 0.7))
        while size > 1 and self.font(size - 1).get_height() >= height:
            size -= 1
        while self.font(size).get_height() < height:
            size += 1
        return size

    def _sizes(self) -> tuple[int, int, int]:
        """Font sizes (caption, status, small): the smallest text 2.5% of the window's height (20 px of
        800, 19 of 768; a tall window's text with its height), the others 1.13 and 1.33 times it, all
        times ``text_scale``."""
        key = (self.scene_size[1], self.text_scale)
        if self._sized[0] != key:
            small = math.ceil(MIN_TEXT_FRACTION * self.scene_size[1] * self.text_scale - 1e-9)
            self._sized = (key, (self._nominal(round(small * 4 / 3)), self._nominal(round(small * 34 / 30)),
                                 self._nominal(small)))
        return self._sized[1]

    def _wrap_words(self, text: str, size: int, width: int) -> list[str]:
        return self._wrap(text, self.font(size), width)

    def _wrap_parts(self, parts: list[str], size: int, width: int) -> list[str]:
        """Parts (never split) on as few lines as ``width`` holds, three spaces apart."""
        lines: list[str] = []
        for part in parts:
            if lines and self.font(size).size(lines[-1] + "   " + part)[0] <= width:
                lines[-1] += "   " + part
            else:
                lines.append(part)
        return lines

    def _fit(self, text: str, size: int, width: int) -> str:
        font = self.font(size)
        if font.size(text)[0] <= width:
            return text
        while text and font.size(text + "...")[0] > width:
            text = text[:-1]
        return text + "..."

    def _status_lines(self, width: int) -> list[str]:
        """The clock and speed on a line, then what the demo measures (each wrapped between its parts)."""
        speed = f"{self.speed:g}x" + ("   PAUSED" if self.paused else "")
        size = self._sizes()[1]
        return self._wrap_parts([f"t = {self.run.t:5.2f} s", f"speed {speed}"], size, width) + \
            self._wrap_parts(self._status().split("   "), size, width)

    # ------------------------------------------------------------------ layout
    def frame_content(self) -> None:
        """Lay the scene out for the window's shape and the text size: the texts at the edges, and the
        arm's reach scaled into the room they leave, centred."""
        self.scene_size = self.scene_shape(self.size or SCENE_SIZE)
        w, h = self.scene_size
        caption, status, small = self._sizes()
        small_h = self.font(small).get_linesize() + 2
        gap = max(4, round(6 * small / 30))
        self.margin = margin = self.px(20)
        self.scene = pygame.Surface(self.scene_size)
        self.caption_lines = self._wrap_words(self.info.caption, caption, w - 2 * margin)
        self.edge = self.px(12)  # the caption's top, the help line's bottom
        # Two pixels between lines: scaled down to a small window, rounding never makes them touch.
        self.caption_pitch = self.font(caption).get_linesize() + 2
        self.status_top = self.edge + self.caption_pitch * len(self.caption_lines) + gap
        self.status_pitch = self.font(status).get_linesize() + 2
        # Room for the status as it reads now, and for chaos's longer line once the arms have parted.
        longest = self._status_lines(w - 2 * margin)
        if self.name == "chaos":
            longest = self._wrap_parts([*longest, "parted at t = 00.0 s"], status, w - 2 * margin)
        self.status_rows = len(longest)
        top = self.status_top + self.status_pitch * self.status_rows + 2 * gap
        self.help_pitch = small_h
        bottom = h - self.edge - small_h * len(self.help_lines()) - gap
        right = w - margin
        self.bar_geometry = None
        if isinstance(self.run, ReachRun):
            bottom = self._lay_out_bars(bottom, gap)
        if self.name == "planning":
            bottom, right = self._lay_out_planning(top, bottom, gap)
        xmin, xmax, ymin, ymax = self.reach
        room = pygame.Rect(margin, top, right - margin, max(bottom - top, 40))
        k = min(room.width / (xmax - xmin), room.height / (ymax - ymin))
        self.pixels_per_metre = k
        self.shoulder = (room.centerx - (xmin + xmax) / 2 * k, room.centery + (ymin + ymax) / 2 * k)
        self.room = room
        self._static_key = None

    def _lay_out_bars(self, bottom: int, gap: int) -> int:
        """The torque bars' block above the help line: a column of row labels as wide as the widest,
        then both joints side by side; returns the room's new bottom."""
        run = self.run
        small = self._sizes()[2]
        font = self.font(small)
        line = font.get_linesize()
        value_w = font.size("+88.8")[0] + gap
        needed = max(font.size("shoulder (N m)")[0] + 2 * gap, 3 * value_w)  # one joint's header and bars
        # Each row's label beside its bars where both joints still have room (in short words if it must),
        # else on a line above them (a tall, narrow window with large text).
        for names in (SHORT_LABELS, NARROW_LABELS, SHORT_LABELS):
            rows = [names.get(k, k) for k in self._bar_rows(run)]
            label_w = max(font.size(r)[0] for r in rows) + 2 * gap
            stacked = (self.scene_size[0] - 2 * self.margin - label_w) // 2 < needed
            if not stacked:
                break
        self.bar_labels = rows
        left = self.margin + (0 if stacked else label_w)
        row_h = 2 * line + 3 if stacked else line + gap
        span = (self.scene_size[0] - self.margin - left) // 2
        centres = (left + span // 2, left + span + span // 2)
        half = max(20, span // 2 - value_w // 2 - gap)
        block_h = (len(rows) + 1) * row_h + line + gap
        top = bottom - block_h
        # (top, row pitch, the joints' centres, half a bar's span, the bars' offset in their row)
        self.bar_geometry = (top, row_h, centres, half, line + 1 if stacked else 0)
        return top - gap

    def _lay_out_planning(self, top: int, bottom: int, gap: int) -> tuple[int, int]:
        """The speed plot (beside the arm on a wide scene, under it on a tall one) and the legend; returns
        the room's new bottom and right edge."""
        small = self._sizes()[2]
        font = self.font(small)
        line = font.get_linesize() + 2
        w, h = self.scene_size
        t = small / 30
        # The legend's two entries, each wrapped beside its line's sample (a narrow scene: two lines each).
        width = w - 2 * self.margin - round(36 * t)
        self.legend = [(colour, self._wrap_words(text, small, width)) for colour, text in LEGEND]
        bottom -= sum(len(lines) for _, lines in self.legend) * line + 2 * gap
        self.legend_top = bottom
        axis_w = font.size("0.0")[0] + 2 * gap
        plot_w, plot_h = round(SPEED_PLOT_SIZE[0] * t), round(SPEED_PLOT_SIZE[1] * t)
        if w >= 1.2 * h:
            # Its "out" and "back" below it stay above the legend.
            plot_h = min(plot_h, bottom - 2 * gap - line - (top + line + gap))
            self.speed_plot = pygame.Rect(w - self.margin - plot_w, top + line + gap, plot_w, plot_h)
            return bottom - gap, self.speed_plot.left - axis_w - 2 * self.margin
        plot_w, plot_h = min(w - 2 * self.margin - axis_w, round(plot_w * 1.5)), min(plot_h, round(0.15 * h))
        self.speed_plot = pygame.Rect(w - self.margin - plot_w, bottom - gap - line - plot_h, plot_w, plot_h)
        return self.speed_plot.top - line - 3 * gap, w - self.margin


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

    def _render(self, text: str, size: int, colour: tuple[int, int, int]) -> Any:
        key = (text, size, colour)
        surface = self._rendered.get(key)
        if surface is None:
            if len(self._rendered) > 512:  # the clock and the speeds make new strings every frame
                self._rendered.clear()
            surface = self._rendered[key] = self.font(size).render(text, True, colour)
        return surface

    def _text(self, text: str, size: int, colour: tuple[int, int, int], pos: tuple[int, int],
              anchor: str = "topleft", target: Any = None, placed: list | None = None) -> None:
        surface = self._render(text, size, colour)
        rect = surface.get_rect(**{anchor: pos})
        (self.scene if target is None else target).blit(surface, rect)
        (self.placed if placed is None else placed).append((text, rect))

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
        pygame.draw.circle(self.scene, self.palette.ink if colour == self.palette.link else colour, points[-1],
                           hand_radius)

    def help_lines(self) -> list[str]:
        """The keys that work (actions: "p resume" while paused), on as few lines as the scene's width
        holds (a narrow window: two)."""
        items = ["p resume", *HELP[1:]] if self.paused else list(HELP)
        return self._wrap_parts(items, self._sizes()[2], self.scene_size[0] - 24)

    def _draw_body(self, pose: tuple[float, float], points: list[tuple[int, int]]) -> None:
        """The game's arm (``armgame.ui.body``): seen from above in the horizontal demos (its torso is in
        the static layer), hanging from a fixed shoulder in the vertical ones; its muscles at rest."""
        q1, q2 = pose
        k = self.pixels_per_metre
        p = self.palette
        world = self.run.arm_points(q1, q2)
        if len(world) < 3:  # the pendulum: one link, no elbow
            pygame.draw.circle(self.scene, p.faint, self.shoulder, self.px(11))
            self._draw_arm(points, p.link, self.px(14), self.px(12))
            return
        l1, l2 = math.dist(world[0], world[1]), math.dist(world[1], world[2])
        if self.info.vertical:
            pygame.draw.circle(self.scene, p.faint, self.shoulder, max(11, round(0.06 * k)))
        draw_arm(self.scene, self.shoulder, k, q1, q2, l1, l2, (0.0, 0.0, 0.0, 0.0), p,
                 torso=not self.info.vertical)
        pygame.draw.aacircle(self.scene, p.ink, points[-1], max(8, round(0.018 * k)))

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
                return f"hands {d:.2f} m apart:   parted at t = {self.parted_at:.1f} s"
            return f"hands {d:.1e} m apart"
        if self.name == "planning":
            jerk, torque_change = run.hand_speeds_now()
            return f"hand speed {jerk:4.2f} m/s (min jerk)   {torque_change:4.2f} m/s (min torque change)"
        return f"hand speed {run.hand_speed_now():.2f} m/s" + ("   (vertical plane, gravity on)" if run.gravity
                                                               else "   (horizontal plane)")

    @staticmethod
    def _bar_rows(run: ReachRun) -> list[str]:
        return [k for k, _, _ in COMPONENTS if (k != "gravity" or run.gravity) and k != "damping"] + ["TOTAL"]

    # ----------------------------------------------------------- the static layer
    def _static_layer(self) -> Any:
        """What never moves at this scene size and pause state, drawn once: the background, the
        planned paths and the speed plot, the bars' axes and labels, the torso, caption and help."""
        key = (self.scene_size, self.paused, self.palette.name)
        if self._static is not None and self._static_key == key:
            return self._static
        self.static_builds += 1
        p = self.palette
        layer = pygame.Surface(self.scene_size)
        layer.fill(p.scene)
        placed: list[tuple[str, Any]] = []
        caption, _, small = self._sizes()
        run = self.run
        if isinstance(run, ReachRun):
            path = [self.to_scene(tuple(pt)) for pt in run.table.hand[:: max(1, len(run.table.hand) // 200)]]
            pygame.draw.lines(layer, p.edge, False, path, self.line)
            for end in (run.plan.home, run.plan.target):
                pygame.draw.circle(layer, p.edge, self.to_scene(end), self.px(14), self.line)
            self._static_bars(layer, placed, small)
        if self.name == "planning":
            self._static_planning(layer, placed, small)
        if not self.info.vertical and len(run.arm_points(*run.states[0][:2])) >= 3:
            draw_torso(layer, self.shoulder, self.pixels_per_metre, p)
        y = self.edge
        for line in self.caption_lines:
            self._text(line, caption, p.ink, (self.margin, y), target=layer, placed=placed)
            y += self.caption_pitch
        lines = self.help_lines()
        y = self.scene_size[1] - self.edge - self.help_pitch * (len(lines) - 1)
        for line in lines:  # the help line last: the tests read the keys from the last text drawn
            self._text(line, small, p.faint, (self.scene_size[0] - self.edge, y), "bottomright", layer, placed)
            y += self.help_pitch
        self._static, self._static_key, self._static_placed = layer, key, placed
        return layer

    def _static_bars(self, layer: Any, placed: list, small: int) -> None:
        p = self.palette
        run = self.run
        top, row_h, centres, half, offset = self.bar_geometry
        rows = self.bar_labels
        scale = max(run.torque_scales())
        for x, joint in zip(centres, ("shoulder", "elbow"), strict=True):
            self._text(f"{joint} (N m)", small, p.ink, (x, top + row_h - self.font(small).get_linesize() - 4),
                       "midtop", layer, placed)
        for r, label in enumerate(rows):
            self._text(label, small, p.ink, (self.margin, top + row_h + r * row_h + (0 if offset else 3)),
                       target=layer, placed=placed)
        axis_y = top + (len(rows) + 1) * row_h - 2
        step = _tick_step(scale)
        for x in centres:
            pygame.draw.line(layer, p.faint, (x, top + row_h - 2), (x, axis_y), 1)
            pygame.draw.line(layer, p.faint, (x - half, axis_y), (x + half, axis_y), 1)
            for k in range(-int(scale // step), int(scale // step) + 1):
                tx = x + round(half * k * step / scale)
                pygame.draw.line(layer, p.faint, (tx, axis_y), (tx, axis_y + 5), 1)
                self._text(f"{k * step:g}", small, p.faint, (tx, axis_y + 6), "midtop", layer, placed)

    def _static_planning(self, layer: Any, placed: list, small: int) -> None:
        """Both planned paths (dark: minimum jerk, orange: minimum torque change, as the caption and the
        legend say), their ends, the speed plot's axes and curves, and the legend."""
        p = self.palette
        run = self.run
        for path, colour in zip(run.paths, (p.link, ARM_B), strict=True):
            pygame.draw.lines(layer, colour, False, [self.to_scene(tuple(pt)) for pt in path[::5]], self.line)
        for end in (run.planning.start, run.planning.target):
            pygame.draw.circle(layer, p.edge, self.to_scene(end), self.px(14), max(MIN_LINE, self.px(3)))
        box = self.speed_plot
        top = max(float(np.max(s)) for s in run.speeds)
        pygame.draw.line(layer, p.faint, box.bottomleft, box.bottomright, 1)
        pygame.draw.line(layer, p.faint, box.bottomleft, box.topleft, 1)
        self._text("hand speed (m/s)", small, p.ink, (box.left, box.top - 6), "bottomleft", layer, placed)
        for value, y in ((0.0, box.bottom), (top, box.top)):
            self._text(f"{value:.1f}", small, p.faint, (box.left - 4, y), "midright", layer, placed)
        every = max(1, len(run.speeds[0]) // 220)
        for speeds, colour in zip(run.speeds, (p.link, ARM_B), strict=True):
            points = [(box.left + round(box.width * i / len(speeds)), box.bottom - round(box.height * v / top))
                      for i, v in list(enumerate(speeds))[::every]]
            pygame.draw.lines(layer, colour, False, points, max(MIN_LINE, self.px(3)))
        self._text("out", small, p.faint, (box.left + box.width // 4, box.bottom + 4), "midtop", layer, placed)
        self._text("back", small, p.faint, (box.left + 3 * box.width // 4, box.bottom + 4), "midtop", layer, placed)
        line = self.font(small).get_linesize() + 2
        y = self.legend_top
        for colour, lines in self.legend:
            colour = p.link if colour is None else colour
            pygame.draw.line(layer, colour, (self.margin, y + line // 2), (self.margin + 28, y + line // 2), 5)
            for text in lines:
                self._text(text, small, p.ink, (self.margin + round(36 * small / 30), y), target=layer, placed=placed)
                y += line

    # --------------------------------------------------------------- what moves
    def _draw_bars(self, run: ReachRun) -> None:
        parts, total = run.torques_now()
        # One N m scale for both joints, as in the figure, so the shoulder's larger torques look larger.
        scale = max(run.torque_scales())
        rows = [(parts[k], _rgb(c)) for k, _, c in COMPONENTS if (k != "gravity" or run.gravity) and k != "damping"]
        rows.append((total, self.palette.ink))
        top, row_h, centres, half, offset = self.bar_geometry
        small = self._sizes()[2]
        for r, (values, colour) in enumerate(rows):
            y = top + row_h + r * row_h + offset
            for x, v in zip(centres, values, strict=True):
                length = round(half * v / scale)
                pygame.draw.rect(self.scene, colour,
                                 pygame.Rect(min(x, x + length), y, abs(length), row_h - offset - 6))
                # The value on the side the bar leaves free, so it never runs into the other joint's bars.
                dy = 0 if offset else 3  # stacked rows have no room to spare below the value
                self._text(f"{v:+.1f}", small, self.palette.ink, (x - 4, y + dy) if v >= 0 else (x + 4, y + dy),
                           "topright" if v >= 0 else "topleft")

    def draw(self) -> None:
        laid_out = (self.scene_shape(self.size or SCENE_SIZE), self.paused)
        if self._laid_out != laid_out:
            if self._laid_out is not None and self._laid_out[0] != laid_out[0]:
                for trail in self.trails:  # in the old shape's pixels
                    trail.clear()
            self.frame_content()  # a new window shape (or help line): the scene laid out again for it
            self._laid_out = laid_out
        scene = self.scene
        scene.blit(self._static_layer(), (0, 0))
        self.placed = []
        p = self.palette
        run = self.run
        poses = self.poses()
        arms = [[self.to_scene(pt) for pt in run.arm_points(q1, q2)] for q1, q2 in poses]
        for trail, arm in zip(self.trails, arms, strict=True):
            trail.append(arm[-1])
        if isinstance(run, ReachRun):
            self._draw_bars(run)
        if self.name == "planning":
            box = self.speed_plot
            cursor = box.left + round(box.width * (run.steps % len(run.speeds[0])) / len(run.speeds[0]))
            pygame.draw.line(scene, p.faint, (cursor, box.top), (cursor, box.bottom), 1)
        for trail, colour in zip(self.trails, (p.trail, TRAIL_B), strict=False):
            if len(trail) > 1:
                pygame.draw.lines(scene, colour, False, list(trail), self.line)
        self._draw_body(poses[0], arms[0])
        if len(arms) > 1:
            self._draw_arm(arms[1], ARM_B, self.px(6), self.px(7))
        status = self._sizes()[1]
        width = self.scene_size[0] - 2 * self.margin
        lines = self._status_lines(width)
        if len(lines) > self.status_rows:  # never more rows than laid out: the last one cut short
            lines = [*lines[:self.status_rows - 1], self._fit("   ".join(lines[self.status_rows - 1:]), status, width)]
        for i, line in enumerate(lines):
            self._text(line, status, p.ink, (self.margin, self.status_top + i * self.status_pitch))
        self.placed += self._static_placed
        screen = pygame.display.get_surface()
        scale, offset = self.view()
        size = (round(self.scene_size[0] * scale), round(self.scene_size[1] * scale))
        # The scene is the window's size but for a frame drawn before a resize has reached it.
        shown = scene if size == self.scene_size else pygame.transform.smoothscale(scene, size)
        if offset != (0, 0) or size != screen.get_size():
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
               fullscreen: bool = False, palette: str = "okabe-ito", text_scale: float = 1.0) -> DemoWindow:
    """Open the window and play demo ``name`` until Esc or close (or ``max_frames`` frames)."""
    window = DemoWindow(name, run, speed=speed, clock=clock, size=size, fullscreen=fullscreen, palette=palette,
                        text_scale=text_scale)
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
