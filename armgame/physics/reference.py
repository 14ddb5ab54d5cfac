"""An adaptive reference solution through scipy's DOP853, for offline runs and for tests.

Torques in armgame are piecewise constant (held over each physics step, switched by keys),
so the reference integrates each constant-torque segment separately: an adaptive solver
stepping across a jump in its right-hand side loses its order there.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

REFERENCE_TOLERANCE = 1e-12


def reference_trajectory(
    model: Any,
    state0: ArrayLike,
    t_eval: ArrayLike,
    segments: Sequence[tuple[float, tuple[float, float]]] = ((0.0, (0.0, 0.0)),),
    rtol: float = REFERENCE_TOLERANCE,
    atol: float = REFERENCE_TOLERANCE,
    method: str = "DOP853",
) -> NDArray[np.float64]:
    """States (q1, q2, qd1, qd2) at the times ``t_eval`` (non-negative, any order, repeats allowed).

    ``segments`` lists (start time, torque) pairs in increasing start order: the torque
    holds from its start until the next segment's. The first must start at or before 0.
    """
    # scipy.integrate takes about half a second to import: only runs that ask for the reference pay it
    # (every `armgame simulate` imports this module, most never call it).
    from scipy.integrate import solve_ivp

    times, where = np.unique(np.asarray(t_eval, dtype=float), return_inverse=True)
    if len(times) and times[0] < 0.0:
        raise ValueError("reference times must be >= 0")
    accel = model.component_dynamics("float").accel

    def make_rhs(t1: float, t2: float):
        def rhs(_t: float, y: NDArray[np.float64]) -> list[float]:
            a1, a2 = accel(y[0], y[1], y[2], y[3], t1, t2)
            return [y[2], y[3], a1, a2]

        return rhs

    out = np.empty((len(times), 4))
    y = np.asarray(state0, dtype=float).copy()
    out[times == 0.0] = y
    t_end = float(times[-1]) if len(times) else 0.0
    starts = [max(0.0, s) for s, _ in segments] + [np.inf]
    for k, (_, torque) in enumerate(segments):
        lo, hi = starts[k], min(starts[k + 1], t_end)
        if hi <= lo:
            continue
        inside = (times > lo) & (times < hi)
        sol = solve_ivp(
            make_rhs(*torque), (lo, hi), y, method=method, rtol=rtol, atol=atol,
            t_eval=np.append(times[inside], hi),
        )
        if not sol.success:
            raise RuntimeError(f"reference solver failed: {sol.message}")
        out[inside] = sol.y[:, :-1].T
        y = sol.y[:, -1]
        out[times == hi] = y
    return out[where.reshape(-1)]
