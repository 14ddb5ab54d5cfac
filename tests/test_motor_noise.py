"""A bot's motor noise (armgame/game/bots.py MotorNoise, armgame lab --motor-noise): seeded, carried by the keys
the bot presses so its replay verifies with nothing re-drawn, off for the game's bots, and refused in one line
when out of range."""

from pathlib import Path

import numpy as np
import pytest

from armgame.errors import UserError
from armgame.game.bots import Autopilot, MotorNoise, make_bot
from armgame.lab.bots import make_lab_bot
from armgame.lab.protocol import Block, Protocol
from armgame.lab.record import LabTask
from armgame.lab.session import LabSession, lab_config

SHORT = Protocol("noise", (Block("baseline", 8),), targets=2)


def _run(noise: MotorNoise | None) -> LabSession:
    session = LabSession(lab_config(SHORT, 10), SHORT)
    Autopilot(session, make_lab_bot("model", noise=noise)).play()
    return session


def test_noise_is_seeded_carried_by_the_keys_and_verified_from_the_timeline():
    quiet, noisy, again, other = (_run(None), _run(MotorNoise(0.3, 1)), _run(MotorNoise(0.3, 1)),
                                  _run(MotorNoise(0.3, 2)))
    assert noisy.timeline == again.timeline and noisy.timeline != other.timeline != quiet.timeline
    # The replay keeps what the noise was; verifying replays the keys, drawing nothing, bit for bit.
    task = LabTask.of(noisy, MotorNoise(0.3, 1))
    data = task.as_dict()
    assert data["motor_noise"] == {"level": 0.3, "correlation_time_s": 0.05, "seed": 1}
    read = LabTask.from_dict(data, noisy.config, noisy.steps)
    assert read == task
    ok, _, replayed = read.verify(noisy.config, noisy.timeline, noisy.result())
    assert ok and [o.xs for o in replayed.outcomes] == [o.xs for o in noisy.outcomes]
    # Without noise the bot's reaches to one target repeat exactly; with it they vary (the point of it).
    def spread(session: LabSession) -> float:
        ends = {}
        for o in session.outcomes:
            ends.setdefault(o.plan.target, []).append(np.hypot(np.diff(o.xs), np.diff(o.ys)).sum())
        return max(float(np.std(v)) for v in ends.values())
    assert spread(quiet) < 1e-12 < 1e-4 < spread(noisy)


def test_the_games_bots_have_no_noise_and_bad_levels_are_one_line_errors():
    assert make_bot("model").noise is None and make_lab_bot("adaptive").noise is None
    for level, time in ((1.5, 0.05), (float("nan"), 0.05), (-0.1, 0.05), (0.2, 0.0)):
        with pytest.raises(UserError, match="motor noise") as caught:
            MotorNoise(level, 1, time)
        assert "\n" not in str(caught.value)
    with pytest.raises(ValueError, match=r"task\.motor_noise"):
        LabTask.from_dict({**LabTask.of(_run(None)).as_dict(), "motor_noise": {"level": 3, "seed": 1,
                                                                              "correlation_time_s": 0.05}},
                          lab_config(SHORT, 10), 10 ** 6)


@pytest.mark.parametrize("argv, level", [
    (["curl", "--bot", "adaptive"], 0.3),  # an experiment a lab report runs: a person's noise, unless...
    (["curl", "--bot", "adaptive", "--motor-noise", "0"], 0.0),  # ...turned off
    (["lesson", "--bot", "adaptive"], 0.0),  # the class's demo: reproducible to the digit
    (["lesson", "--bot", "model", "--motor-noise", "human"], 0.3),
    (["short.toml", "--bot", "adaptive"], 0.0),  # a protocol file: none unless asked
    (["spontaneous"], 0.0),  # a person at the keys brings their own
])
def test_each_preset_brings_its_bot_a_motor_noise_that_the_option_overrides(argv, level):
    from armgame.cli import build_parser
    from armgame.commands.lab import _motor_noise, _noise_line, _resolve_motor_noise
    from armgame.lab.presets import HUMAN_NOISE, PRESET_MOTOR_NOISE, PRESETS

    assert HUMAN_NOISE == 0.3 and {p for p in PRESETS if PRESET_MOTOR_NOISE[p]} == set(PRESETS) - {"lesson"}
    args = build_parser().parse_args(["lab", *argv, "--seed", "10"])
    _resolve_motor_noise(args)
    assert args.motor_noise == level
    assert _motor_noise(args) == (MotorNoise(level, 10) if level else None)
    if argv[0] in ("curl", "lesson") and len(argv) == 3:  # the two lines docs/lab.md quotes, as printed
        line = _noise_line(args)
        assert f"  {line}\n" in (Path(__file__).parent.parent / "docs" / "lab.md").read_text(encoding="utf-8")


def test_a_replay_without_its_noise_recorded_still_verifies():
    """The noise is in the keys: a replay whose task section names none (as every one before it did) re-simulates
    to the same trials, bit for bit."""
    noisy = _run(MotorNoise(0.3, 1))
    data = LabTask.of(noisy, MotorNoise(0.3, 1)).as_dict()
    del data["motor_noise"]
    read = LabTask.from_dict(data, noisy.config, noisy.steps)
    assert read.motor_noise is None and read.verify(noisy.config, noisy.timeline, noisy.result())[0]
