"""The demo window (pygame): plays a demo's run at real time, with pause, restart and playback speed.

The only demo module that imports pygame, and three parts: the playback clock (``demo_playback``:
real time into fixed physics steps, scaled by the speed; pure, tested without a display), the layout
(``demo_layout``: where the texts, bars and reach go for the window's shape) and the drawing, here. The
drawing interpolates joint angles between the last two steps, in the settings' palette, and draws what
never moves once per size (``_static_layer``). With no size asked, the window opens in the desktop's
shape, as large as it allows (a 4:3 projector, a 4:3 window), and F11 fills the screen. The arm is the
game's (``armgame.ui.body``). Every text drawn is recorded (``text_boxes``), so the tests check that
none is cut or overlaps another at any window size.
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
from .body import draw_arm, draw_torso
from .demo_layout import ARM_B, HELP, SCENE_SIZE, TRAIL_B, DemoLayout, scene_shape
from .demo_playback import SPEEDS, DemoPlayback, DemoRun
from .display import open_window, toggle_fullscreen
from .loop import run_loop
from .playback import SKIP_SECONDS, skip_sign, speed_after
from .render import MIN_LINE, PALETTES

__all__ = ["ARM_B", "HELP", "SCENE_SIZE", "SPEEDS", "DemoWindow", "run_window"]


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

    def __init__(self, name: str, run: DemoRun, speed: float = 1.0, clock: Callable[[], float] = time.perf_counter,
                 size: tuple[int, int] | None = None, fullscreen: bool = False, palette: str = "okabe-ito",
                 text_scale: float = 1.0) -> None:
        self.info = get_info(name)
        self.name = name
        self.playback = DemoPlayback(run, speed, clock,
                                     hands_apart=run.hand_distance if name == "chaos" else None)  # type: ignore[attr-defined]
        self.lay = DemoLayout(self.info, name, run, text_scale)
        self.lay.size = size
        self.fullscreen = fullscreen
        #: The settings' palette (a bright room's high-contrast).
        self.palette = PALETTES.get(palette, PALETTES["okabe-ito"])
        self.windowed_size = size or SCENE_SIZE
        #: Every text of the last frame: (text, rectangle in scene pixels).
        self.placed: list[tuple[str, Any]] = []
        self.trails: list[deque[tuple[int, int]]] = []
        self._jumps = -1  # the playback's jumps when the trails were last cleared
        self.running = True
        self.screen: Any = None
        self.scene: Any = None
        self._static: Any = None
        self._static_key: tuple | None = None
        self._static_placed: list[tuple[str, Any]] = []
        #: How many times the static layer was drawn (once per scene size and pause state).
        self.static_builds = 0
        self._laid_out: tuple | None = None

    # ------------------------------------------------------------------ the parts' state, as the tests read it
    run = property(lambda self: self.playback.run, doc="the demo's run")
    paused = property(lambda self: self.playback.paused)
    parted_at = property(lambda self: self.playback.parted_at)
    size = property(lambda self: self.lay.size, lambda self, value: setattr(self.lay, "size", value),
                    doc="the window's size (None: not open yet)")
    scene_size = property(lambda self: self.lay.scene_size)
    room = property(lambda self: self.lay.room)
    line = property(lambda self: self.lay.line)

    @property
    def speed(self) -> float:
        return self.playback.speed

    @speed.setter
    def speed(self, value: float) -> None:
        self.playback.speed = value

    def advance(self) -> None:
        self.playback.advance()

    def poses(self) -> list[tuple[float, float]]:
        return self.playback.poses()

    def skip(self, seconds: float) -> None:
        self.playback.skip(seconds)

    def restart(self) -> None:
        self.playback.restart()

    def to_scene(self, point: tuple[float, float]) -> tuple[int, int]:
        return self.lay.to_scene(point)

    def to_window(self, point: tuple[float, float]) -> tuple[int, int]:
        return self.lay.to_window(point)

    def view(self) -> tuple[float, tuple[int, int]]:
        return self.lay.view()

    def reach_rect(self) -> Any:
        return self.lay.reach_rect()

    # ------------------------------------------------------------------ lifecycle
    def open(self) -> None:
        # A 4:3 projector gets a 4:3 window: the desktop's own shape, as large as it allows.
        self.screen = open_window(self.size, self.fullscreen, self.info.title, None)
        self.size = self.windowed_size = self.screen.get_size()
        self.frame_content()
        self.restart()

    def close(self) -> None:
        pygame.display.quit()

    def frame_content(self) -> None:
        """Lay the scene out for the window's shape and the text size (``DemoLayout.lay_out``)."""
        self.lay.lay_out(self.paused, self.speed, self._status())
        self.scene = pygame.Surface(self.scene_size)
        self._static_key = None

    def _clear_trails(self) -> None:
        keep = 2500 if self.name == "passive" else 90
        self.trails = [deque(maxlen=keep) for _ in self.run.states]
        self._jumps = self.playback.jumps

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
            self.playback.toggle_pause()
        elif key == pygame.K_r:
            self.restart()
        elif (speed := speed_after(pygame.key.name(key).lower(), self.speed, SPEEDS)) is not None:
            self.speed = speed
        elif skip_sign(pygame.key.name(key).lower()):
            self.skip(SKIP_SECONDS * skip_sign(pygame.key.name(key).lower()))
        return True

    # ------------------------------------------------------------------ drawing
    def _text(self, text: str, height: int, colour: tuple[int, int, int], pos: tuple[int, int],
              anchor: str = "topleft", target: Any = None, placed: list | None = None) -> None:
        surface = self.lay.kit.text(text, height, colour)
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
        return self.lay.help_lines(self.paused)

    def _draw_body(self, pose: tuple[float, float], points: list[tuple[int, int]]) -> None:
        """The game's arm (``armgame.ui.body``): seen from above in the horizontal demos (its torso is in
        the static layer), hanging from a fixed shoulder in the vertical ones; its muscles at rest."""
        q1, q2 = pose
        k = self.lay.pixels_per_metre
        p = self.palette
        world = self.run.arm_points(q1, q2)
        if len(world) < 3:  # the pendulum: one link, no elbow
            pygame.draw.circle(self.scene, p.faint, self.lay.shoulder, self.lay.px(11))
            self._draw_arm(points, p.link, self.lay.px(14), self.lay.px(12))
            return
        l1, l2 = math.dist(world[0], world[1]), math.dist(world[1], world[2])
        if self.info.vertical:
            pygame.draw.circle(self.scene, p.faint, self.lay.shoulder, max(11, round(0.06 * k)))
        draw_arm(self.scene, self.lay.shoulder, k, q1, q2, l1, l2, (0.0, 0.0, 0.0, 0.0), p,
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
        caption, _, small = self.lay.heights()
        run = self.run
        if isinstance(run, ReachRun):
            path = [self.to_scene(tuple(pt)) for pt in run.table.hand[:: max(1, len(run.table.hand) // 200)]]
            pygame.draw.lines(layer, p.edge, False, path, self.line)
            for end in (run.plan.home, run.plan.target):
                pygame.draw.circle(layer, p.edge, self.to_scene(end), self.lay.px(14), self.line)
            self._static_bars(layer, placed, small)
        if self.name == "planning":
            self._static_planning(layer, placed, small)
        if not self.info.vertical and len(run.arm_points(*run.states[0][:2])) >= 3:
            draw_torso(layer, self.lay.shoulder, self.lay.pixels_per_metre, p)
        y = self.lay.edge
        for line in self.lay.caption_lines:
            self._text(line, caption, p.ink, (self.lay.margin, y), target=layer, placed=placed)
            y += self.lay.caption_pitch
        lines = self.help_lines()
        y = self.scene_size[1] - self.lay.edge - self.lay.help_pitch * (len(lines) - 1)
        for line in lines:  # the help line last: the tests read the keys from the last text drawn
            self._text(line, small, p.faint, (self.scene_size[0] - self.lay.edge, y), "bottomright", layer, placed)
            y += self.lay.help_pitch
        self._static, self._static_key, self._static_placed = layer, key, placed
        return layer

    def _static_bars(self, layer: Any, placed: list, small: int) -> None:
        p = self.palette
        run = self.run
        top, row_h, centres, half, offset = self.lay.bar_geometry
        rows = self.lay.bar_labels
        scale = max(run.torque_scales())
        for x, joint in zip(centres, ("shoulder", "elbow"), strict=True):
            self._text(f"{joint} (N m)", small, p.ink, (x, top + row_h - self.lay.kit.font(small).get_linesize() - 4),
                       "midtop", layer, placed)
        for r, label in enumerate(rows):
            self._text(label, small, p.ink, (self.lay.margin, top + row_h + r * row_h + (0 if offset else 3)),
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
            pygame.draw.circle(layer, p.edge, self.to_scene(end), self.lay.px(14), max(MIN_LINE, self.lay.px(3)))
        box = self.lay.speed_plot
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
            pygame.draw.lines(layer, colour, False, points, max(MIN_LINE, self.lay.px(3)))
        self._text("out", small, p.faint, (box.left + box.width // 4, box.bottom + 4), "midtop", layer, placed)
        self._text("back", small, p.faint, (box.left + 3 * box.width // 4, box.bottom + 4), "midtop", layer, placed)
        line = self.lay.kit.font(small).get_linesize() + 2
        y = self.lay.legend_top
        for colour, lines in self.lay.legend:
            colour = p.link if colour is None else colour
            pygame.draw.line(layer, colour, (self.lay.margin, y + line // 2), (self.lay.margin + 28, y + line // 2), 5)
            for text in lines:
                indent = round(36 * self.lay.kit.nominal(small) / 30)
                self._text(text, small, p.ink, (self.lay.margin + indent, y), target=layer, placed=placed)
                y += line

    # --------------------------------------------------------------- what moves
    def _draw_bars(self, run: ReachRun) -> None:
        parts, total = run.torques_now()
        # One N m scale for both joints, as in the figure, so the shoulder's larger torques look larger.
        scale = max(run.torque_scales())
        rows = [(parts[k], _rgb(c)) for k, _, c in COMPONENTS if (k != "gravity" or run.gravity) and k != "damping"]
        rows.append((total, self.palette.ink))
        top, row_h, centres, half, offset = self.lay.bar_geometry
        small = self.lay.heights()[2]
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
        if self._jumps != self.playback.jumps:  # restarted or skipped: the trails no longer follow
            self._clear_trails()
        laid_out = (scene_shape(self.size or SCENE_SIZE), self.paused)
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
            box = self.lay.speed_plot
            cursor = box.left + round(box.width * (run.steps % len(run.speeds[0])) / len(run.speeds[0]))
            pygame.draw.line(scene, p.faint, (cursor, box.top), (cursor, box.bottom), 1)
        for trail, colour in zip(self.trails, (p.trail, TRAIL_B), strict=False):
            if len(trail) > 1:
                pygame.draw.lines(scene, colour, False, list(trail), self.line)
        self._draw_body(poses[0], arms[0])
        if len(arms) > 1:
            self._draw_arm(arms[1], ARM_B, self.lay.px(6), self.lay.px(7))
        status = self.lay.heights()[1]
        width = self.scene_size[0] - 2 * self.lay.margin
        lines = self.lay.status_lines(width, self.speed, self.paused, self._status())
        if len(lines) > self.lay.status_rows:  # never more rows than laid out: the last one cut short
            rest = "   ".join(lines[self.lay.status_rows - 1:])
            lines = [*lines[:self.lay.status_rows - 1], self.lay.kit.fit_text(rest, status, width)]
        for i, line in enumerate(lines):
            self._text(line, status, p.ink, (self.lay.margin, self.lay.status_top + i * self.lay.status_pitch))
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
                self.running = False
                return False
        self.advance()
        self.draw()
        pygame.display.flip()
        return True


def run_window(name: str, run: DemoRun, speed: float = 1.0, clock: Callable[[], float] = time.perf_counter,
               max_frames: int | None = None, frame_rate: float | None = 60.0, size: tuple[int, int] | None = None,
               fullscreen: bool = False, palette: str = "okabe-ito", text_scale: float = 1.0) -> DemoWindow:
    """Open the window and play demo ``name`` until Esc or close (or ``max_frames`` frames)."""
    window = DemoWindow(name, run, speed=speed, clock=clock, size=size, fullscreen=fullscreen, palette=palette,
                        text_scale=text_scale)
    window.open()
    try:
        # The loop only paces the frames; the physics reads ``clock`` (the playback's) instead.
        run_loop(lambda _seconds: window.frame(), lambda: window.running, fps=frame_rate, max_frames=max_frames)
    finally:
        window.close()
    return window
