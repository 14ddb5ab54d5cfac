"""The browser's engine carries what the class's game needs and no more.

``static/constants.js`` is generated from armgame's own definitions (``armgame.classroom.jsconstants``): the committed
file must be what the generator writes now (a changed arm, muscle, limit or version fails here until it is written
again), and its doubles must reach JavaScript with their bits. engine.js keeps no name nothing reads.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from node import bits, node, skip_without_node

import armgame
from armgame.classroom import jsconstants
from armgame.game.muscles import MuscleSet
from armgame.game.rules import GameConfig
from armgame.physics.twojoint import TwoJointArm

ROOT = Path(__file__).resolve().parent.parent
STATIC = ROOT / "armgame" / "classroom" / "static"


def test_the_committed_constants_are_not_stale():
    assert jsconstants.PATH == STATIC / "constants.js"
    assert jsconstants.PATH.read_text(encoding="utf-8") == jsconstants.source(), (
        "armgame/classroom/static/constants.js is stale: run python -m armgame.classroom.jsconstants")


def test_the_generator_writes_and_checks(tmp_path, monkeypatch, capsys):
    target = tmp_path / "constants.js"
    target.write_text(jsconstants.source().replace(armgame.__version__, "0.0.1"), encoding="utf-8")
    monkeypatch.setattr(jsconstants, "PATH", target)
    assert jsconstants.main(["--check"]) == 1
    assert "stale" in capsys.readouterr().err
    assert jsconstants.main([]) == 0
    assert jsconstants.main(["--check"]) == 0 and target.read_text(encoding="utf-8") == jsconstants.source()
    assert jsconstants.main(["--wrong"]) == 2


def test_the_constants_reach_javascript_bit_for_bit():
    """Each double of constants.js, read by JavaScript, has the bits Python computed (repr is exact both ways)."""
    skip_without_node("constants.js's doubles in JavaScript are not checked here")
    script = ("import * as c from './constants.js';"
              "const v = new DataView(new ArrayBuffer(8));"
              "const bits = (x) => { v.setFloat64(0, x); return v.getBigUint64(0).toString(16).padStart(16, '0'); };"
              "process.stdout.write(JSON.stringify({arm: Object.fromEntries(Object.entries(c.ARM).map(([k, x]) =>"
              " [k, bits(x)])), rise: c.RISE.map(bits), decay: c.DECAY.map(bits), version: c.ARMGAME_VERSION}));")
    done = node("--input-type=module", "-e", script, cwd=STATIC)
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)

    config = GameConfig()
    model, muscles = TwoJointArm(config.arm), MuscleSet(config.muscles, config.dt)
    assert got["arm"] == {"l1": bits(config.arm.l1), "l2": bits(config.arm.l2), "b": bits(model.b),
                          "d": bits(model.d), "det0": bits(model.a * model.d - model.d * model.d),
                          "aMinusD": bits(model.a - model.d), "k1": bits(config.arm.damping1),
                          "k2": bits(config.arm.damping2)}
    assert got["rise"] == [bits(r) for r in muscles._rise] and got["decay"] == [bits(r) for r in muscles._decay]
    assert got["version"] == armgame.__version__


def test_the_engine_has_no_dead_names():
    """Every top-level name engine.js declares is read in it or imported by a page or the tests' runner."""
    source = (STATIC / "engine.js").read_text(encoding="utf-8")
    code = "\n".join(line.split("//")[0] for line in source.splitlines())
    declared = re.findall(r"^(?:export )?(?:const|let|function|class) (\w+)", code, re.M)
    declared += [n for group in re.findall(r"^(?:export )?const ((?:\w+ = [^,;]+, )+\w+) =", code, re.M)
                 for n in re.findall(r"(\w+) =", group + " =")]
    users = [p.read_text(encoding="utf-8") for p in STATIC.glob("*.js") if p.name != "engine.js"]
    users.append((ROOT / "tests" / "engine_runner.mjs").read_text(encoding="utf-8"))
    imported = {name for text in users for names in re.findall(r"import \{([^}]*)\}\s*from \"[./]*[^\"]*engine\.js\"",
                                                                text) for name in re.findall(r"\w+", names)}
    assert len(declared) >= 20
    for name in declared:
        used = len(re.findall(rf"\b{name}\b", code)) > 1
        assert used or name in imported, f"engine.js declares {name} and nothing reads it"
    for dead in ("ENGINE_VERSION", "MASK64", "expm1", "square"):
        assert not re.search(rf"\b{dead}\b", code), dead


def test_a_browser_game_is_a_persons_game_in_the_code_and_the_docs():
    """The engine's replay names its driver, the browser (the device a person played on), which the scores count
    as a person's game, not a program's; the two docs that define a program say the same."""
    from armgame.records.entry import ScoreEntry
    from armgame.records.replay import KEYBOARD_DEVICES

    engine = (STATIC / "engine.js").read_text(encoding="utf-8")
    assert re.findall(r'\bdriven: "(\w+)",\s*driver: "(\w+)"', engine) == [("keyboard", "browser")]
    assert "browser" in KEYBOARD_DEVICES

    def entry(driven: str, driver: str | None) -> ScoreEntry:
        return ScoreEntry(id="x", name="Ann", driven=driven, driver=driver, score=1, hits=1, resets=0, seed=0,
                          scene="game", duration=60.0, date="2026-01-01T00:00:00+00:00", version="0.5.0",
                          replay="x.json", replay_sha256="0" * 64)

    assert not entry("keyboard", "browser").program and not entry("keyboard", None).program
    assert entry("keyboard", "autoclicker").program and entry("bot", "model").program
    development = (ROOT / "docs" / "development.md").read_text(encoding="utf-8")
    browser = development.split("## The game in the browser", 1)[1].split("\n## ", 1)[0]
    assert '`"driver": "browser"`' in browser and "no driver" not in browser
    scores = (ROOT / "docs" / "scores.md").read_text(encoding="utf-8")
    programs = next(line for line in scores.splitlines() if line.startswith("| programs |"))
    assert "`browser`" in programs and "a person's" in programs
