"""The golden game: one standard game's final state hashed and committed, through every copy of the arm's step.

Every other test of the physics is differential: a copy against the Python, on one machine, at one commit. A change
that moves every copy together passes them all, and old replays would then stop verifying. This one pins the bits
themselves (as Box2D's ``test/test_determinism.c`` pins its ``EXPECTED_HASH``): the standard game of seed
``GOLDEN_SEED`` on a fixed key timeline, played by the Python loop, the compiled single game (``_cstep.h``'s
``game_loop``), the batch in numpy and in C (its lanes and its one-game-at-a-time loop) and the browser's engine in
Node, must each give ``GOLDEN``: the SHA-256 of its final state, activations, target, hit times and result.

``GOLDEN`` changes only with a version bump, named in the CHANGELOG (which quotes it): a new value means every replay
of the old physics stops verifying. docs/development.md's table "The physics' copies" lists each copy and its test.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from node import run_node, skip_without_node

from armgame.game.batch import BatchGameSession, compiled
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, InputEvent
from armgame.records.replay import Replay, config_to_dict

ROOT = Path(__file__).resolve().parent.parent

#: The committed hash of the golden game. Changed only with a version bump and a CHANGELOG entry that quotes it.
GOLDEN = "e9ed40b01b8c6ee4552a347d770418571576c063ad43bf8fd521e3df01a8b54e"
GOLDEN_SEED = 20260531


def golden_timeline() -> list[InputEvent]:
    """A student's 60 s of keys, written out by integer arithmetic (no random module, whose draws may change):
    presses and releases of the four muscles, chords, a few resets and tabs, and a key after the clock's end."""
    events = []
    step = 0
    for i in range(400):
        step += 15 + (i * 53) % 50
        key = "dfjk"[(i * 7 + i // 5) % 4]
        events.append(InputEvent(step, key, "down"))
        events.append(InputEvent(step + 15 + (i * 29) % 90, key, "up"))
        if i % 41 == 17:
            events.append(InputEvent(step + 1, "space", "down"))
        if i % 53 == 8:
            events.append(InputEvent(step + 2, "tab", "down"))
    return sorted(events, key=lambda e: e.step)


def digest(state, activation, target, hit_times, score: int, hits: int, resets: int, steps: int) -> str:
    """SHA-256 of a game's end: the doubles' 64 bits (big-endian) and the counts as decimal text."""
    data = struct.pack(">4d4d2d", *state, *activation, *target)
    data += struct.pack(f">{len(hit_times)}d", *hit_times)
    data += f"score {score} hits {hits} resets {resets} steps {steps}".encode("ascii")
    return hashlib.sha256(data).hexdigest()


def session_digest(session: GameSession) -> str:
    board, target = session.rules.board, session.rules.target
    return digest(session.state, session.muscles.activation, (target.x, target.y), board.hit_times, board.score,
                  board.hits, board.resets, session.steps)


CONFIG = GameConfig(seed=GOLDEN_SEED)
EVENTS = golden_timeline()


def test_the_golden_game_is_a_game():
    """It does what it is for: hits (so the target draws are in the hash), resets, the whole clock."""
    session = GameSession(CONFIG, compiled=False)
    result = session.play(EVENTS)
    assert result.steps == 15000 and result.hits >= 5 and result.resets >= 3, result


@pytest.mark.parametrize("compiled_loop", [False, True], ids=["python", "compiled"])
def test_the_single_session(compiled_loop):
    if compiled_loop and not compiled.AVAILABLE and not os.environ.get("ARMGAME_REQUIRE_COMPILED"):
        pytest.skip("the compiled loops are not built here")
    session = GameSession(CONFIG, compiled=compiled_loop)
    assert (session._compiled is not None) == compiled_loop
    session.play(EVENTS)
    assert session_digest(session) == GOLDEN
    # The replay of it verifies, and its outcome is the game's.
    replay = Replay.from_session(session, "keyboard", None, "golden")
    ok, result = Replay.from_bytes(replay.to_bytes(), "the golden replay").verify()
    assert ok and result == session.result()


# numpy's batch pays its call overhead on every step of one game (3 s): the slow tier, which CI runs.
@pytest.mark.parametrize("kernel, lanes", [pytest.param("numpy", None, marks=pytest.mark.slow), ("compiled", True),
                                           ("compiled", False)], ids=["numpy", "c-lanes", "c-one-at-a-time"])
def test_the_batch(kernel, lanes, monkeypatch):
    if kernel == "compiled" and not compiled.AVAILABLE and not os.environ.get("ARMGAME_REQUIRE_COMPILED"):
        pytest.skip("the compiled loops are not built here")
    if lanes is not None:
        monkeypatch.setattr(compiled, "LANES", lanes)
    batch = BatchGameSession([CONFIG], kernel=kernel)
    batch.play([EVENTS])
    board = batch.rules[0].board
    got = digest(batch.state(0), batch.activation[0].tolist(), (float(batch.target_x[0]), float(batch.target_y[0])),
                 board.hit_times, int(batch.score[0]), int(batch.hits[0]), int(batch.resets[0]), int(batch.steps[0]))
    assert got == GOLDEN


def test_the_browser_engine():
    skip_without_node("the browser's engine is not checked here")
    request = {"games": [{"config": config_to_dict(CONFIG), "events": [[e.step, e.key, e.action] for e in EVENTS]}]}
    game = run_node(ROOT / "tests" / "engine_runner.mjs", request, timeout=60)["games"][0]

    def floats(hexes: list[str]) -> list[float]:
        return [struct.unpack(">d", bytes.fromhex(h))[0] for h in hexes]

    got = digest(floats(game["state"]), floats(game["activation"]), floats(game["target"])[:2],
                 floats(game["hit_times"]), game["score"], game["hits"], game["resets"], game["steps"])
    assert got == GOLDEN


def test_one_changed_bit_changes_the_hash():
    """The negative control: the last bit of one velocity, or one hit less, is another hash."""
    session = GameSession(CONFIG, compiled=False)
    session.play(EVENTS)
    board, target = session.rules.board, session.rules.target
    q1, q2, w1, w2 = session.state
    args = [session.muscles.activation, (target.x, target.y), board.hit_times, board.score, board.hits,
            board.resets, session.steps]
    assert digest((q1, q2, w1, w2), *args) == GOLDEN
    assert digest((q1, q2, w1, float(np.nextafter(w2, np.inf))), *args) != GOLDEN
    assert digest((q1, q2, w1, w2), *args[:2], board.hit_times[:-1], *args[3:]) != GOLDEN


def test_the_changelog_quotes_the_golden_hash():
    """A new hash is a CHANGELOG entry (with its version bump): the file names the one committed here."""
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert re.search(rf"\b{GOLDEN[:16]}", changelog), "CHANGELOG.md does not quote tests/test_golden.py's GOLDEN"


def test_the_step_header_has_no_python_in_it(tmp_path):
    """``_cstep.h`` (the arm's step and the single game's loop) compiles with no Python headers: the source any
    build of the game, a browser's wasm too, shares with the extension modules."""
    source = (ROOT / "armgame" / "game" / "_cstep.h").read_text(encoding="utf-8")
    assert "Python.h" not in source and "Py_" not in source and "PyObject" not in source
    cc = shutil.which("cc") or shutil.which("clang") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler here")
    main = tmp_path / "golden.c"
    main.write_text('#include "_cstep.h"\nint armgame_use_sincos = 0;\nint main(void) { return 0; }\n')
    done = subprocess.run([cc, "-fsyntax-only", "-Wall", "-Werror", "-I", str(ROOT / "armgame" / "game"), str(main)],
                          capture_output=True, text=True, timeout=60, check=False, env={"PATH": os.environ["PATH"]})
    assert done.returncode == 0, done.stderr
