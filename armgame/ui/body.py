"""The arm drawn as a body: a torso and head seen from above, a tapered upper arm and forearm, a
hand, and the four muscles the keys drive, where they act.

The game's arm moves in the horizontal plane with the shoulder fixed (a right arm: the torso lies to
the shoulder's left, the player faces +y). Each muscle is drawn as a spindle between its origin and
its insertion: pectoralis from the chest to the front of the upper arm, posterior deltoid from the
back of the shoulder to the back of the upper arm (the pair that turns the shoulder), biceps along
the front of the upper arm onto the forearm and triceps along its back to behind the elbow (the
pair that turns the elbow). So the key that swings the arm anticlockwise swells a muscle on the
side it pulls towards. A muscle swells and brightens with its activation, in its key's colour (the
palette's muscle colours, as the bars), from a pale version of that colour at rest.

Geometry is computed in metres (``muscle_outline``, ``limb_outline``: pure functions the tests check)
and drawn through a ``to_px`` mapping, so the game, the autopilot and the demos draw the same arm at
their own scale. Edges are anti-aliased (a filled polygon under its anti-aliased outline).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import pygame

from ..physics.hand import hand_xy
from .palette import RGB, Palette

Point = tuple[float, float]

#: Half-widths (m) of the limbs at each end: upper arm at shoulder and elbow, forearm at elbow and wrist.
UPPER_ARM = (0.048, 0.034)
FOREARM = (0.034, 0.022)
HAND = (0.036, 0.030)  # the palm's half-length along the forearm and half-width
#: A muscle's greatest half-width (m): at rest, and added at full activation.
MUSCLE_REST, MUSCLE_GAIN = 0.011, 0.02
#: The shoulder pair are broad, flat muscles: wider bellies than the elbow pair's.
BREADTH = (1.4, 1.4, 1.0, 1.0)
#: Muscle fill: this far from the body's skin towards the muscle's colour at rest, the rest with activation.
MUSCLE_TINT = 0.45
SPINDLE_POINTS = 9
#: Along a muscle (0 at its origin, 1 at its insertion): where each outline point is, and the belly's shape there.
_SPINDLE = tuple((k / (SPINDLE_POINTS - 1), math.sin(math.pi * k / (SPINDLE_POINTS - 1)) ** 1.2)
                 for k in range(SPINDLE_POINTS))
#: The torso and head (top view, m): the torso's centre and half-sizes, the head's centre and radius.
TORSO = ((-0.19, -0.035), (0.23, 0.11))
HEAD = ((-0.19, -0.02), 0.085)


def _along(origin: Point, direction: Point, normal: Point, a: float, n: float) -> Point:
    return origin[0] + a * direction[0] + n * normal[0], origin[1] + a * direction[1] + n * normal[1]


def joints(q1: float, q2: float, l1: float, l2: float) -> tuple[Point, Point, Point]:
    """Shoulder, elbow and hand (m)."""
    return (0.0, 0.0), (l1 * math.cos(q1), l1 * math.sin(q1)), hand_xy(l1, l2, q1, q2)


def muscle_ends(i: int, q1: float, q2: float, l1: float, l2: float) -> tuple[Point, Point]:
    """Origin and insertion (m) of muscle ``i`` (0 pectoralis, 1 posterior deltoid, 2 biceps, 3 triceps)."""
    shoulder, elbow, _ = joints(q1, q2, l1, l2)
    u = (math.cos(q1), math.sin(q1))
    n = (-u[1], u[0])  # the upper arm's anticlockwise side: the side flexion turns it towards
    f = (math.cos(q1 + q2), math.sin(q1 + q2))
    nf = (-f[1], f[0])
    if i == 0:  # pectoralis: from the chest, in front of the shoulder, to the front of the upper arm
        return (-0.12, 0.05), _along(shoulder, u, n, 0.30 * l1, 0.6 * UPPER_ARM[0])
    if i == 1:  # posterior deltoid: from the back of the shoulder blade to the back of the upper arm
        return (-0.07, -0.085), _along(shoulder, u, n, 0.28 * l1, -0.6 * UPPER_ARM[0])
    if i == 2:  # biceps: along the front of the upper arm, onto the forearm past the elbow
        return _along(shoulder, u, n, 0.12 * l1, 0.55 * UPPER_ARM[0]), _along(elbow, f, nf, 0.12 * l2, 0.4 * FOREARM[0])
    # triceps: along the back of the upper arm, to behind the elbow
    return _along(shoulder, u, n, 0.12 * l1, -0.55 * UPPER_ARM[0]), _along(elbow, u, n, 0.02, -0.5 * UPPER_ARM[1])


def muscle_outline(i: int, q1: float, q2: float, l1: float, l2: float, activation: float) -> list[Point]:
    """Muscle ``i`` as a closed spindle (m): thin tendons at both ends, its belly as wide as its activation."""
    a = min(max(activation, 0.0), 1.0)
    (x0, y0), (x1, y1) = muscle_ends(i, q1, q2, l1, l2)
    dx, dy = x1 - x0, y1 - y0
    length = math.hypot(dx, dy) or 1e-9
    nx, ny = -dy / length, dx / length
    belly = (MUSCLE_REST + MUSCLE_GAIN * a) * BREADTH[i]
    side: list[Point] = []
    other: list[Point] = []
    for s, shape in _SPINDLE:
        w = 0.002 + belly * shape
        cx, cy = x0 + s * dx, y0 + s * dy
        side.append((cx + w * nx, cy + w * ny))
        other.append((cx - w * nx, cy - w * ny))
    return side + other[::-1]


def limb_outline(start: Point, end: Point, widths: tuple[float, float]) -> list[Point]:
    """A tapered limb (m): a quadrilateral from ``start`` to ``end``, half-widths ``widths``."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    length = math.hypot(dx, dy) or 1e-9
    nx, ny = -dy / length, dx / length
    w0, w1 = widths
    return [(start[0] + w0 * nx, start[1] + w0 * ny), (end[0] + w1 * nx, end[1] + w1 * ny),
            (end[0] - w1 * nx, end[1] - w1 * ny), (start[0] - w0 * nx, start[1] - w0 * ny)]


def area(points: Sequence[Point]) -> float:
    """A polygon's area (the shoelace formula)."""
    return 0.5 * abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(points, [*points[1:], points[0]],
                                                                             strict=True)))


def blend(a: Sequence[int], b: Sequence[int], k: float) -> RGB:
    """The colour a fraction ``k`` of the way from ``a`` to ``b``."""
    return tuple(round(x + (y - x) * k) for x, y in zip(a[:3], b[:3], strict=True))  # type: ignore[return-value]


@functools.lru_cache(maxsize=1024)
def _muscle_colour(skin: RGB, colour: RGB, level: int) -> RGB:
    """A muscle's fill at activation ``level`` / 64: from a tint of its colour at rest to the colour itself."""
    return blend(skin, colour, MUSCLE_TINT + (1.0 - MUSCLE_TINT) * level / 64)


@functools.lru_cache(maxsize=64)
def _edge_colour(colour: RGB, ink: RGB) -> RGB:
    return blend(colour, ink, 0.35)


def _ring(surface: pygame.Surface, fill: RGB, edge: RGB, centre: tuple[int, int], radius: int, line: int) -> None:
    pygame.draw.aacircle(surface, edge, centre, radius + line)
    pygame.draw.aacircle(surface, fill, centre, radius)


def line_width(px_per_m: float) -> int:
    """The body's outline (px): 3 px or more, wider on a large window."""
    return max(3, round(px_per_m * 0.005))


def draw_torso(surface: pygame.Surface, origin: tuple[float, float], px_per_m: float, palette: Palette) -> None:
    """The torso and head, seen from above (static: the game draws it once into its background).

    ``origin``: where the shoulder (0, 0) is, in pixels; y points up the screen.
    """
    ox, oy = origin

    def to_px(x: float, y: float) -> tuple[int, int]:
        return round(ox + x * px_per_m), round(oy - y * px_per_m)

    line = line_width(px_per_m)
    (cx, cy), (hw, hh) = TORSO
    left, top = to_px(cx - hw, cy + hh)
    rect = pygame.Rect(left, top, max(1, round(2 * hw * px_per_m)), max(1, round(2 * hh * px_per_m)))
    radius = round(hh * px_per_m)
    pygame.draw.rect(surface, palette.link, rect.inflate(2 * line, 2 * line), border_radius=radius + line)
    pygame.draw.rect(surface, palette.skin, rect, border_radius=radius)
    (hx, hy), r = HEAD
    nose = to_px(hx, hy + r * 0.95)
    pygame.draw.aacircle(surface, palette.link, nose, round(0.022 * px_per_m) + line)
    pygame.draw.aacircle(surface, palette.skin, nose, round(0.022 * px_per_m))
    _ring(surface, palette.skin, palette.link, to_px(hx, hy), round(r * px_per_m), line)
    # The other shoulder, so the torso reads as shoulders rather than a box.
    _ring(surface, palette.skin, palette.link, to_px(-0.38, 0.0), round(0.03 * px_per_m), line)


def draw_arm(surface: pygame.Surface, origin: tuple[float, float], px_per_m: float, q1: float, q2: float,
             l1: float, l2: float, activation: Sequence[float], palette: Palette,
             torso: bool = True) -> list[pygame.Rect]:
    """The arm at angles (q1, q2): limbs, joints, hand, and the four muscles at ``activation`` (0 to 1);
    returns the rectangles it drew in (for a window that redraws only what changed).

    ``torso``: False where no torso is drawn (an arm hanging in a vertical plane): the shoulder pair, which
    run to the torso, are left out. ``origin``: the shoulder in pixels; y points up the screen. Points stay
    fractional: pygame's
    anti-aliased lines place them to the sub-pixel, and nothing is rounded twice.
    """
    ox, oy = origin
    k = px_per_m
    line = line_width(k)
    grow = line / k  # the outline's width, in metres
    shoulder, elbow, hand = joints(q1, q2, l1, l2)
    skin, edge = palette.skin, palette.link
    wrist_f = max(0.0, 1.0 - HAND[0] / l2)
    wrist = (elbow[0] + wrist_f * (hand[0] - elbow[0]), elbow[1] + wrist_f * (hand[1] - elbow[1]))

    def px(points: Sequence[Point]) -> list[tuple[float, float]]:
        return [(ox + x * k, oy - y * k) for x, y in points]

    def at(p: Point) -> tuple[float, float]:
        return ox + p[0] * k, oy - p[1] * k

    polygon, aalines, aacircle = pygame.draw.polygon, pygame.draw.aalines, pygame.draw.aacircle
    joint_r = ((shoulder, UPPER_ARM[0]), (elbow, UPPER_ARM[1]), (wrist, FOREARM[1]))
    # The silhouette's outline first (each part grown by the outline's width), the skin over it.
    drawn = []
    for start, end, widths in ((shoulder, elbow, UPPER_ARM), (elbow, wrist, FOREARM)):
        outer = px(limb_outline(start, end, (widths[0] + grow, widths[1] + grow)))
        polygon(surface, edge, outer)
        drawn.append(aalines(surface, edge, True, outer))
    for centre, r in joint_r:
        drawn.append(aacircle(surface, edge, at(centre), r * k + line))
    drawn.append(polygon(surface, edge, px(_palm(wrist, hand, grow))))
    for start, end, widths in ((shoulder, elbow, UPPER_ARM), (elbow, wrist, FOREARM)):
        polygon(surface, skin, px(limb_outline(start, end, widths)))
    for centre, r in joint_r:  # inside the joint's anti-aliased edge: a plain fill is smooth enough
        pygame.draw.circle(surface, skin, at(centre), r * k)
    polygon(surface, skin, px(_palm(wrist, hand, 0.0)))
    colours = palette.muscles
    for i in (1, 0, 3, 2) if torso else (3, 2):  # the shoulder pair under the elbow pair, where they cross
        a = min(max(float(activation[i]), 0.0), 1.0)
        outline = px(muscle_outline(i, q1, q2, l1, l2, a))
        polygon(surface, _muscle_colour(skin, tuple(colours[i]), round(64 * a)), outline)
        drawn.append(aalines(surface, _edge_colour(tuple(colours[i]), palette.ink), True, outline))
    return [drawn[0].unionall(drawn[1:])]  # its parts overlap: one rectangle restores less than all of theirs


def _palm(wrist: Point, hand: Point, grow: float) -> list[Point]:
    """The hand: a rounded palm from the wrist to past the hand's point (which the game marks with a disc)."""
    dx, dy = hand[0] - wrist[0], hand[1] - wrist[1]
    length = math.hypot(dx, dy) or 1e-9
    ux, uy = dx / length, dy / length
    nx, ny = -uy, ux
    half_l, half_w = HAND[0] * 1.1 + grow, HAND[1] + grow
    cx, cy = hand[0] - 0.2 * HAND[0] * ux, hand[1] - 0.2 * HAND[0] * uy
    points = []
    for c, s in _PALM:
        a, b = c * half_l, s * half_w
        points.append((cx + a * ux + b * nx, cy + a * uy + b * ny))
    return points


# A rounded rectangle's outline (a superellipse), as unit (along, across) pairs.
_PALM = tuple((math.copysign(abs(math.cos(t)) ** 0.6, math.cos(t)), math.copysign(abs(math.sin(t)) ** 0.6, math.sin(t)))
              for t in (2.0 * math.pi * j / 14 for j in range(14)))
