"""``physics.hand``: the hand's position written once, with the bits of every copy it replaced.

Each place that wrote ``l1 cos q1 + l2 cos(q1 + q2)`` out kept its own sine when it moved to these
functions; the copies are written out again here, as they were, and compared with ``==`` on the bits.
"""

import math
import random
import struct

import numpy as np

from armgame.game.rules import hand_position
from armgame.physics import TwoJointArm
from armgame.physics.hand import hand_from_trig, hand_xy, hand_xy_arm_sine, hand_xy_arrays
from armgame.physics.params import GAME_ARM
from armgame.physics.trig import sin_cos


def bits(*values: float) -> tuple[int, ...]:
    return tuple(struct.unpack("<q", struct.pack("<d", float(v)))[0] for v in values)


def angles(count: int = 2000) -> list[tuple[float, float]]:
    rng = random.Random(42)
    drawn = [(rng.uniform(-7.0, 7.0), rng.uniform(-7.0, 7.0)) for _ in range(count)]
    return [*drawn, (0.0, 0.0), (math.pi / 2, -math.pi), (-1e-300, 1e-300), (100.0, -3.0)]


def test_the_c_library_hand_has_the_bits_of_the_copies_it_replaced():
    l1, l2 = GAME_ARM.l1, GAME_ARM.l2
    for q1, q2 in angles():
        session_copy = (l1 * math.cos(q1) + l2 * math.cos(q1 + q2), l1 * math.sin(q1) + l2 * math.sin(q1 + q2))
        elbow = (l1 * math.cos(q1), l1 * math.sin(q1))  # the renderer's and the body's: elbow first
        drawn_copy = (elbow[0] + l2 * math.cos(q1 + q2), elbow[1] + l2 * math.sin(q1 + q2))
        assert bits(*hand_xy(l1, l2, q1, q2)) == bits(*session_copy) == bits(*drawn_copy)


def test_the_rules_hand_is_the_arm_sines_and_has_its_old_bits():
    l1, l2 = GAME_ARM.l1, GAME_ARM.l2
    assert hand_position is hand_xy_arm_sine
    for q1, q2 in angles():
        s1, c1 = sin_cos(q1)
        s12, c12 = sin_cos(q1 + q2)
        assert bits(*hand_position(l1, l2, q1, q2)) == bits(l1 * c1 + l2 * c12, l1 * s1 + l2 * s12)


def test_the_array_hand_has_the_bits_of_the_copies_it_replaced():
    l1, l2 = GAME_ARM.l1, GAME_ARM.l2
    q = np.array(angles())
    a, b = q[:, 0], q[:, 1]
    hx, hy = hand_xy_arrays(l1, l2, a, b)
    assert np.array_equal(hx, l1 * np.cos(a) + l2 * np.cos(a + b))
    assert np.array_equal(hy, l1 * np.sin(a) + l2 * np.sin(a + b))
    assert np.array_equal(TwoJointArm(GAME_ARM).hand(q), np.stack([hx, hy], axis=-1))
    c1, s1, c12, s12 = np.cos(a), np.sin(a), np.cos(a + b), np.sin(a + b)
    fx, fy = hand_from_trig(l1, l2, c1, s1, c12, s12)
    assert np.array_equal(fx, hx) and np.array_equal(fy, hy)
