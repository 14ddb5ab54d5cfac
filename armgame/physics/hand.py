"""Where the two-joint arm's hand is: ``(l1 cos q1 + l2 cos(q1 + q2), l1 sin q1 + l2 sin(q1 + q2))``, written once.

Two sines are in use, and which one a place takes is part of its results' bits, so each has its own
function and no place's arithmetic changed when it moved here:

* ``hand_xy_arm_sine``: the arm's own sine (``physics.trig``, + and * only), the same bits on every
  machine and in the browser's engine. The game's rules decide hits and place targets on it
  (``game.rules.hand_position``, since armgame 0.4).
* ``hand_xy``: the C library's (``math.cos``, ``math.sin``), which the renderer, the session's
  ``hand()``, the lab and the batch's "near" filters have always used; ``hand_xy_arrays`` is the same
  on numpy arrays (numpy's ``cos`` and ``sin``), as ``TwoJointArm.hand`` and the numpy kernel take it.

All three are ``hand_from_trig`` of their cosines and sines (``hand_xy`` with it written out, for speed): the same
operations in the same order as the code they replaced (``q1 + q2`` formed once, then ``l1 c1 + l2 c12``
and ``l1 s1 + l2 s12``), so a hand computed here has the bits it had. Where the cosines and sines are
at hand already (the batch's ``hand_trig``, the lab's channel), ``hand_from_trig`` takes them.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from .trig import sin_cos

#: A float, or a float64 array (``hand_from_trig`` works on either, element by element).
Number = TypeVar("Number", float, NDArray[np.float64])


def hand_from_trig(l1: float, l2: float, c1: Number, s1: Number, c12: Number, s12: Number) -> tuple[Number, Number]:
    """The hand (m) from cos q1, sin q1, cos(q1 + q2) and sin(q1 + q2), whichever sine made them."""
    return l1 * c1 + l2 * c12, l1 * s1 + l2 * s12


def hand_xy(l1: float, l2: float, q1: float, q2: float) -> tuple[float, float]:
    """The hand (m) of joint angles (q1, q2) (rad) with the C library's sine (Python's ``math``)."""
    # ``hand_from_trig`` written out: the lab's hot loop calls this every step, where a second call cost another 3%.
    q12 = q1 + q2
    return l1 * math.cos(q1) + l2 * math.cos(q12), l1 * math.sin(q1) + l2 * math.sin(q12)


def hand_xy_arm_sine(l1: float, l2: float, q1: float, q2: float) -> tuple[float, float]:
    """The hand (m) of joint angles (q1, q2) with the arm's own sine (``physics.trig.sin_cos``): the rules'."""
    s1, c1 = sin_cos(q1)
    s12, c12 = sin_cos(q1 + q2)
    return hand_from_trig(l1, l2, c1, s1, c12, s12)


def hand_xy_arrays(l1: float, l2: float, q1: NDArray[np.float64],
                   q2: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``hand_xy`` of arrays of joint angles, element by element, with numpy's ``cos`` and ``sin``."""
    q12 = q1 + q2
    return hand_from_trig(l1, l2, np.cos(q1), np.sin(q1), np.cos(q12), np.sin(q12))
