"""The harder tasks' physics in a batch (armgame.game.batch.variant and the compiled lanes' loaded step): motor
noise, a field at the hand and the speed guard, each game equal to the single ``GameVariant`` game fed the same
keys, bit for bit in the exact kernel and within STATE_TOLERANCE in the fast one."""

import numpy as np
import pytest

from armgame.game.batch import STATE_TOLERANCE, BatchGameSession
from armgame.game.batch.compiled import AVAILABLE, _ckernel
from armgame.game.batch.variant import BatchMuscleNoise
from armgame.game.rules import GameConfig
from armgame.game.variant import GameVariant, MuscleNoise, RunawayError, noise_generator
from armgame.lab.presets import VISCOUS_B

pytestmark = pytest.mark.skipif(not AVAILABLE, reason="the loaded step is the compiled kernel's (no C compiler here)")

BOUND = 34.4  # about the game's joint speed bound (rad/s): the guard of a field's game


def viscous(strength):
    return tuple(tuple(strength * v for v in row) for row in VISCOUS_B)


VARIANTS = {
    "noise": GameVariant(decision_steps=5, motor_noise=0.3),
    "curl": GameVariant(decision_steps=5, field="curl", field_parameter=-2.0, speed_limit=BOUND),
    "viscous": GameVariant(decision_steps=4, field="viscous", field_parameter=viscous(2.0), speed_limit=BOUND),
    "all": GameVariant(hold_steps=20, motor_noise=0.5, decision_steps=5, field="curl", field_parameter=2.0,
                       speed_limit=BOUND),
}


def play_both(variant, exact, decisions=300, n=6, radius=0.12, seed=20, pump=False):
    """Random keys (or, ``pump``, the keys feeding each joint energy) into the batch and into single games; checks
    every decision that hits, steps, the end and the stop's reason agree and the states and activations are
    equal (exact) or within STATE_TOLERANCE. Returns the hits, the games stopped and the largest difference."""
    configs = [GameConfig(seed=seed + i, time_limit=10.0, target_radius=radius) for i in range(n)]
    batch = BatchGameSession(configs, exact=exact, variant=variant)
    assert batch.variant is not None and batch.compiled is not None
    singles = [variant.session(c) for c in configs]
    noises = [variant.noise(c, s) for c, s in zip(configs, singles, strict=True)]
    reasons: dict[int, str] = {}
    rng = np.random.default_rng(seed)
    largest = 0.0
    held = np.zeros((n, 4), dtype=bool)
    for _ in range(decisions):
        if pump:
            w = batch._x[2:4].T
            held = np.column_stack([w[:, 0] > 0, w[:, 0] <= 0, w[:, 1] > 0, w[:, 1] <= 0])
        else:  # keys held for a while, so that the arm sweeps across the targets
            held = np.where(rng.random((n, 1)) < 0.1, rng.random((n, 4)) < 0.5, held)
        batch.set_held(held)
        batch.apply_noise()
        batch.advance(variant.decision_steps)
        for i, single in enumerate(singles):
            if single.over:
                continue
            for m, key in enumerate(single.muscles.keys):
                if single.held[m] != bool(held[i, m]):
                    single.key_event(key, "down" if held[i, m] else "up")
            if noises[i] is not None:
                noises[i].apply(single)
            try:
                single.advance(variant.decision_steps)
            except RunawayError as stop:
                single.total_steps = single.steps
                reasons[i] = str(stop)
        for i, single in enumerate(singles):
            assert (single.rules.board.hits, single.steps, single.over) == \
                (batch.hits[i], batch.steps[i], bool(batch.over[i])), i
            difference = np.abs(np.array(single.state) - batch._x[:4, i]).max()
            largest = max(largest, float(difference))
            if exact:
                assert difference == 0.0 and list(single.muscles.activation) == batch.activation[i].tolist(), i
        assert batch.stop_reasons == reasons and batch.stopped.tolist() == [i in reasons for i in range(n)]
    assert largest <= STATE_TOLERANCE
    return sum(s.rules.board.hits for s in singles), len(reasons), largest


@pytest.mark.parametrize("name", sorted(VARIANTS))
@pytest.mark.parametrize("exact", [True, False])
def test_a_batch_with_noise_or_a_field_is_the_single_games_variant(name, exact):
    hits, stopped, largest = play_both(VARIANTS[name], exact)
    assert hits > 0 and stopped == 0  # play reached targets; the guard never acted within the range
    assert (largest == 0.0) == exact or name == "noise"  # the fast kernel rounds differently (noise: maybe not)


def test_the_variant_changes_the_games():
    """The comparison above would pass if both sides lost the noise or the field: they change the states."""
    configs = [GameConfig(seed=3, time_limit=2.0)]
    finals = []
    for variant in (GameVariant(decision_steps=5), *VARIANTS.values()):
        batch = BatchGameSession(configs, variant=variant)
        batch.set_held(np.array([[True, False, False, True]]))
        for _ in range(40):
            batch.apply_noise()
            batch.advance(5)
        finals.append(tuple(batch._x[:4, 0]))
    assert len(set(finals)) == len(finals)


@pytest.mark.parametrize("exact", [True, False])
def test_the_guard_stops_a_runaway_where_the_single_game_does(exact):
    """A viscous field far beyond its range with the keys that feed the arm energy: every game runs away; each
    stops at the decision the single game stops at, put back to that decision's start, with the same reason."""
    runaway = GameVariant(decision_steps=5, field="viscous", field_parameter=viscous(10.0), speed_limit=BOUND)
    _, stopped, _ = play_both(runaway, exact, decisions=400, n=4, pump=True)
    assert stopped == 4


def test_a_stopped_game_takes_no_input_and_starts_again_when_restarted():
    runaway = GameVariant(decision_steps=5, field="viscous", field_parameter=viscous(10.0), speed_limit=BOUND)
    batch = BatchGameSession([GameConfig(seed=s, time_limit=20.0) for s in (1, 2)], variant=runaway)
    while not batch.stopped[0]:
        w = batch._x[2:4].T
        batch.set_held(np.column_stack([w[:, 0] > 0, w[:, 0] <= 0, w[:, 1] > 0, w[:, 1] <= 0]))
        batch.advance(5)
    state, steps = batch._x[:4, 0].copy(), int(batch.steps[0])
    assert batch.over[0] and "past 34.4 rad/s" in batch.stop_reasons[0] and steps < batch.total_steps[0]
    batch.set_held(np.ones((2, 4), dtype=bool))
    batch.advance(5)
    assert (batch._x[:4, 0] == state).all() and batch.steps[0] == steps
    batch.restart(np.array([True, False]), [7])
    assert not batch.stopped[0] and 0 not in batch.stop_reasons and batch.steps[0] == 0


def test_the_noise_draws_a_games_stream_in_blocks_as_the_single_game_draws_it():
    """Games started at different rows of a block, refilled across blocks: every factor is MuscleNoise's."""
    noise = BatchMuscleNoise(0.3, 0.02, 3)
    seeds = {0: 11, 1: 12, 2: 13}
    singles = {}
    for step in range(2 * BatchMuscleNoise.BLOCK + 9):
        for i, at in ((0, 0), (1, 5), (2, BatchMuscleNoise.BLOCK)):
            if step == at:
                noise.start(i, seeds[i])
                session = GameVariant(motor_noise=0.3, decision_steps=5).session(GameConfig(seed=seeds[i]))
                singles[i] = (session, MuscleNoise(0.3, seeds[i], 0.02, session), session.muscles.moments)
        factors = noise.factors()
        for i, (session, single, base) in singles.items():
            single.apply(session)
            moments = session.muscles.moments
            assert [f * s for f, (s, _) in zip(factors[i].tolist(), base, strict=True)] == [m[0] for m in moments]
    assert len(singles) == 3 and noise_generator(11).standard_normal() != noise_generator(12).standard_normal()


def test_a_batch_refuses_noise_or_a_field_without_the_compiled_kernel():
    with pytest.raises(Exception, match="compiled kernel only"):
        BatchGameSession([GameConfig()], kernel="numpy", variant=VARIANTS["noise"])
    with pytest.raises(ValueError, match="decision by decision"):
        BatchGameSession([GameConfig()], variant=VARIANTS["curl"]).play([[]])


def test_the_kernel_refuses_bad_loads_and_moments_before_any_step():
    batch = BatchGameSession([GameConfig(time_limit=1.0)], variant=VARIANTS["all"])
    a, c = batch.arrays, batch.compiled
    ev = c.no_events
    halt = np.array([10], dtype=np.int64)

    def run(moments, loads, lanes=True):
        return _ckernel.run(c.params, c.mode, c.fast, 1, a.xs, a.act, a.goal, a.rate, a.slack, a.target_x,
                            a.target_y, a.steps, halt, ev.cursor, ev.end, ev.step, ev.muscle, ev.goal, ev.rate,
                            c.flags, a.trig, lanes, moments, loads)

    good = np.array([1.0, 2.0, 0.0, 0.0, 0.0, 30.0])
    for bad, match in ((np.array([3.0, 2.0, 0, 0, 0, 30.0]), "kind"), (np.array([1.0, np.nan, 0, 0, 0, 30.0]), "kind"),
                       (np.array([1.0, 2.0, 0, 0, 0, 0.0]), "guard"), (np.zeros(5), "bytes")):
        with pytest.raises(ValueError, match=match):
            run(None, bad)
    with pytest.raises(ValueError, match="not finite"):
        run(np.full((8, 1), np.inf), good)
    with pytest.raises(ValueError, match="lanes"):
        run(None, good, lanes=False)
    assert batch.steps[0] == 0  # nothing ran
    run(np.ones((8, 1)), good)
    assert batch.steps[0] == 10


def test_a_single_noisy_game_runs_its_compiled_loop_with_the_python_loops_floats():
    """``GameSession.set_muscle_moments`` packs the compiled loop's moments again each decision, so a noisy single
    game runs in C (it ran the Python loop) with the same floats; a field's game still runs the Python loop."""
    variant = VARIANTS["noise"]
    config = GameConfig(seed=5, time_limit=10.0, target_radius=0.15)
    games = []
    for compiled in (True, False):
        session = variant.session(config)
        if not compiled:
            session._compiled = None  # the Python loop, the reference
        noise = variant.noise(config, session)
        rng = np.random.default_rng(1)
        held = np.zeros(4, dtype=bool)
        while not session.over:
            held = np.where(rng.random() < 0.1, rng.random(4) < 0.5, held)
            for m, key in enumerate(session.muscles.keys):
                if session.held[m] != held[m]:
                    session.key_event(key, "down" if held[m] else "up")
            noise.apply(session)
            session.advance(variant.decision_steps)
        games.append((session.state, session.rules.board.hits, session.muscles.activation))
    assert games[0] == games[1] and games[0][1] > 0
    pushed = VARIANTS["curl"].session(config)
    assert pushed._compiled is not None and pushed._compiled[2] is not pushed._physics_step  # the Python loop


@pytest.mark.parametrize("name", ["curl", "viscous"])
def test_a_single_fields_compiled_step_is_the_python_loaded_arms_step(name):
    """``GameSession.field_step`` (``_ckernel.rk4_step_loaded``) against ``physics.loads``' RK4 in Python, on states
    across and beyond the game's range: the same floats, so a field's replays recorded before it still verify."""
    from armgame.physics.integrators import Integrator
    from armgame.physics.loads import loaded_arm

    variant = VARIANTS[name]
    session = variant.session(GameConfig())
    compiled = session.field_step(1 if name == "curl" else 2, variant.field_parameters)
    python = Integrator("rk4", loaded_arm(session.model, variant.loads())).step_components
    rng = np.random.default_rng(4)
    for q1, q2, w1, w2, t1, t2 in rng.uniform(-1, 1, (2000, 6)) * (4.0, 3.0, 40.0, 40.0, 30.0, 30.0):
        assert compiled(q1, q2, w1, w2, t1, t2, 0.004) == python(q1, q2, w1, w2, t1, t2, 0.004)
    with pytest.raises(ValueError, match="kind"):
        session.field_step(3, variant.field_parameters)(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.004)
    with pytest.raises(ValueError, match="p0 is not finite"):
        session.field_step(1, (np.inf, 0.0, 0.0, 0.0))(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.004)


def test_noise_alone_has_no_guard_a_state_gone_non_finite_is_the_single_games_error():
    """Without a field there is no guard: a game whose physics blows up (muscles a million times too strong) raises
    NonFiniteStateError in the batch as in the single game, not a runaway's stop."""
    import dataclasses

    from armgame.game.muscles import MuscleSpec
    from armgame.game.session import NonFiniteStateError

    base = GameConfig(seed=2, time_limit=2.0)
    strong = dataclasses.replace(base, muscles=tuple(
        MuscleSpec(m.name, m.key, (m.moment[0] * 1e6, m.moment[1] * 1e6), m.rise_time, m.decay_time)
        for m in base.muscles))
    variant = VARIANTS["noise"]
    single = variant.session(strong)
    batch = BatchGameSession([strong], variant=variant)
    single.key_event(single.muscles.keys[0], "down")
    batch.set_held(np.array([[True, False, False, False]]))
    with pytest.raises(NonFiniteStateError):
        for _ in range(100):
            variant.noise(strong, single).apply(single)
            single.advance(5)
    with pytest.raises(NonFiniteStateError):
        for _ in range(100):
            batch.apply_noise()
            batch.advance(5)
    assert not batch.stopped.any()
