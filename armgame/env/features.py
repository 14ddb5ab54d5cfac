"""What the v1 envs add for learners: the hand's kinematics, observation bounds that hold, the dense reward.

One place for each formula: on numpy arrays for the vector envs (N games), in plain floats for the
single envs (``hand_and_velocity``: numpy's one-element arrays made a single env 3 times slower), the two
agreeing to round-off. The game's state stays in joint coordinates; a learner gets the hand and the
hand-to-target vector here rather than deriving them, which every user of v0 had to do.

The dense reward is progress toward the current target plus a bonus per hit::

    r_t = w (e_{t-1} - e_t) + bonus h_t - c resets_t

with ``e = max(0, |hand - target| - radius)``, the hand's distance to the target's edge, taken at the
end of each step; ``h_t`` the hits and ``resets_t`` the reset-key presses in step ``t``; ``c`` the
game's reset cost. On a step with a hit, ``e_t`` is 0 (the old target's edge was reached) and the
progress term restarts from the new target at the next step, so a new target far away costs
nothing. Summed over a game the progress telescopes, target by target::

    return = w (sum_k e0_k - e_end) + bonus H - c R

``e0_k`` the distance to target ``k``'s edge when it appeared (at the reset or at the end of the
step that hit the previous one), ``e_end`` the last target's at the end, ``H`` hits, ``R`` resets.
It is a potential-based shaping per target, so it pays no more for wandering and the best policy
still hits as many targets as it can (``tests/test_env_v1.py`` checks the sum).

>>> import numpy as np
>>> float(edge_distance(np.float64(0.3), np.float64(0.4), 0.0, 0.0, 0.05))  # 0.5 m from the centre
0.45
"""

from __future__ import annotations

import math

import numpy as np

from .._native import load
from ..game.rules import GameConfig
from ..physics.hand import hand_from_trig
from ..physics.params import TwoJointParams
from .errors import EnvArgumentError

#: armgame/env/_cvector.c where built, and only if it speaks this module's calling convention (VERSION 1;
#: ``armgame._native``): otherwise numpy's twins run.
_cvector = load("armgame.env._cvector", 1)
#: ``_cvector.observe_v1`` (None: ``observe_v1`` runs numpy).
_c_observe_v1 = None if _cvector is None else _cvector.observe_v1
#: ``_cvector.hold_keys``: ``BatchGameSession.set_held`` in one pass, for the vector envs (None: they call it).
_c_hold_keys = None if _cvector is None else _cvector.hold_keys

#: Reward per metre of progress toward the current target's edge (1 per 10 cm).
DEFAULT_PROGRESS_WEIGHT = 10.0
#: Reward per hit, on top of the progress that reached it.
DEFAULT_HIT_BONUS = 1.0
REWARDS = ("dense", "sparse")
#: Reach-v1's rewards: ``"score"`` too, whose return is the game's score (``score_shaping``).
REACH_REWARDS = ("dense", "sparse", "score")


def hand_velocity(arm: TwoJointParams, q1: np.ndarray, q2: np.ndarray, w1: np.ndarray,
                  w2: np.ndarray, trig: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The hand's velocity (m/s), the Jacobian times the joint velocities; ``trig``: the angles' cos q1, sin q1,
    cos(q1 + q2), sin(q1 + q2) where known (``BatchGameSession.hand_trig``: numpy's trig was most of a step)."""
    c1, s1, c12, s12 = (np.cos(q1), np.sin(q1), np.cos(q1 + q2), np.sin(q1 + q2)) if trig is None else trig
    w12 = w1 + w2
    return -arm.l1 * s1 * w1 - arm.l2 * s12 * w12, arm.l1 * c1 * w1 + arm.l2 * c12 * w12


def hand_and_velocity(arm: TwoJointParams, q1: float, q2: float, w1: float,
                      w2: float) -> tuple[float, float, float, float]:
    """The hand (as ``GameSession.hand``) and ``hand_velocity`` of one arm in plain floats, their trig shared:
    a single env steps 3 times as fast as through numpy's one-element arrays, and agrees with them to
    round-off (the vector tests)."""
    q12, w12 = q1 + q2, w1 + w2
    c1, s1, c12, s12 = math.cos(q1), math.sin(q1), math.cos(q12), math.sin(q12)
    hx, hy = hand_from_trig(arm.l1, arm.l2, c1, s1, c12, s12)
    return hx, hy, -arm.l1 * s1 * w1 - arm.l2 * s12 * w12, arm.l1 * c1 * w1 + arm.l2 * c12 * w12


def hand_speed_bound(arm: TwoJointParams, joint_speed: float) -> float:
    """A bound on either component of the hand's velocity when each joint speed is within ``joint_speed``.

    ``|vx| <= l1 |w1| + l2 |w1 + w2| <= (l1 + 2 l2) w``, and the same for ``vy``.
    """
    return (arm.l1 + 2.0 * arm.l2) * joint_speed


def edge_distance(hx: np.ndarray, hy: np.ndarray, tx: np.ndarray, ty: np.ndarray, radius: float) -> np.ndarray:
    """The hand's distance to the target's edge (m), 0 inside it."""
    return np.maximum(0.0, np.hypot(hx - tx, hy - ty) - radius)


def muscle_levels(action: np.ndarray, centred: bool) -> np.ndarray:
    """A continuous action as muscle levels in [0, 1]: v0's action is the level (clipped), v1's ``a`` in
    [-1, 1] is ``(a + 1) / 2`` (clipped), so a policy's zero is a half-active muscle."""
    if centred:
        action = (action + 1.0) * 0.5
    return np.clip(action, 0.0, 1.0)


OBSERVATION_DTYPES = ("float32", "float64")


def check_dtype(value: object) -> str:
    """``observation_dtype``: float32 (the default: what networks take) or float64 (the game's state exactly)."""
    name = np.dtype(value).name if isinstance(value, type) and issubclass(value, np.floating) else value
    if name not in OBSERVATION_DTYPES:
        raise EnvArgumentError(f"observation_dtype must be 'float32' or 'float64', got {value!r}")
    return str(name)


def check_reward(reward: object, progress_weight: object, hit_bonus: object,
                 kinds: tuple[str, ...] = REWARDS) -> tuple[str, float, float]:
    """The reward arguments of a v1 env, checked: one line naming a bad one."""
    if reward not in kinds:
        names = ", ".join(repr(k) for k in kinds[:-1]) + f" or {kinds[-1]!r}"
        raise EnvArgumentError(f"reward must be {names}, got {reward!r}")
    for name, value in (("progress_weight", progress_weight), ("hit_bonus", hit_bonus)):
        if isinstance(value, bool) or not isinstance(value, int | float) or not 0.0 <= value <= 1000.0:
            raise EnvArgumentError(f"{name} must be a number from 0 to 1000, got {value!r}")
    return str(reward), float(progress_weight), float(hit_bonus)  # type: ignore[arg-type]


def reach_bounds_v1(config: GameConfig, joint_speed: float) -> tuple[np.ndarray, np.ndarray]:
    """The bounds of a Reach-v1 observation (see ``ReachV1Env``), in float64."""
    arm = config.arm
    reach = arm.l1 + arm.l2
    xmin, xmax, ymin, ymax = config.view
    r, w, pi = config.target_radius, joint_speed, math.pi
    v = hand_speed_bound(arm, w)
    # A target's centre lies within the view less its radius; the hand within the arm's reach.
    low = np.array([-pi, -pi, -w, -w, 0, 0, 0, 0, -reach, -reach, -v, -v, xmin + r - reach, ymin + r - reach, 0.0])
    high = np.array([pi, pi, w, w, 1, 1, 1, 1, reach, reach, v, v, xmax - r + reach, ymax - r + reach, 1.0])
    return low, high


def wrap_angles(q: np.ndarray) -> np.ndarray:
    """Angles in [-pi, pi]: themselves when already there, else ``q - 2 pi round(q / 2 pi)``."""
    # The usual case, every angle already in range, costs two reductions instead of six passes and three arrays.
    if q.size and -math.pi <= q.min() and q.max() <= math.pi:
        return q
    wrapped = q - math.tau * np.rint(q / math.tau)
    np.clip(wrapped, -math.pi, math.pi, out=wrapped)
    return np.where(np.abs(q) <= math.pi, q, wrapped)


def observe_v1(arm: TwoJointParams, radius: float, x: np.ndarray, trig: np.ndarray, activation: np.ndarray,
               target_x: np.ndarray, target_y: np.ndarray, steps: np.ndarray, total_steps: np.ndarray,
               obs: np.ndarray, edges: np.ndarray | None = None, compiled: bool | None = None) -> None:
    """Reach-v1 observations of ``n`` games into ``obs`` ((n, 15), float32 or float64, C-contiguous) and,
    unless None, the hands' distances to their targets' edges (``edge_distance``) into ``edges`` (n,).

    ``x``: rows q1, q2, w1, w2 (a batch's state, at least 4 rows of n); ``trig``: rows cos q1, sin q1,
    cos(q1 + q2), sin(q1 + q2) (``BatchGameSession.hand_trig``); ``activation``: the 4 muscles' rows (4, n);
    ``steps``, ``total_steps``: int64. ``compiled``: ``_cvector.c``'s one pass (None: where built), else numpy's
    passes; the two give the same bits (tests/test_env_observe.py).
    """
    if compiled is None:
        compiled = _c_observe_v1 is not None
    if compiled:
        if _c_observe_v1 is None:
            raise RuntimeError("armgame.env._cvector is not built (reinstall with a C compiler: pip install -e .)")
        _c_observe_v1(x, trig, activation, target_x, target_y, steps, total_steps, obs, edges,
                      float(arm.l1), float(arm.l2), float(radius))
        return
    l1, l2 = arm.l1, arm.l2
    q1, q2, w1, w2 = x[0], x[1], x[2], x[3]
    c1, s1, c12, s12 = trig[0], trig[1], trig[2], trig[3]
    # The hand once, for both the observation and the distance: ``hand_from_trig``'s operations in its order
    # (l1 c1 + l2 c12, l1 s1 + l2 s12, so the same bits), written out to build them in scratch arrays: its
    # form makes a temporary array per product, and this pass runs at every step of every game of a batch.
    hx = l1 * c1
    scratch = np.multiply(l2, c12)
    hx += scratch
    hy = np.multiply(l1, s1)
    hy += np.multiply(l2, s12, out=scratch)
    obs[:, 0] = wrap_angles(q1)
    obs[:, 1] = wrap_angles(q2)
    obs[:, 2] = w1
    obs[:, 3] = w2
    obs[:, 4:8] = activation.T
    obs[:, 8] = hx
    obs[:, 9] = hy
    # hand_velocity's operations, in its order: (-l1 s1) w1 - (l2 s12) w12 and (l1 c1) w1 + (l2 c12) w12.
    w12 = w1 + w2
    v = np.multiply(-l1, s1)
    v *= w1
    np.multiply(l2, s12, out=scratch)
    scratch *= w12
    v -= scratch
    obs[:, 10] = v
    np.multiply(l1, c1, out=v)
    v *= w1
    np.multiply(l2, c12, out=scratch)
    scratch *= w12
    v += scratch
    obs[:, 11] = v
    obs[:, 12] = np.subtract(target_x, hx, out=v)
    obs[:, 13] = np.subtract(target_y, hy, out=scratch)
    obs[:, 14] = (total_steps - np.minimum(steps, total_steps)) / total_steps
    if edges is not None:
        # hypot's sign-symmetric, so the way to the target serves as the distance's legs.
        np.hypot(v, scratch, out=edges)
        edges -= radius
        np.maximum(0.0, edges, out=edges)
