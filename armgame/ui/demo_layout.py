"""A demo window's layout: where the texts, the torque bars, the speed plot and the arm's reach go.

Pure geometry, nothing drawn (as ``render.GameRenderer.layout`` is for the game): the demo window
(``demo_window``) lays its scene out again whenever the window's shape or its help line changes, and
draws what this says. The scene is drawn at the window's own size and pixels (``scene_shape``), its
sizes in proportion to its shorter side (``px``: the pixels of an 800 px one) and its text to its height
(the smallest 2.5% of it, times the settings' ``text_scale``; ``heights``), with the text kit's
smallest-size rule (``text.smallest_size``); the arm's reach is framed in the room the texts leave
(``lay_out``).
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import pygame

from ..demos.catalog import DemoInfo
from ..demos.reach import COMPONENTS, ReachRun
from .playback import PLAYBACK_HELP
from .render import MIN_LINE, MIN_TEXT_FRACTION
from .text import TextKit, smallest_size

SCENE_SIZE = (800, 800)
#: The scene's shorter side, in pixels: the longer one follows the window's shape.
SCENE_SIDE = 800
#: The keys every demo window offers, as its help line says them (one set with the replays').
HELP = ("p pause", "r restart", *PLAYBACK_HELP, "F11 fullscreen", "Esc quit")
# The second arm and its path, which the captions call orange whatever the palette: 3:1 or more on white
# (WCAG's rule for graphics).
ARM_B = (213, 94, 0)
TRAIL_B = (213, 94, 0)
#: Lines a class must see: 4 px in an 800 px scene.
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


def scene_shape(size: tuple[int, int]) -> tuple[int, int]:
    """The scene's size for a window of ``size``: the window's own, drawn at its pixels (never scaled:
    text scaled up to a 1920 x 1080 projector came out blurred, and the scaling cost a frame 1.4 ms)."""
    return max(size[0], 1), max(size[1], 1)


def bar_rows(run: ReachRun) -> list[str]:
    """The torque bars' rows: the components the run has (gravity only where it is on), then the total."""
    return [k for k, _, _ in COMPONENTS if (k != "gravity" or run.gravity) and k != "damping"] + ["TOTAL"]


def content_box(info: DemoInfo, run: Any) -> tuple[float, float, float, float]:
    """What the arm can cover, in metres (xmin, xmax, ymin, ymax) about the shoulder: the whole reach for a
    swinging arm, the cycle's arm and paths for a prescribed reach; and the body's width."""
    if info.vertical:
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


class DemoLayout:
    """The scene's geometry for one window size, text scale and help line (``lay_out``), and the mapping
    from the arm's plane (m) to the scene's and the window's pixels."""

    def __init__(self, info: DemoInfo, name: str, run: Any, text_scale: float = 1.0) -> None:
        self.info, self.name, self.run = info, name, run
        self.text_scale = text_scale
        #: The demos' text kit: the smallest font whose lines are the height asked or more.
        self.kit = TextKit(rule=smallest_size)
        #: The window's size (None: not open yet, the scene's default) and the scene's.
        self.size: tuple[int, int] | None = None
        self.scene_size = SCENE_SIZE
        self.shoulder, self.pixels_per_metre = (400.0, 450.0), 400.0
        self.speed_plot = pygame.Rect((560, 290), SPEED_PLOT_SIZE)
        self.reach = content_box(info, run)
        self.bar_geometry: tuple | None = None

    # ------------------------------------------------------------------ sizes
    def px(self, pixels: float) -> int:
        """``pixels`` of a scene 800 px on its shorter side, in this scene's pixels."""
        return max(1, round(pixels * min(self.scene_size) / SCENE_SIDE))

    @property
    def line(self) -> int:
        """Paths and trails: 4 px at 800 lines, never under MIN_LINE."""
        return max(MIN_LINE, self.px(LINE))

    def heights(self) -> tuple[int, int, int]:
        """Text heights (caption, status, small): the smallest text 2.5% of the window's height (20 px of
        800, 19 of 768; a tall window's text with its height), the others 4/3 and 34/30 of it, all times
        ``text_scale``."""
        small = math.ceil(MIN_TEXT_FRACTION * self.scene_size[1] * self.text_scale - 1e-9)
        return round(small * 4 / 3), round(small * 34 / 30), small

    def small_scale(self) -> float:
        """The small text's nominal size over 30, its size in an 800 px scene: spacing that follows the text."""
        return self.kit.nominal(self.heights()[2]) / 30

    # ------------------------------------------------------------------ lines of text
    def status_lines(self, width: int, speed: float, paused: bool, status: str) -> list[str]:
        """The clock and speed on a line, then what the demo measures (each wrapped between its parts)."""
        shown = f"{speed:g}x" + ("   PAUSED" if paused else "")
        height = self.heights()[1]
        return self.kit.wrap_items([f"t = {self.run.t:5.2f} s", f"speed {shown}"], height, width, sep="   ",
                                   fit=False) + \
            self.kit.wrap_items(status.split("   "), height, width, sep="   ", fit=False)

    def help_lines(self, paused: bool) -> list[str]:
        """The keys that work (actions: "p resume" while paused), on as few lines as the scene's width
        holds (a narrow window: two)."""
        items = ["p resume", *HELP[1:]] if paused else list(HELP)
        return self.kit.wrap_items(items, self.heights()[2], self.scene_size[0] - 24, sep="   ", fit=False)

    # ------------------------------------------------------------------ layout
    def lay_out(self, paused: bool, speed: float, status: str) -> None:
        """Lay the scene out for the window's shape and the text size: the texts at the edges, and the
        arm's reach scaled into the room they leave, centred (``status``: what the demo measures now)."""
        self.scene_size = scene_shape(self.size or SCENE_SIZE)
        w, h = self.scene_size
        caption, status_h, small = self.heights()
        font = self.kit.font
        small_h = font(small).get_linesize() + 2
        gap = max(4, round(6 * self.kit.nominal(small) / 30))
        self.margin = margin = self.px(20)
        self.caption_lines = self.kit.wrap_text(self.info.caption, caption, w - 2 * margin, max_lines=None, fit=False)
        self.edge = self.px(12)  # the caption's top, the help line's bottom
        # Two pixels between lines: scaled down to a small window, rounding never makes them touch.
        self.caption_pitch = font(caption).get_linesize() + 2
        self.status_top = self.edge + self.caption_pitch * len(self.caption_lines) + gap
        self.status_pitch = font(status_h).get_linesize() + 2
        # Room for the status as it reads now, and for chaos's longer line once the arms have parted.
        longest = self.status_lines(w - 2 * margin, speed, paused, status)
        if self.name == "chaos":
            longest = self.kit.wrap_items([*longest, "parted at t = 00.0 s"], status_h, w - 2 * margin, sep="   ",
                                          fit=False)
        self.status_rows = len(longest)
        top = self.status_top + self.status_pitch * self.status_rows + 2 * gap
        self.help_pitch = small_h
        bottom = h - self.edge - small_h * len(self.help_lines(paused)) - gap
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

    def _lay_out_bars(self, bottom: int, gap: int) -> int:
        """The torque bars' block above the help line: a column of row labels as wide as the widest,
        then both joints side by side; returns the room's new bottom."""
        font = self.kit.font(self.heights()[2])
        line = font.get_linesize()
        value_w = font.size("+88.8")[0] + gap
        needed = max(font.size("shoulder (N m)")[0] + 2 * gap, 3 * value_w)  # one joint's header and bars
        # Each row's label beside its bars where both joints still have room (in short words if it must),
        # else on a line above them (a tall, narrow window with large text).
        for names in (SHORT_LABELS, NARROW_LABELS, SHORT_LABELS):
            rows = [names.get(k, k) for k in bar_rows(self.run)]
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
        small = self.heights()[2]
        font = self.kit.font(small)
        line = font.get_linesize() + 2
        w, h = self.scene_size
        t = self.small_scale()
        # The legend's two entries, each wrapped beside its line's sample (a narrow scene: two lines each).
        width = w - 2 * self.margin - round(36 * t)
        self.legend = [(colour, self.kit.wrap_text(text, small, width, max_lines=None, fit=False))
                       for colour, text in LEGEND]
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

    # ---------------------------------------------------------------- geometry
    def to_scene(self, point: tuple[float, float]) -> tuple[int, int]:
        """Where a point (m) of the arm's plane is in the scene, in pixels."""
        x, y = point
        k = self.pixels_per_metre
        return round(self.shoulder[0] + x * k), round(self.shoulder[1] - y * k)

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

    def reach_rect(self) -> pygame.Rect:
        """The framed reach, in window pixels (the tests check it against the texts and the window)."""
        xmin, xmax, ymin, ymax = self.reach
        (x0, y0), (x1, y1) = self.to_window((xmin, ymax)), self.to_window((xmax, ymin))
        return pygame.Rect(x0, y0, x1 - x0, y1 - y0)
