"""The arm's sine and cosine: the trig of the equations of motion, the same bits on every machine.

Owns ``sin_cos`` (one angle, Python floats) and ``sin_cos_array`` (numpy arrays), which the arm's
equations of motion use for every cos and sin of a joint angle (``TwoJointArm.component_dynamics``,
the batched kernels, and their C twin ``arm_sin_cos`` in ``armgame/physics/_trig.h``, which the
compiled loops inline and ``_ctrig`` gives Python as ``sin_cos`` where it was built), and since armgame 0.4
the rules' hand too (``game.rules.hand_position``: the hit test and the targets, which the browser's engine
must find to the bit). The picture, the envs' observations and the batch's "near" filters keep the C
library's ``math.cos`` and ``math.sin``.

Why not the C library's: its sine is a scalar function whose bits differ between glibc, macOS and
Windows and between glibc's builds for CPUs with and without FMA, and none is proven equal to any
vector sine. A physics that must give the same result bit for bit in Python, in numpy, in C one game at
a time and in C with many games side by side in SIMD registers needs a sine made only of operations
IEEE 754 rounds correctly (+, -, *), in a fixed order: those give the same bits on every machine, in
every one of those four forms, and vectorise. The compiled code is built without contraction (no fused
multiply-add, ``setup.py``), so the C evaluates exactly the expressions below.

The method is fdlibm's (Sun, 1993, as kept in FreeBSD's msun): the angle reduced by the nearest
multiple k of pi/2 (pi/2 in three parts, the first two of 33 bits, so k times them is exact for
|k| < 2^20), then minimax polynomials for sin and cos on [-pi/4, pi/4] (FreeBSD's ``__kernel_sin``
and ``__kernel_cos``, without the reduced angle's tail), and the quadrant k mod 4. Measured against
mpmath (``tests/test_trig.py``): within 1.5 ulp for |x| <= 100 rad, 2.5 ulp up to 1e5 (glibc's is
within about 0.5: ``benchmarks/trig_change.py`` measures both). Angles beyond ``MAX_ANGLE`` (no arm
gets there: 1e15 rad is 10^14 turns) and non-finite ones give NaN, which the sessions stop as a state
gone non-finite.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .._native import load

FloatArray = NDArray[np.float64]

#: Past this |angle| (rad) the result is NaN: the quadrant is read from the low bits of
#: x * 2/pi + 1.5 * 2^52, which hold k mod 4 only while |k| < 2^51.
MAX_ANGLE = 1e15

_INV_PIO2 = 6.36619772367581382433e-01  # 2/pi
_SHIFT = 6755399441055744.0  # 1.5 * 2^52: adding it rounds to an integer, kept in the low bits
_PIO2_1 = 1.57079632673412561417e+00  # pi/2: the first 33 bits
_PIO2_2 = 6.07710050630396597660e-11  # the next 33
_PIO2_3 = 2.02226624871116645580e-21  # the rest
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
_NAN = float("nan")
_SIN_SIGN = np.array([1.0, 1.0, -1.0, -1.0])  # by k mod 4: sin x = s, c, -s, -c
_COS_SIGN = np.array([1.0, -1.0, -1.0, 1.0])  # cos x = c, -s, -c, s


def sin_cos_python(x: float) -> tuple[float, float]:
    """(sin x, cos x) as the arm's equations of motion take them (see the module's docstring), in Python:
    what ``sin_cos`` is where the compiled ``_ctrig`` was not built."""
    if not -MAX_ANGLE <= x <= MAX_ANGLE:
        return _NAN, _NAN
    k = (x * _INV_PIO2 + _SHIFT) - _SHIFT
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_3
    z = r * r
    w = z * z
    s = r + z * r * (_S1 + z * (_S2 + z * (_S3 + z * _S4) + z * w * (_S5 + z * _S6)))
    hz = 0.5 * z
    v = 1.0 - hz
    c = v + (((1.0 - v) - hz) + z * (z * (_C1 + z * (_C2 + z * _C3)) + w * w * (_C4 + z * (_C5 + z * _C6))))
    n = int(k) & 3
    if n == 0:
        return s, c
    if n == 1:
        return c, -s
    if n == 2:
        return -s, -c
    return -c, s


def sin_python(x: float) -> float:
    """sin x as the arm's equations of motion take it, in Python."""
    return sin_cos_python(x)[0]


def cos_python(x: float) -> float:
    """cos x as the arm's equations of motion take it, in Python."""
    return sin_cos_python(x)[1]


# The same operations in C (_trig.h, _ctrig.c): some 0.05 us a call against 0.5 (benchmarks/trig_change.py).
# Its interface (a float in, floats out) has no convention a stale build could misread: no version asked.
_ctrig = load("armgame.physics._ctrig", None)
if _ctrig is None:
    sin_cos, sin, cos = sin_cos_python, sin_python, cos_python
else:
    sin_cos, sin, cos = _ctrig.sin_cos, _ctrig.sin, _ctrig.cos


def sin_array(x: FloatArray, out: FloatArray | None = None) -> FloatArray:
    """``sin`` of every element of a float64 array, bit for bit; into ``out`` if given."""
    return sin_cos_array(x, out, None)[0]


def cos_array(x: FloatArray, out: FloatArray | None = None) -> FloatArray:
    """``cos`` of every element of a float64 array, bit for bit; into ``out`` if given."""
    return sin_cos_array(x, None, out)[1]


def sin_cos_array(x: FloatArray, sin_out: FloatArray | None = None,
                  cos_out: FloatArray | None = None) -> tuple[FloatArray, FloatArray]:
    """``sin_cos`` of every element of a float64 array, bit for bit; into ``sin_out``, ``cos_out`` if given
    (either may be ``x`` itself)."""
    x = np.asarray(x, dtype=np.float64)
    largest = float(np.max(np.abs(x))) if x.size else 0.0
    bad = None
    if not largest <= MAX_ANGLE:  # reduced as 0 (no warnings of inf - inf), then NaN
        bad = ~(np.abs(x) <= MAX_ANGLE)
        x = np.where(bad, 0.0, x)
    y = x * _INV_PIO2
    y += _SHIFT
    k = y - _SHIFT
    r = x - k * _PIO2_1
    r -= k * _PIO2_2
    r -= k * _PIO2_3
    z = r * r
    w = z * z
    # s = r + z r (S1 + z (S2 + z (S3 + z S4) + z w (S5 + z S6))), in the scalar's order
    p = z * _S4
    p += _S3
    p *= z
    p += _S2
    t = z * _S6
    t += _S5
    t *= z * w
    p += t
    p *= z
    p += _S1
    p *= z * r
    s = r + p
    # c = v + (((1 - v) - hz) + z (z (C1 + z (C2 + z C3)) + w w (C4 + z (C5 + z C6))))
    hz = 0.5 * z
    v = 1.0 - hz
    p = z * _C3
    p += _C2
    p *= z
    p += _C1
    p *= z
    t = z * _C6
    t += _C5
    t *= z
    t += _C4
    t *= w * w
    p += t
    p *= z
    t = 1.0 - v
    t -= hz
    t += p
    c = v + t
    n = y.view(np.int64) & 3
    odd = n == 1
    odd |= n == 3
    # The quadrant's signs as a multiplication by +-1: exact, and a zero's sign flips as negation flips it.
    sin_result = np.where(odd, c, s)
    sin_result *= _SIN_SIGN[n]
    cos_result = np.where(odd, s, c)
    cos_result *= _COS_SIGN[n]
    if bad is not None:
        sin_result[bad] = np.nan
        cos_result[bad] = np.nan
    if sin_out is None:
        sin_out = sin_result
    else:
        sin_out[...] = sin_result
    if cos_out is None:
        cos_out = cos_result
    else:
        cos_out[...] = cos_result
    return sin_out, cos_out
