"""The bound on hits (benchmarks/hit_bound.py) and protocol 3's reference (references.py's REFERENCES_V3)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium")

from armgame.env.references import CEILINGS, REFERENCE_HITS, REFERENCES_V3, TIER_HITS

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"


def _module(name: str):
    spec = importlib.util.spec_from_file_location(f"bench_{name}", ROOT / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_bounds_hand_acceleration_is_the_arms():
    """The bound's hand acceleration equals the arm's own dynamics (TwoJointArm) at random states and torques."""
    from armgame.game.rules import GAME_PLAY_ARM
    from armgame.physics.twojoint import TwoJointArm

    bound = _module("hit_bound")
    arm = TwoJointArm(GAME_PLAY_ARM)
    rng = np.random.default_rng(1)
    for _ in range(20):
        q2, w, tau = rng.uniform(-3, 3), rng.uniform(-5, 5, 2), rng.uniform(-2, 2, 2)
        qdd = arm.forward_dynamics([0.0, q2], w, tau)
        eps = 1e-6
        mine = bound.hand_acceleration(GAME_PLAY_ARM, np.array(q2), w, tau, 0.0)
        # The hand's acceleration from the joints': J qdd + Jdot w, Jdot w by a finite difference of J along w.
        j = bound.jacobian(GAME_PLAY_ARM, np.array(q2))
        jdot = (bound.jacobian(GAME_PLAY_ARM, np.array(q2 + eps * w[1])) - j) / eps
        # Shoulder rotation by w1 rotates J: d/dt (R(q1) J) at q1 = 0 adds w1 [[0, -1], [1, 0]] J.
        spin = w[0] * np.array([[0.0, -1.0], [1.0, 0.0]]) @ j
        expected = j @ np.asarray(qdd) + (jdot + spin) @ w
        np.testing.assert_allclose(mine, expected, rtol=1e-4, atol=1e-5)


def _committed_scores() -> dict[str, list[float]]:
    """Every committed mean score of every Reach id: PPO's runs, the controller's and the bots'."""
    scores: dict[str, list[float]] = {}
    for path in RESULTS.glob("ppo*/**/result.json"):
        result = json.loads(path.read_text(encoding="utf-8"))
        scores.setdefault(result["env_id"], []).append(float(result["mean_hits"]))
    ceiling = _module("ceiling")
    for folder in ("ceiling", "reference"):
        for path in (RESULTS / folder).glob("*.json"):
            data = ceiling.read_result(path)
            if data["hits"]:
                for env_id in (data["env_id"], *[k for k, v in ceiling.STANDS_FOR.items() if v == data["env_id"]]):
                    scores.setdefault(env_id, []).append(float(np.mean(data["hits"])))
    for env_id, row in REFERENCE_HITS.items():
        scores.setdefault(env_id, []).extend(row[p] for p in ("random", "naive", "model", "ppo"))
    for env_id, row in CEILINGS.items():
        scores.setdefault(env_id, []).append(row["hits"])
    for env_id, row in TIER_HITS.items():  # the separating tier's bots
        scores.setdefault(env_id, []).extend(row[p] for p in ("random", "naive", "model"))
    return {env_id: v for env_id, v in scores.items() if "CenterOut" not in env_id}


def test_the_bound_is_above_every_committed_score_and_the_docs_figures_are_the_committed_result():
    ceiling = _module("ceiling")
    rows = {row["env_id"]: row for row in json.loads((RESULTS / "hit_bound.json").read_text(encoding="utf-8"))}
    assert set(rows) == set(ceiling.DISTINCT)
    scores = _committed_scores()
    assert len(scores) == 15  # the 12 Reach ids and the separating tier's 3
    guide = " ".join((ROOT / "docs" / "programs.md").read_text(encoding="utf-8").split())
    for env_id, values in scores.items():
        row = rows[ceiling.STANDS_FOR.get(env_id, env_id)]
        # A bound below a measured score is a bug.
        assert row["bound_hits"] > max(values), env_id
        assert row["oracle_hits"] >= row["bound_hits"] * 0.999, env_id
    ratios = [row["bound_hits"] / max(max(v) for k, v in scores.items() if ceiling.STANDS_FOR.get(k, k) == env_id)
              for env_id, row in rows.items()]
    assert f"The bound is loose: {min(ratios):.0f} to {max(ratios):.0f} times the best score measured." in guide
    bound = _module("hit_bound")
    assert bound.committed_scores() == {env_id: max(values) for env_id, values in scores.items()}
    assert bound.table(list(rows.values())) in (ROOT / "docs" / "programs.md").read_text(encoding="utf-8")
    with pytest.raises(SystemExit, match="not a result of hit_bound"):
        bound.main(["--table", str(ROOT / "pyproject.toml")])


def test_protocol_3_divides_by_the_reference_and_a_run_above_it_scores_above_1():
    from armgame.env.evaluation import normalised_score

    scores = _module("reference_scores")
    assert scores.references_v3() == REFERENCES_V3
    guide = (ROOT / "docs" / "programs.md").read_text(encoding="utf-8")
    assert scores.references_v3_table() in guide
    for env_id, row in REFERENCES_V3.items():
        if row["unit"] == "hits a game":  # a Reach id: the controller's hits, random play's from the bots' table
            assert row["random"] == {**REFERENCE_HITS, **TIER_HITS}[env_id]["random"]
            assert row["code"].startswith("armgame.env.ceiling.ShootingController(")

            def score(x, env_id=env_id):
                return normalised_score(env_id, x, protocol=3)
        else:  # a CenterOut id: the model bot's hits a minute, whatever its count of hits
            assert row["unit"] == "hits a minute" and "CenterOut" in env_id
            assert row["code"] in scores.CENTER_OUT_REFERENCES.values()

            def score(x, env_id=env_id):
                return normalised_score(env_id, 8.0, protocol=3, hits_per_minute=x)
        assert score(row["hits"]) == pytest.approx(1.0) and score(row["hits"] + 1.0) > 1.0
        assert score(row["random"]) == pytest.approx(0.0) and row["cpu_per_decision"] > 0
    assert {env_id for env_id, row in REFERENCES_V3.items() if row["unit"] == "hits a minute"} == {
        env_id for env_id in scores.IDS if "CenterOut" in env_id}
    # Protocol 2's figures are untouched.
    assert normalised_score("armgame/Reach-v1", CEILINGS["armgame/Reach-v1"]["hits"], protocol=2) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="protocol must be one of 2, 3"):
        normalised_score("armgame/Reach-v1", 50.0, protocol=4)


def test_the_reference_run_records_its_settings_decisions_and_processor(tmp_path):
    """``ceiling.py run --reference`` plays the id's REFERENCE settings and keeps what the CPU a decision needs."""
    bench = _module("ceiling")
    bench.main(["run", "--reference", "--ids", "armgame/ReachHard-v1", "--games", "1", "--seconds", "1",
                "--out", str(tmp_path)])
    result = json.loads((tmp_path / "ReachHard-v1.json").read_text(encoding="utf-8"))
    assert result["settings"] == bench.REFERENCE["armgame/ReachHard-v1"] != bench.SETTINGS["armgame/ReachHard-v1"]
    assert result["decisions"] == 50 and result["processor"] and result["cpu_seconds"] > 0


def test_a_played_games_hand_stays_within_the_bounds_speed_and_acceleration():
    """Random keys and a pump (each joint's muscle pushing the way it turns) on the noisy game, whose bound is the
    widest: the hand's speed stays below ``V`` and its mean acceleration over each decision below ``A``."""
    import gymnasium as gym

    bound = _module("hit_bound")
    row = {r["env_id"]: r for r in json.loads((RESULTS / "hit_bound.json").read_text(encoding="utf-8"))}
    seen = {}
    for env_id in ("armgame/Reach-v1", "armgame/ReachNoisy-v1"):
        limit = row[env_id]
        env = gym.make(env_id, time_limit=8.0)
        p = env.unwrapped.settings.config.arm
        rng = np.random.default_rng(0)
        for pump in (False, True):
            env.reset(seed=5)
            before, fastest, hardest, done = None, 0.0, 0.0, False
            while not done:
                q1, q2, w1, w2 = env.unwrapped.session.state
                j = bound.jacobian(p, np.array(q2))
                c, s = np.cos(q1), np.sin(q1)
                v = np.array([[c, -s], [s, c]]) @ j @ np.array([w1, w2])
                fastest = max(fastest, float(np.linalg.norm(v)))
                if before is not None:
                    hardest = max(hardest, float(np.linalg.norm(v - before)) / 0.02)
                before = v
                keys = (np.array([w1 >= 0, w1 < 0, w2 >= 0, w2 < 0]) if pump else rng.integers(0, 2, 4)).astype(np.int8)
                _, _, terminated, truncated, _ = env.step(keys)
                done = terminated or truncated
            assert fastest < limit["speed"] and hardest < limit["accel"], (env_id, pump, fastest, hardest)
            seen[env_id, pump] = (fastest, hardest)
        env.close()
    # The docs' reading of how far the bound's V and A are from what the pump reaches.
    guide = " ".join((ROOT / "docs" / "programs.md").read_text(encoding="utf-8").split())
    fastest, hardest = seen["armgame/Reach-v1", True]
    limit = row["armgame/Reach-v1"]
    assert (f"reaches {fastest:.1f} m/s and {hardest:.0f} m/s^2 in an 8 s game of Reach-v1, against `V` "
            f"{limit['speed']:.1f} and `A` {limit['accel']:.0f}") in guide


def test_a_complete_reference_is_no_weaker_than_the_controllers_earlier_settings():
    """docs/programs.md: an id whose reference replays at new settings keeps them only if its 100 games beat the 100
    of the settings before (``benchmarks/results/ceiling``); until then the table says "incomplete"."""
    from armgame.env.references import REFERENCES_V3

    earlier = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "ceiling"
    for env_id, ref in REFERENCES_V3.items():
        if ref["games_of"] != env_id or ref["games"] < 100 or ref["unit"] != "hits a game":  # CenterOut: the bot's
            continue
        before = json.loads((earlier / f"{env_id.split('/')[1]}.json").read_text(encoding="utf-8"))
        hits = before["hits"]
        mean = sum(hits) / len(hits)
        assert ref["hits"] >= round(mean, 2) - 1e-9, f"{env_id}: the reference {ref['hits']} is below {mean:.2f}"
