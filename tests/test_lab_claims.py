"""The numbers docs/lab.md and docs/physics.md state, measured: each is computed here (cheaply: the learner's
equations, the arm's inertia, the presets, the code's limits) and looked for in the docs' text at its printed
precision, so a change to the code or the docs that makes them disagree fails. The numbers of whole bot runs
(the curl, lesson, viscous, savings and spontaneous tables, the field the bot measures, its speed) cost seconds
each and are checked by ``benchmarks/lab_claims.py`` instead; docs/lab.md's "Motor noise" and the fits' table
by ``benchmarks/fit_coverage.py`` and ``benchmarks/lab_claims.py``."""

import math
import re
from pathlib import Path

import numpy as np
import pytest

from armgame.lab.learner import TwoRateLearner, simulate
from armgame.lab.perturbations import VISCOUS_MAX_FEEDING
from armgame.lab.presets import SAVINGS_WASHOUT, preset
from armgame.lab.protocol import CHANNEL_DAMPING, CHANNEL_STIFFNESS
from armgame.lab.session import LabSession, lab_config

DOCS = Path(__file__).resolve().parent.parent / "docs"


def _text(name: str) -> str:
    """The doc's text with every run of whitespace one space (a number's sentence may wrap anywhere)."""
    return re.sub(r"\s+", " ", (DOCS / name).read_text(encoding="utf-8"))


LAB, PHYSICS = _text("lab.md"), _text("physics.md")


def _says(text: str, *phrases: str) -> None:
    for phrase in phrases:
        assert phrase in text, f"the docs should say {phrase!r}"


def _trials_to_half(estimate: np.ndarray) -> int:
    """Trials learned from before the estimate first reaches half the field."""
    return int(np.argmax(estimate >= 0.5))


def test_the_learner_half_lives_and_savings():
    r = TwoRateLearner()
    _says(LAB, f"`A_f = {r.retention_fast:g}`, `A_s = {r.retention_slow:g}`, `B_f = {r.rate_fast:g}`, "
               f"`B_s = {r.rate_slow:g}`",
          f"the fast process halves in {math.log(0.5) / math.log(r.retention_fast):.1f} trials, the slow one in "
          f"{math.log(0.5) / math.log(r.retention_slow):.0f})")
    first = _trials_to_half(simulate(TwoRateLearner(), np.ones(80))["estimate"])
    counter = TwoRateLearner()
    simulate(counter, np.ones(80))
    simulate(counter, -np.ones(4))
    again = _trials_to_half(simulate(counter, np.ones(80))["estimate"])
    _says(LAB, f"re-learns half the field in {again} trials, against {first} the first time")
    washed = TwoRateLearner()
    simulate(washed, np.ones(80))
    simulate(washed, np.zeros(SAVINGS_WASHOUT))
    left = float(washed.estimate)
    slow = _trials_to_half(simulate(washed, np.ones(80))["estimate"])
    _says(LAB, f"({SAVINGS_WASHOUT} trials: {100 * left:.1f}% of the field left)", f"re-learning takes {slow} trials")


def test_the_viscous_field_and_its_scale():
    published = np.array([[-10.1, -11.2], [-11.2, 11.1]])
    scaled = np.asarray(preset("viscous").blocks[1].perturbation.matrix)
    np.testing.assert_array_equal(scaled, published / 8)
    low, high = np.linalg.eigvalsh(published)
    assert np.array_equal(published, published.T)  # so it has no curl part at all: "symmetric", not "nearly"
    _says(LAB, "Shadmehr & Mussa-Ivaldi's matrix is symmetric", f"(eigenvalues {high:.1f} and {low:.1f} N s/m)",
          f"its largest singular value, {np.linalg.svd(published)[1][0]:.1f} N s/m",
          f"one eighth of the matrix, largest gain {np.linalg.svd(scaled)[1][0]:.2f} N s/m",
          "`[[-1.2625, -1.4], [-1.4, 1.3875]]`")
    assert scaled.tolist() == [[-1.2625, -1.4], [-1.4, 1.3875]]


def test_the_task_geometry_the_endpoint_mass_and_the_channel():
    protocol = preset("curl")
    session = LabSession(lab_config(protocol, 10), protocol)
    arm = session.model
    hx, hy = session.home
    _says(LAB, f"({hx:.3f}, {hy:.3f}) m); {protocol.targets} targets lie {protocol.distance:.2f} m around it")
    postures = [np.asarray(session.config.start_posture)]
    postures += [arm.inverse_kinematics(np.array(t)) for t in protocol.target_positions(session.home)]
    masses = [np.linalg.eigvalsh(np.linalg.inv(arm.jacobian(q) @ np.linalg.inv(arm.mass_matrix(q))
                                               @ arm.jacobian(q).T)) for q in postures]
    lightest = min(m[0] for m in masses)
    _says(LAB, f"({lightest:.2f} kg in its lightest direction, {masses[0][1]:.1f} kg in its heaviest at home and "
               f"up to {max(m[1] for m in masses[1:]):.2f} kg at the targets)")
    k, c, dt = CHANNEL_STIFFNESS, CHANNEL_DAMPING, session.config.dt
    s = np.roots([lightest, c, k])
    _says(LAB, f"the low end, {k:,.0f} N/m", f"and {c:.0f} N s/m damps it well (damping ratio "
               f"{c / (2 * math.sqrt(k * lightest)):.2f} at the lightest mass)",
          f"The defaults give `|s| dt = {max(abs(s)) * dt:.2f}` at the game's {dt * 1000:.0f} ms")


def test_the_presets_block_lengths():
    def lengths(name: str) -> list[int]:
        return [b.trials for b in preset(name).blocks]
    curl, lesson = lengths("curl"), lengths("lesson")
    _says(LAB, f"baseline {curl[0]} trials, exposure {curl[1]}, washout {curl[2]} (`lesson`: {lesson[0]}, "
               f"{lesson[1]} and {lesson[2]}, to {preset('lesson').targets} targets)")
    savings, spontaneous = lengths("savings"), lengths("spontaneous")
    _says(LAB, f"`savings` (baseline {savings[0]}, exposure {savings[1]}, the opposite field for {savings[2]} "
               f"trials, re-exposure {savings[3]})",
          f"then {spontaneous[3]} error-clamp trials", f"adaptation index; {sum(spontaneous)} trials")


def test_the_physics_docs_numbers():
    from armgame import limits, simulation
    from armgame.physics.defaults import BLOWUP_SPEED
    from armgame.physics.reference import REFERENCE_TOLERANCE
    from armgame.scenes import get_scene

    _says(PHYSICS, f"over the budget ({limits.MAX_SIMULATE_STEPS:,} steps or {limits.MAX_SIMULATE_ROWS:,} rows",
          f"`--initial` takes angles within +-{math.degrees(simulation.MAX_INITIAL_ANGLE):.0f} deg and speeds within "
          f"+-{math.degrees(simulation.MAX_INITIAL_SPEED):,.0f} deg/s",
          f"a joint faster than 10^{math.log10(BLOWUP_SPEED):.0f} rad/s",
          f"(scipy's adaptive solver at rtol = atol = {REFERENCE_TOLERANCE:.0e}, the reference)")
    passive = get_scene("passive")
    x, y = passive.model.hand(np.asarray(passive.initial[:2]))
    _says(PHYSICS, f"hand starting at ({x:.4f}, {y:.4f}) m")
    q1, q2 = lab_config(preset("curl"), 10).start_posture
    _says(PHYSICS, f"The game's start posture is q1 = {math.degrees(q1):.0f} deg, q2 = {math.degrees(q2):.0f} deg")


def test_the_task_protocol_and_option_numbers():
    """The task's defaults, the clock, the limits of a protocol file and of the commands, as docs/lab.md says them."""
    from armgame.commands.analyze import MAX_CLASS_FILES
    from armgame.lab import fit
    from armgame.lab.learner import MAX_TUNING_WIDTH_DEG as WIDEST
    from armgame.lab.learner import MIN_TUNING_WIDTH_DEG as NARROWEST
    from armgame.lab.learner import TUNING_CENTRES, TUNING_WIDTH_DEG, DirectionalLearner
    from armgame.lab.perturbations import Viscous
    from armgame.lab.protocol import MAX_CHANNEL_DAMPING, MAX_CHANNEL_STIFFNESS, Protocol
    from armgame.ui.playback import REPLAY_SPEEDS

    p = Protocol("defaults", preset("curl").blocks)
    _says(LAB, f"{p.targets} targets lie {p.distance:.2f} m around it",
          f"home and targets have a {p.target_radius:.2f} m radius",
          f"for a random {p.delay[0]:.1f} to {p.delay[1]:.1f} s",
          f"on the target for {p.hold_time:.1f} s",
          f"a miss {p.timeout:g} s after the go cue",
          # The protocol file's comment, its lines between the keys it sets:
          f"defaults: targets = {p.targets}, distance = {p.distance:.2f},",
          f"# target_radius = home_radius = {p.target_radius:.2f}, hold_time = {p.hold_time:.1f}, delay_min = "
          f"{p.delay[0]:.1f},", f"# delay_max = {p.delay[1]:.1f}, timeout = {p.timeout:.1f}, first_target_deg = "
          f"{p.first_target_deg:g},", f"# home_shoulder_deg = {p.home_posture_deg[0]:g}, home_elbow_deg = "
          f"{p.home_posture_deg[1]:g}")
    assert p.home_radius == p.target_radius
    lesson = preset("lesson")
    program, person = (lab_config(lesson, 10, person=who).time_limit for who in (False, True))
    _says(LAB, f"(`lesson`: {program:.0f} s and {person:.0f} s)")
    low, high = Viscous.parameters()[0][1:3]
    _says(LAB, f"each entry from {low:.0f} to {high:.0f}, and the matrix may feed the arm at most "
               f"{VISCOUS_MAX_FEEDING:g} N s/m",
          f"`channel_stiffness` (N/m, default {CHANNEL_STIFFNESS:.0f}, above 0 and at most "
          f"{MAX_CHANNEL_STIFFNESS:,.0f})",
          f"`channel_damping` (N s/m, default {CHANNEL_DAMPING:.0f}, 0 to {MAX_CHANNEL_DAMPING:.0f})",
          f"(at most {MAX_CLASS_FILES})", f"({min(REPLAY_SPEEDS):g}x to {max(REPLAY_SPEEDS):g}x",
          f"with {TUNING_CENTRES} Gaussian bases every {360 / TUNING_CENTRES:g} deg, normalised, of s.d. "
          f"{TUNING_WIDTH_DEG:g} deg (`--tuning-width DEG`, {NARROWEST:g} to {WIDEST:g})")
    local = DirectionalLearner(TwoRateLearner())
    _says(LAB, f"{local.generalization(45):.2f} at 45 deg, {local.generalization(90):.3f} at 90 deg, "
               f"{local.generalization(135):.3f} at 135 deg")
    from scipy.stats import chi2

    _says(LAB, f"each at most {fit.MAX_EVALUATIONS} evaluations",
          f"within {chi2.ppf(0.95, 1) / 2:.2f} (half of chi-squared's 95th percentile, 1 degree of freedom)")


def test_the_scenes_and_the_commands_numbers_in_physics():
    from armgame.cli import build_parser
    from armgame.commands.derive import MAX_STATES
    from armgame.scenes import get_scene

    pendulum, propeller, upright = (get_scene(n) for n in ("pendulum", "propeller", "upright"))
    (_, torques), (off, rest) = propeller.torque_segments
    _says(PHYSICS, f"the tutorial's one-joint arm from {math.degrees(pendulum.initial[0]) + 90:.0f} deg",
          f"the game arm spun up by constant torques for {off:g} s, then free for {propeller.duration - off:g} s",
          f"balanced straight up, {upright.initial[0] - math.pi / 2:.2f} rad off")
    assert any(torques) and not any(rest)
    simulate = build_parser().parse_args(["simulate", "--scene", "passive", "--out", "x.csv"])
    _says(PHYSICS, f"(`--states`, 1 to {MAX_STATES:,}; `--seed`, 0 to 2^63 - 1)",
          f"Rows come at `--sample-rate` ({simulate.sample_rate:.0f} Hz by default)")


def test_the_channel_step_limit_and_rk4s_stability():
    """The channel's |s| dt limit is the code's, and RK4's stability limits are where its amplification
    factor R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 reaches 1 along each ray (a root of |R| = 1, bracketed)."""
    from scipy.optimize import brentq

    from armgame.lab.protocol import MAX_CHANNEL_LAMBDA_DT

    def limit(angle: float) -> float:
        ray = np.exp(1j * angle)
        return brentq(lambda r: abs(np.polyval([1 / 24, 1 / 6, 1 / 2, 1, 1], r * ray)) - 1.0, 0.5, 3.5)

    protocol = preset("curl")
    session = LabSession(lab_config(protocol, 10), protocol)
    arm = session.model
    postures = [np.asarray(session.config.start_posture)]
    postures += [arm.inverse_kinematics(np.array(t)) for t in protocol.target_positions(session.home)]
    lightest = min(np.linalg.eigvalsh(np.linalg.inv(arm.jacobian(q) @ np.linalg.inv(arm.mass_matrix(q))
                                                    @ arm.jacobian(q).T))[0] for q in postures)
    mode = np.roots([lightest, CHANNEL_DAMPING, CHANNEL_STIFFNESS])[0]
    _says(LAB, f"the fastest mode must satisfy `|s| dt <= {MAX_CHANNEL_LAMBDA_DT:g}` (RK4 is stable to `|s| dt` of "
               f"{limit(np.angle(mode)):.2f} along the direction of these modes, {limit(math.pi):.2f} for a pure "
               f"decay and {limit(math.pi / 2):.2f} for a pure oscillation;")


def test_the_measures_definitions_are_the_codes_defaults():
    import inspect

    from armgame.lab import figures
    from armgame.lab.metrics import reach_metrics

    defaults = {k: p.default for k, p in inspect.signature(reach_metrics).parameters.items()}
    _says(LAB, f"rises through {100 * defaults['threshold']:g}% of that reach's peak speed",
          f"over the first {1000 * defaults['direction_delay']:g} ms after onset",
          f"the hand never reaches {defaults['min_peak_speed']:g} m/s",
          f"**Figures** ({figures.WIDTH * figures.DPI:.0f} x {figures.HEIGHT * figures.DPI:.0f}, for a projector)")


def test_the_window_times_worked_out_and_the_muscles():
    """A person's column of the window-time table is benchmarks/lab_slot.py's arithmetic on the protocol (the
    bot's columns are wall times, measured there and not checkable here)."""
    import importlib.util

    from armgame.game.muscles import ELBOW_MAX_TORQUE, SHOULDER_MAX_TORQUE
    from armgame.ui.lab_window import BOT_CARD_SECONDS, FEEDBACK_SECONDS

    spec = importlib.util.spec_from_file_location("lab_slot", DOCS.parent / "benchmarks" / "lab_slot.py")
    slot = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(slot)
    p = preset("lesson")
    _says(LAB, f"(per reach: {p.delay[0]:.1f} to {p.delay[1]:g} s at home, the reach, {p.hold_time:.1f} s on the "
               f"target, {FEEDBACK_SECONDS:.1f} s of its path; a person's reach taken as {slot.PERSON_REACH:g} s, the "
               f"cards read in {slot.PERSON_FIRST_CARD:g} s and {slot.PERSON_BLOCK_CARD:g} s;",
          f"the path and its cards of {BOT_CARD_SECONDS:g} s:",
          f"and {FEEDBACK_SECONDS:.1f} s of path a trial)")
    for name in ("lesson", "curl"):
        _says(LAB, f"| `{name}` | {preset(name).trials} |", f"| {slot.person_cell(preset(name))} |")
    _says(LAB, f"game's {SHOULDER_MAX_TORQUE:g} and {ELBOW_MAX_TORQUE:g} N m muscles")


def test_the_physics_docs_remaining_numbers():
    from armgame import simulation
    from armgame.scenes import get_scene

    q1, q2 = get_scene("passive").initial[:2]
    assert q1 == -math.pi / 2  # "upper arm hanging": straight down from the shoulder in our convention
    _says(PHYSICS, f"upper arm hanging and elbow at {math.degrees(q2):.0f} deg")
    # "memory stays a few thousand rows": the writer's chunk.
    assert 2000 <= simulation._CHUNK_ROWS < 10_000 and "memory stays a few thousand rows" in PHYSICS
    # derive's "`--seed`, 0 to 2^63 - 1" is held by tests/test_derive.py, where SymPy is imported anyway.


def test_issue_39s_corrected_numbers():
    """The numbers an independent re-analysis found wrong in the lab's docs (issue 39), as now stated: the
    person's clock on ``lesson`` (lab_config's docstring said 5 minutes), the worst window times with the mean
    and the longest wait at home, the generalization's width against its bases', and the citations."""
    import importlib.util

    from armgame.lab.learner import TUNING_WIDTH_DEG, DirectionalLearner

    lesson = preset("lesson")
    person, program = lab_config(lesson, 10, person=True).time_limit, lab_config(lesson, 10).time_limit
    assert f"``lesson``: {person:.0f} s, {person / 60:.1f} minutes, of reaching" in re.sub(r"\s+", " ",
                                                                                            lab_config.__doc__)
    assert f"a program {program:.0f} s" in re.sub(r"\s+", " ", lab_config.__doc__)
    _says(LAB, f"(`lesson`: {program:.0f} s and {person:.0f} s)")
    spec = importlib.util.spec_from_file_location("lab_slot", DOCS.parent / "benchmarks" / "lab_slot.py")
    slot = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(slot)
    _, worst, longest = slot.person_estimate(lesson)
    _says(_text("teaching.md"), f"at most {worst / 60:.1f} minutes even if every reach times out (with the mean wait "
                                f"at home; {longest / 60:.2f} with the longest)")
    local = DirectionalLearner(TwoRateLearner())
    widths = [d / math.sqrt(-2.0 * math.log(local.generalization(d))) for d in (22.5, 45.0, 67.5, 90.0)]
    assert max(widths) - min(widths) < 0.01  # the overlap of two tunings is a Gaussian: one s.d. at every angle
    assert widths[0] == pytest.approx(TUNING_WIDTH_DEG * math.sqrt(2.0), abs=0.01)
    _says(LAB, f"The {TUNING_WIDTH_DEG:g} deg is each basis function's width (s.d.); the generalization they make is "
               f"wider, a Gaussian of s.d. {widths[1]:.1f} deg")
    # Krakauer et al. (2000) is a visuomotor-rotation study: cited for rotation, never for a force field's design.
    _says(LAB, "Gandolfo, Mussa-Ivaldi & Bizzi (1996) trained a force field", "(Krakauer et al. 2000 asked the same of "
               "a visuomotor rotation)", "Generalization of a visuomotor rotation across directions.")
    from armgame.lab import presets

    assert "Krakauer" not in presets.generalization.__doc__
