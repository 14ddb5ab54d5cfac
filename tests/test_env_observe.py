"""Reach-v1's batch observation (``features.observe_v1``): its C pass and its numpy passes give the same bits,
and both are the formulas the single env's features are written in (``hand_velocity``, ``edge_distance``)."""

import math
import os

import numpy as np
import pytest

from armgame.env import features
from armgame.game.batch import BatchGameSession
from armgame.game.rules import GameConfig

needs_build = pytest.mark.skipif(not (features._c_observe_v1 or os.environ.get("ARMGAME_REQUIRE_COMPILED")),
                                 reason="armgame.env._cvector is not built here")


def played_batch(n=48, steps=40):
    """A batch after some random key presses, with a few angles set outside [-pi, pi] and a game near its end."""
    batch = BatchGameSession([GameConfig(seed=s, time_limit=2.0) for s in range(n)], exact=False)
    rng = np.random.default_rng(3)
    for _ in range(steps):
        batch.set_held(rng.integers(0, 2, (n, 4)).astype(bool))
        batch.advance(5)
    batch._x[0, :6] = [7.5, -7.5, math.pi, -math.pi, 40.0, -13.0]
    batch._x[1, 6:9] = [3.5, -100.25, 2 * math.pi]
    batch.steps[9] = batch.total_steps[9] + 3  # past its end: the clock reads 0, not below
    return batch


def observe(batch, dtype, compiled, edges=True):
    obs = np.full((batch.n, 15), -1, dtype=dtype)
    out = np.full(batch.n, np.nan) if edges else None
    features.observe_v1(batch.config.arm, batch.config.target_radius, batch._xs, batch.hand_trig(), batch._act,
                        batch.target_x, batch.target_y, batch.steps, batch.total_steps, obs, out, compiled=compiled)
    return obs, out


@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_the_numpy_passes_are_the_features_formulas(dtype):
    batch = played_batch()
    obs, edges = observe(batch, dtype, compiled=False)
    arm, (hx, hy) = batch.config.arm, batch.hand()
    vx, vy = features.hand_velocity(arm, batch.q1, batch.q2, batch.w1, batch.w2, batch.hand_trig())
    left = (batch.total_steps - np.minimum(batch.steps, batch.total_steps)) / batch.total_steps
    columns = [features.wrap_angles(batch.q1), features.wrap_angles(batch.q2), batch.w1, batch.w2,
               *batch._act, hx, hy, vx, vy, batch.target_x - hx, batch.target_y - hy, left]
    assert np.array_equal(obs, np.stack(columns, axis=1).astype(dtype))
    assert np.array_equal(edges, features.edge_distance(hx, hy, batch.target_x, batch.target_y,
                                                        batch.config.target_radius))
    assert obs[9, 14] == 0.0 and np.all(np.abs(obs[:, :2]) <= np.float32(math.pi))
    assert obs[2, 0] == obs.dtype.type(math.pi) and obs[4, 0] == obs.dtype.type(40.0 - 6 * math.tau)


@needs_build
@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_the_compiled_pass_gives_the_numpy_passes_bits(dtype):
    batch = played_batch()
    numpy_obs, numpy_edges = observe(batch, dtype, compiled=False)
    c_obs, c_edges = observe(batch, dtype, compiled=True)
    assert c_obs.tobytes() == numpy_obs.tobytes() and c_edges.tobytes() == numpy_edges.tobytes()
    without, none = observe(batch, dtype, compiled=True, edges=False)
    assert none is None and without.tobytes() == c_obs.tobytes()


@needs_build
def test_the_compiled_pass_refuses_arrays_of_the_wrong_size_or_kind():
    batch = played_batch(n=16, steps=1)
    with pytest.raises(ValueError, match="obs"):
        observe(batch, "int32", compiled=True)
    obs = np.empty((batch.n, 15), dtype="float32")
    args = (batch._xs, batch.hand_trig(), batch._act, batch.target_x, batch.target_y[:-1], batch.steps,
            batch.total_steps, obs, None, 1.0, 1.0, 0.1)
    with pytest.raises(ValueError, match="ty: expected"):
        features._c_observe_v1(*args)
    with pytest.raises(ValueError, match="same n games"):
        features._c_observe_v1(*args[:4], np.append(batch.target_y, 0.0), *args[5:])


def test_wrap_angles_fast_path_is_the_general_formula():
    inside = np.array([0.0, -math.pi, math.pi, 1.0, -3.0])
    assert features.wrap_angles(inside) is inside
    mixed = np.array([0.0, 7.0, -math.pi, 3.2, -40.0])
    assert np.array_equal(features.wrap_angles(mixed), np.where(np.abs(mixed) <= math.pi, mixed, np.clip(
        mixed - math.tau * np.rint(mixed / math.tau), -math.pi, math.pi)))


@needs_build
def test_the_compiled_keys_are_set_held():
    """``hold_keys``, which the discrete vector envs call, changes what ``set_held`` changes, to the bit: games
    over untouched, keys unchanged keep their goal and rate (here a level set before, not 0 or 1)."""
    batches = [played_batch(n=40, steps=3) for _ in range(2)]
    rng = np.random.default_rng(5)
    levels = rng.uniform(0.0, 1.0, (40, 4))
    for batch in batches:
        batch.set_levels(levels)
        batch.steps[[3, 17]] = batch.total_steps[[3, 17]]  # over: neither may touch them
    for _ in range(3):
        pressed = rng.integers(0, 2, (40, 4)).astype(bool)
        batches[0].set_held(pressed)
        b = batches[1]
        features._c_hold_keys(pressed, b.steps, b.total_steps, b._held, b._goal, b._rate, b._rise, b._decay)
        for name in ("_held", "_goal", "_rate"):
            assert getattr(batches[0], name).tobytes() == getattr(b, name).tobytes(), name
    assert not np.all(batches[0]._goal == batches[0]._held)  # some goals are still the levels
