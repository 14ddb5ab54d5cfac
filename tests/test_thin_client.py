"""The student's side of a class loads none of the server: ``play --join``, ``class submit``, ``class show``.

Each command runs for real in a fresh process against a class served here, and the armgame modules it loaded
are compared with the lists below. A module added to a student's path fails the test: if it belongs there (it
is light and the student needs it), add it to its list; if it is the server's (the clerk, the table's
writer, the batch replays), import what the student needs from a module both sides share
(``armgame.classroom.wire``, ``armgame.classroom.bounds``) instead.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from class_server import keyboard_game, running_class

#: Importing the client: what joining and handing in need, and nothing more (no numpy, no pygame).
CLIENT = {
    "armgame", "armgame.errors", "armgame.files", "armgame.limits", "armgame.valid",
    "armgame.records", "armgame.records.standings", "armgame.records.storage",
    "armgame.classroom", "armgame.classroom.bounds", "armgame.classroom.client", "armgame.classroom.memberships",
    "armgame.classroom.wire",
}
#: Parsing any command line: every command's ``register`` (``armgame --help`` loads these).
COMMAND_LINE = {
    "armgame", "armgame.cli", "armgame.commands", "armgame.commands.analyze", "armgame.commands.bench",
    "armgame.commands.classroom", "armgame.commands.demo", "armgame.commands.derive", "armgame.commands.lab",
    "armgame.commands.outputs", "armgame.commands.play", "armgame.commands.replay", "armgame.commands.scores",
    "armgame.commands.settings", "armgame.commands.simulate", "armgame.commands.verify", "armgame.demos",
    "armgame.errors", "armgame.files", "armgame.lab", "armgame.lab.perturbations", "armgame.lab.presets",
    "armgame.lab.protocol", "armgame.limits", "armgame.records", "armgame.records.storage", "armgame.ui",
    "armgame.ui.options", "armgame.ui.playback", "armgame.ui.settings", "armgame.valid", "armgame.words",
}
#: The game itself: its rules, its muscles and the arm (numpy's share of it is the game's own).
GAME = {
    "armgame._native", "armgame.game", "armgame.game._ckernel", "armgame.game.muscles", "armgame.game.rules",
    "armgame.game.session", "armgame.physics", "armgame.physics._ctrig", "armgame.physics.defaults",
    "armgame.physics.hand", "armgame.physics.integrators", "armgame.physics.onejoint", "armgame.physics.params",
    "armgame.physics.trig", "armgame.physics.twojoint",
}
#: Reading a replay file, a lab run's included (``commands.read_lab_replays``): ``class submit`` tells a lab
#: run from a game before it joins.
REPLAYS = {
    "armgame.records._ctimeline", "armgame.records.replay", "armgame.game._cbots", "armgame.game.bots",
    "armgame.lab.protocol_file", "armgame.lab.record", "armgame.lab.session", "armgame.physics.loads",
    "armgame.game.variant",  # the lab session's speed guard (``variant.guarded``), Reach's own
}
#: ``play``'s own, with or without a class: the local table it keeps the game in, a bot to play it.
PLAY = {
    "armgame.game.script", "armgame.records.cache", "armgame.records.checking", "armgame.records.entry",
    "armgame.records.identity", "armgame.records.journalmend", "armgame.records.locking",
    "armgame.records.rulesets", "armgame.records.scores", "armgame.records.standings",
    "armgame.records.tablefile", "armgame.records.tableformat", "armgame.records.teacher",
}
#: The projector's standings in a window (pygame).
WINDOW = {
    "armgame.ui.body", "armgame.ui.class_window", "armgame.ui.display", "armgame.ui.loop", "armgame.ui.names",
    "armgame.ui.palette", "armgame.ui.render", "armgame.ui.text",
}
#: The optional C builds (``armgame._native``): loaded where built, their Python twins' place elsewhere.
COMPILED = {"armgame.game._ckernel", "armgame.game._cbots", "armgame.physics._ctrig", "armgame.records._ctimeline"}
#: What only the server runs: none of it may reach a student's machine.
SERVER_PACKAGES = ("starlette", "uvicorn", "anyio", "h11")
SERVER_MODULES = {f"armgame.classroom.{name}" for name in (
    "app", "board", "errors", "experiment", "guard", "handins", "intake", "labruns", "middleware", "page", "roster",
    "rounds", "serve", "state", "views", "worker")}

#: Run in a fresh process: armgame's command line with sys.argv, the user's data folder in a temporary one (the
#: student's own path to it, as no $ARMGAME_CLASS_CLIENT is set), ``class show``'s window cut to a few frames; then
#: the modules loaded, as JSON.
RUN = """
import json, sys
import platformdirs
platformdirs.user_data_dir = lambda *a, **k: sys.argv[1]
if sys.argv[2:4] == ["class", "show"]:  # its window, a few frames long (the window loads the loop itself)
    import armgame.ui.loop as loop
    run_loop = loop.run_loop
    loop.run_loop = lambda *a, **k: run_loop(*a, **{**k, "max_frames": 3})
from armgame.cli import main
code = main(sys.argv[2:])
print(json.dumps({"code": code, "modules": sorted(sys.modules)}))
"""


def loaded(tmp_path: Path, *argv: str) -> tuple[int, set[str], set[str]]:
    """(exit code, armgame modules, other top-level packages) after ``armgame *argv`` in a fresh process."""
    env = {k: v for k, v in os.environ.items() if k != "ARMGAME_CLASS_CLIENT"}
    env |= {"ARMGAME_SCORES": str(tmp_path / "scores"), "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    done = subprocess.run([sys.executable, "-c", RUN, str(tmp_path / "data"), *argv], capture_output=True,
                          text=True, env=env, cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr
    answer = json.loads(done.stdout.splitlines()[-1])
    modules = set(answer["modules"])
    return (answer["code"], {m for m in modules if m.split(".")[0] == "armgame"},
            {m.split(".")[0] for m in modules})


def check(modules: set[str], packages: set[str], expected: set[str]) -> None:
    assert not modules & SERVER_MODULES, f"the server's modules on a student's machine: {modules & SERVER_MODULES}"
    assert not packages & set(SERVER_PACKAGES), f"the server's packages loaded: {packages & set(SERVER_PACKAGES)}"
    modules, expected = modules - COMPILED, expected - COMPILED
    assert modules == expected, (f"loaded and not listed: {sorted(modules - expected)}; "
                                 f"listed and not loaded: {sorted(expected - modules)}")


def test_importing_the_client_loads_none_of_the_server_nor_numpy():
    code = "import json, sys\nimport armgame.classroom.client\nprint(json.dumps(sorted(sys.modules)))\n"
    modules = set(json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                            check=True).stdout))
    check({m for m in modules if m.split(".")[0] == "armgame"}, {m.split(".")[0] for m in modules}, CLIENT)
    assert not {"numpy", "pygame"} & modules
    development = " ".join((Path(__file__).parents[1] / "docs" / "development.md").read_text("utf-8").split())
    assert f"importing the client loads {len(CLIENT)}, and no numpy" in development


@pytest.fixture(scope="module")
def rehearsal():
    """A rehearsal class (15 s games: a bot's game is played quickly), served by this process."""
    with running_class(None, rehearse=True) as opened:
        yield f"127.0.0.1:{opened.port}", opened.clerk.roster.code


def test_class_submit_loads_the_client_and_the_replay_reader_only(tmp_path, rehearsal):
    where, code = rehearsal
    game = tmp_path / "game.json"
    game.write_bytes(keyboard_game(5, player="Ann", duration=15.0).to_bytes())
    exit_code, modules, packages = loaded(tmp_path, "class", "submit", where, "--code", code, "--name", "Ann",
                                          str(game))
    assert exit_code == 0 and "pygame" not in packages
    check(modules, packages, COMMAND_LINE | CLIENT | GAME | REPLAYS)


@pytest.mark.slow  # a whole headless game against a class: about 1 s
def test_play_join_loads_what_play_does_and_the_client(tmp_path, rehearsal):
    where, code = rehearsal
    exit_code, modules, packages = loaded(tmp_path, "play", "--headless", "--bot", "model", "--join", where,
                                          "--code", code, "--name", "Bo")
    assert exit_code == 0 and "pygame" not in packages
    check(modules, packages, COMMAND_LINE | CLIENT | GAME | REPLAYS | PLAY)


@pytest.mark.slow  # the window opened against a class
def test_class_show_loads_the_client_and_the_window_only(tmp_path, rehearsal):
    where, _ = rehearsal
    exit_code, modules, packages = loaded(tmp_path, "class", "show", where)
    assert exit_code == 0
    check(modules, packages, COMMAND_LINE | CLIENT | GAME | WINDOW)
