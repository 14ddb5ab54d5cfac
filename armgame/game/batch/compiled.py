"""The compiled kernel's wrapper: the batched game's hot loop in C, optional, and exact.

Owns the way a batch runs on ``armgame/game/_ckernel.c`` (built by ``pip install`` as
``armgame.game._ckernel``; it stays beside the game package so the build does not move), and
``play`` there; the kernel's calling convention (its version, its params' layout) is
``game/session.py``'s, whose single game runs on the same file (``compiled_kernel`` loads it for
both). It reads the batch through the values the session hands it (``kernel_inputs``), never the
session itself. Invariant: a game run here is the single session's game bit for bit (``fast``:
within ``session.STATE_TOLERANCE``); a build of another convention is never called.

``_ckernel`` (``_ckernel.c``, built by ``pip install`` where a C compiler exists) runs each
game of a batch from its step to a halt step in registers: the muscles, RK4 and the hand's
slack, with the muscle keys' commands applied at their steps. It stops a game early only
when its hand may be on its target, and the batch judges that with the single session's own
test and rules (the ``HitTest`` the session passes it, ``BatchGameSession._hit_test``). Its
arithmetic is the single session's, operation for operation, with the C library's cos and sin,
which Python's ``math`` calls too: a batched game is the single game bit for bit
(tests/test_batch.py checks states with ``==``). With ``fast`` (``BatchGameSession(exact=False)``,
games up to 60 s) RK4's elbow cos and sin come by angle addition instead, as numpy's fast kernel
takes them: round-off, within ``session.STATE_TOLERANCE`` (tests/test_batch_fast.py runs both kernels).

Where it was not built (no compiler) or is stale, ``AVAILABLE`` is False and the batch runs
its numpy kernel: the same results, slower. It runs RK4, the game's integrator; batches of the
Euler schemes go through numpy.

Speed (``python benchmarks/class_speed.py``): see the README's "Performance" section.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...physics.batch import SERIES_LIMIT
from ..session import DOWN, KERNEL_VERSION, compiled_kernel, kernel_mode, kernel_params, speaks_our_convention
from .kernel_inputs import BatchArrays, HitTest, KernelInputs, Runaway
from .numpy_kernel import NEAR, hand_move_bounds
from .schedule import MuscleEvents
from .variant import FLAG_RUNAWAY

#: The C module, or None (not built, or a build of another convention).
_ckernel = compiled_kernel()

__all__ = ["AVAILABLE", "KERNEL_VERSION", "CompiledKernel", "available", "speaks_our_convention"]

#: Whether the compiled kernel is here to use.
AVAILABLE = _ckernel is not None

#: Whether ``run`` steps games side by side (``_cbatch.c``'s lanes) or one at a time, its reference. The same
#: results either way (tests/test_lanes.py); the lanes are the faster, so only the tests switch them off.
LANES = True


def available() -> bool:
    """``AVAILABLE``, read when asked (tests switch it off): how ``session`` asks, importing this module's
    names rather than the package, whose ``__init__`` imports ``session`` (an import circle)."""
    return AVAILABLE


class CompiledKernel:
    """Runs a batch's games to given steps with ``_ckernel``, on the batch's own arrays (``arrays``).

    ``hit`` is called for each game the kernel stops at a target's edge; it decides and scores the hit.
    ``runaway`` for each game the speed guard stopped (``arrays.loads``), which runs no further in the call."""

    def __init__(self, inputs: KernelInputs, arrays: BatchArrays, hit: HitTest, runaway: Runaway | None = None) -> None:
        if _ckernel is None:
            raise RuntimeError("the compiled kernel is not built (reinstall with a C compiler: pip install -e .)")
        self.arrays, self.hit, self.runaway = arrays, hit, runaway
        #: RK4's elbow trig by angle addition (round-off, not bit for bit; see ``_ckernel.c``).
        self.fast = bool(inputs.fast)
        model, config = inputs.model, inputs.config
        p = model.params
        dt, radius = config.dt, config.target_radius
        self.mode = kernel_mode(p)
        self.params = np.array(kernel_params(model, dt, inputs.shoulder, inputs.elbow, radius,
                                             NEAR * radius * radius, hand_move_bounds(p.l1, p.l2),
                                             SERIES_LIMIT * SERIES_LIMIT), dtype=float)
        self.flags = np.zeros(arrays.n, dtype=np.uint8)
        self.no_events = MuscleEvents.none(arrays.n)

    def run(self, halt: np.ndarray, events: MuscleEvents | None = None) -> None:
        """Every game ``i`` to step ``halt[i]`` (none past its end), its hits scored on the way."""
        a = self.arrays
        ev = self.no_events if events is None else events
        given = halt = np.ascontiguousarray(halt, dtype=np.int64)
        while _ckernel.run(self.params, self.mode, self.fast, a.n, a.xs, a.act, a.goal, a.rate, a.slack,
                           a.target_x, a.target_y, a.steps, halt, ev.cursor, ev.end, ev.step, ev.muscle, ev.goal,
                           ev.rate, self.flags, a.trig, LANES, a.moments, a.loads):
            for i in np.flatnonzero(self.flags).tolist():
                if self.flags[i] == FLAG_RUNAWAY and self.runaway is not None:
                    self.runaway(i)
                    if halt is given:  # the caller's array stays as it was: a copy halts the game where it is put back
                        halt = halt.copy()
                    halt[i] = a.steps[i]
                else:
                    self.hit(i, a.xs[:4, i], int(a.steps[i]))

    def play(self, events: MuscleEvents, specials: list[tuple[int, int, str]], limits: np.ndarray,
             press: Callable[[int, str, str], object]) -> None:
        """``BatchGameSession.play`` here: each game runs on its own to its next reset or tab, or its stop.

        The kernel applies the muscle commands itself; at a game's reset or tab step (after that
        step's muscle commands, as ``play`` orders them) the key goes through ``press``, the session's
        ``key_event``.
        """
        pending: dict[int, list[tuple[int, str]]] = {}
        for step, i, key in specials:  # in timeline order: by step within each game
            pending.setdefault(i, []).append((step, key))
        halt = limits.copy()
        for i, keys in pending.items():
            keys.reverse()  # popped from the end
            halt[i] = min(keys[-1][0], int(limits[i]))
        while True:
            self.run(halt, events)
            if not pending:
                return
            for i in list(pending):
                keys = pending[i]
                at = keys[-1][0]  # where game i now is: its halt
                while keys and keys[-1][0] == at:
                    press(i, keys.pop()[1], DOWN)
                if keys:
                    halt[i] = min(keys[-1][0], int(limits[i]))
                else:
                    del pending[i]
                    halt[i] = limits[i]
