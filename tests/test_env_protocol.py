"""Issue 40: the suite's protocol (seeds, fresh policies, IQM and stratified bootstrap), every Reach game
verifiable, fields that stay physical, and the small items (evaluate exported, the batched reward's round-off)."""

from __future__ import annotations

import doctest
import itertools
import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import armgame.env
import armgame.env.statistics
from armgame.cli import main
from armgame.env import evaluation, suite
from armgame.env.errors import EnvArgumentError
from armgame.env.policies import BotPolicy, bot_policy
from armgame.env.record import replay_of
from armgame.env.statistics import iqm, mean_of_tasks, median_of_tasks, stratified_bootstrap_ci
from armgame.env.variants import MAX_FIELD_STRENGTH, MAX_VISCOUS_STRENGTH, ReachVariant
from armgame.env.vector import REWARD_TOLERANCE
from armgame.records.replay import Replay


# ------------------------------------------------------------------ item 6: evaluate exported
def test_evaluate_is_exported_where_the_docs_name_it():
    assert armgame.env.evaluate is evaluation.evaluate
    assert armgame.env.aggregate_runs is evaluation.aggregate_runs


# ------------------------------------------------------------------ item 2: the protocol
def test_the_three_seed_ranges_are_disjoint():
    training = range(0, suite.TRAINING_SEED_LIMIT)
    ranges = (training, suite.VALIDATION_SEEDS, suite.EVALUATION_SEEDS)
    for a, b in itertools.combinations(ranges, 2):
        assert a.stop <= b.start or b.stop <= a.start, (a, b)
    assert len(suite.VALIDATION_SEEDS) == len(suite.EVALUATION_SEEDS) == 10**6


@pytest.mark.slow  # a seed's games evaluated twice: about 3 s
def test_a_seed_scores_the_same_alone_and_after_another_game():
    # The case: the naive bot hit once on this seed alone and never after another game, because one
    # bot's clock ran on between games. evaluate gives every game a fresh bot.
    result = armgame.env.evaluate("naive", "armgame/CenterOutHold-v1", seeds=[7_000_001, 7_000_002])
    assert result.hits[1] == 1


class Counting:
    """A policy with state: the number of steps it has seen, reset by ``reset``."""

    def __init__(self) -> None:
        self.resets = 0
        self.steps = 0

    def reset(self) -> None:
        self.resets += 1
        self.steps = 0

    def __call__(self, observation):
        self.steps += 1
        assert self.steps <= 10  # a game of 0.2 s is 10 decisions: more means the last game leaked in
        return np.zeros(4, dtype=np.int8)


def test_evaluate_resets_a_policy_with_state_before_every_game_or_makes_one_a_game():
    policy = Counting()
    armgame.env.evaluate(policy, "armgame/Reach-v1", games=3, time_limit=0.2)
    assert policy.resets == 3
    made = []

    def factory(env):
        made.append(BotPolicy("naive", env))
        return made[-1]

    result = armgame.env.evaluate("naive", "armgame/Reach-v1", games=3, time_limit=0.5, policy_factory=factory)
    assert len(made) == 3 and len({id(p) for p in made}) == 3
    assert result.hits == armgame.env.evaluate("naive", "armgame/Reach-v1", games=3, time_limit=0.5).hits
    with pytest.raises(EnvArgumentError, match="policy_factory"):
        armgame.env.evaluate("naive", "armgame/Reach-v1", games=1, policy_factory=3)


class RestAndPush:
    """A model (``predict``, so ``evaluate`` plays its games batched) whose even rows rest at home, so their trials
    time out and their episodes end in bounded time, and whose odd rows hold a key, so the hold's go cue never comes
    and their run's clock runs out: a finished row's replacement game ends again while the odd rows play on."""

    def predict(self, observation, deterministic=True):
        action = np.zeros((len(observation), 4), dtype=np.int64)
        action[1::2, 0] = 1
        return action, None


@pytest.mark.slow  # a second: the README's command is at its minute
def test_a_model_s_games_of_unequal_length_all_end_and_count_once():
    """A CenterOut episode is as long as its trials take: a finished game's place plays on, uncounted, and may end
    again before the others; ``evaluate`` starts it again each time (a PPO run's test games once stopped on an
    ``AssertionError`` there) and counts every game once, as the same games one at a time do."""
    kwargs = {"episode_trials": 1, "decision_steps": 25}
    batched = armgame.env.evaluate(RestAndPush(), "armgame/CenterOutHold-v1", games=2, **kwargs)
    rest = armgame.env.evaluate(lambda _obs: np.zeros(4, dtype=np.int64), "armgame/CenterOutHold-v1", games=1,
                                **kwargs)
    assert batched.seeds == (suite.EVALUATION_SEED_START, suite.EVALUATION_SEED_START + 1)
    assert batched.hits[0] == rest.hits[0] and batched.hits[1] == 0


def test_the_statistics_docstring_runs():
    failed, attempted = doctest.testmod(armgame.env.statistics)
    assert attempted >= 3 and failed == 0


def test_the_iqm_is_the_quarter_trimmed_mean():
    from scipy.stats import trim_mean  # here, not at the top: every worker collects this file, few need scipy.stats

    rng = np.random.default_rng(0)
    for shape in ((5, 7), (3, 4), (1, 1), (10, 2)):
        x = rng.normal(size=shape)
        assert iqm(x) == pytest.approx(trim_mean(x, 0.25, axis=None), rel=1e-12, abs=1e-15)
    assert iqm(np.array([[0.0, 100.0], [1.0, 2.0]])) == 1.5  # one run far off moves it not at all


def exact_bootstrap(scores: np.ndarray, statistic) -> np.ndarray:
    """The statistic on every stratified resample of ``scores`` (runs x tasks), each equally likely."""
    runs, tasks = scores.shape
    per_task = [list(itertools.product(range(runs), repeat=runs)) for _ in range(tasks)]
    values = []
    for choice in itertools.product(*per_task):
        sample = np.stack([scores[list(rows), t] for t, rows in enumerate(choice)], axis=1)
        values.append(float(statistic(sample[None])[0]))
    return np.sort(values)


@pytest.mark.parametrize("statistic", [iqm, mean_of_tasks, median_of_tasks])
def test_the_stratified_bootstrap_matches_every_resample_enumerated(statistic):
    scores = np.array([[0.1, 2.0], [0.7, 3.5], [0.3, 9.0]])  # 3 runs of 2 tasks: 27 x 27 resamples
    exact = exact_bootstrap(scores, statistic)
    low, high = stratified_bootstrap_ci(scores, statistic, reps=50_000, seed=1)
    # The percentile interval's ends lie between the exact distribution's 2nd and 3rd, 97th and 98th percentiles.
    assert np.quantile(exact, 0.02) <= low <= np.quantile(exact, 0.03)
    assert np.quantile(exact, 0.97) <= high <= np.quantile(exact, 0.98)
    assert stratified_bootstrap_ci(scores, statistic, reps=2_000, seed=1) == \
        stratified_bootstrap_ci(scores, statistic, reps=2_000, seed=1)


def test_each_task_is_resampled_from_its_own_runs_only():
    scores = np.array([[1.0, 10.0], [2.0, 20.0]])
    seen = []

    def record(samples):
        seen.append(samples.copy())
        return samples.mean(axis=(1, 2))

    stratified_bootstrap_ci(scores, record, reps=200, seed=0)
    samples = np.concatenate(seen)
    assert set(np.unique(samples[:, :, 0])) <= {1.0, 2.0} and set(np.unique(samples[:, :, 1])) <= {10.0, 20.0}


@pytest.mark.parametrize("protocol", [2, 3])
def test_aggregate_runs_normalises_by_the_references_and_refuses_uneven_runs(protocol):
    from armgame.env.references import CEILINGS, REFERENCES_V3

    ones = CEILINGS if protocol == 2 else REFERENCES_V3
    top = {env_id: ones[env_id]["hits"] for env_id in ("armgame/Reach-v1", "armgame/ReachHold-v1")}
    runs = {"armgame/Reach-v1": [top["armgame/Reach-v1"], top["armgame/Reach-v1"], 0.53],
            "armgame/ReachHold-v1": [top["armgame/ReachHold-v1"], 0.46, top["armgame/ReachHold-v1"]]}
    result = armgame.env.aggregate_runs(runs, reps=1_000, protocol=protocol)
    assert result.scores.shape == (3, 2) and result.scores.max() == pytest.approx(1.0)
    # The six scores 1, 1, 0, 1, 0, 1 (normalised): their middle four 0, 1, 1, 1.
    assert result.iqm[0] == pytest.approx(0.75) and result.iqm[1] <= result.iqm[0] <= result.iqm[2]
    assert f"IQM normalised score (protocol {protocol}) 0.75" in result.summary()
    with pytest.raises(EnvArgumentError, match="same number"):
        armgame.env.aggregate_runs({"armgame/Reach-v1": [1.0], "armgame/ReachHold-v1": [1.0, 2.0]})
    with pytest.raises(EnvArgumentError, match="reference"):
        armgame.env.aggregate_runs({"armgame/Reach-v0": [1.0]})


def test_protocol_3_scores_a_center_out_run_by_its_hits_a_minute_and_refuses_a_bare_count():
    """Every trial of a CenterOut episode is hit by the model bot and by most runs, so protocol 3 ranks them by hits
    a minute: the model bot's own evaluation scores 1, a run as many hits but slower scores less, and a bare count
    of hits, which cannot say how fast, is refused rather than read as hits a minute."""
    from armgame.env.references import REFERENCES_V3

    env_id = "armgame/CenterOut-v1"
    model = armgame.env.evaluate("model", env_id, games=3)
    reference = REFERENCES_V3[env_id]
    # The model bot hits every trial, slower than the reference: its hits a minute, not its count, set its score.
    assert model.mean_hits == 8.0 and model.normalised == pytest.approx(
        (model.hits_per_minute - reference["random"]) / (reference["hits"] - reference["random"]))
    slower = evaluation.normalised_score(env_id, 8.0, hits_per_minute=reference["hits"] * 0.8)
    assert slower == pytest.approx((reference["hits"] * 0.8 - reference["random"]) /
                                   (reference["hits"] - reference["random"]))
    assert evaluation.normalised_score(env_id, 8.0) is None
    assert evaluation.normalised_score(env_id, 8.0, protocol=2) == pytest.approx(1.0)  # protocol 2: a count
    with pytest.raises(EnvArgumentError, match="hits a minute"):
        armgame.env.aggregate_runs({env_id: [8.0, 8.0]})
    as_read = [{"mean_hits": 8.0, "hits_per_minute": reference["hits"]}, model]  # a result.json, an Evaluation
    assert armgame.env.aggregate_runs({env_id: as_read}, reps=100).scores.ravel() == pytest.approx(
        [1.0, model.normalised])
    assert armgame.env.aggregate_runs({env_id: [8.0, 8.0]}, protocol=2, reps=100).scores.ravel().tolist() == [1, 1]


# ------------------------------------------------------------------ item 3: every game verifiable
def play(env, policy, seed: int, most: int = 10**6):
    observation, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    done, steps = False, 0
    while not done and steps < most:
        action = env.action_space.sample() if policy is None else policy(observation)
        observation, _, terminated, truncated, info = env.step(action)
        done, steps = terminated or truncated, steps + 1
    return info


ALL_IDS = tuple(i for i in gym.registry if i.startswith("armgame/"))


def short(env_id: str):
    """The id's env with short episodes: 4 s games, 2-trial CenterOut-v1 episodes (v0: a run, cut short)."""
    if env_id.startswith("armgame/Reach"):
        return gym.make(env_id, time_limit=4.0)
    return gym.make(env_id, episode_trials=2) if env_id.endswith("-v1") else gym.make(env_id)


def a_bot(env_id: str, env):
    if env_id.endswith("Continuous-v0"):
        return None  # v0's levels are not centred: no bot plays them (random play is recorded)
    if env_id.startswith("armgame/CenterOut") and env_id.endswith("-v0"):
        from armgame.env.center_out import CenterOutBotPolicy

        return CenterOutBotPolicy("model", env)
    return bot_policy("model", env)


def test_every_id_is_covered():
    assert len(ALL_IDS) == 23  # 20, and the separating tier's three (suite.TIER)


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_every_game_an_env_plays_is_recorded_and_verifies(env_id):
    env = short(env_id)
    bot = a_bot(env_id, env)
    for k, policy in enumerate([None] if bot is None else [None, bot]):
        info = play(env, policy, 7 + k, most=400)  # a CenterOut-v0 run is recorded as far as it went
        replay = replay_of(env, driver="random" if policy is None else "model bot")
        assert replay.result.hits == info["hits"]
        read = Replay.from_bytes(replay.to_bytes())
        ok, got = read.verify()
        assert ok, (env_id, k, got)
        if env_id.startswith("armgame/Reach"):
            plain = env.unwrapped.game_variant.plain if env.unwrapped.version else True
            assert (read.task is None) == (plain and "Continuous" not in env_id), env_id
        else:
            assert read.task.hold_at_home == env.unwrapped.session.hold_at_home


def test_a_centre_out_episode_s_go_cue_rule_is_part_of_its_replay(tmp_path, capsys):
    env = gym.make("armgame/CenterOutHold-v1", episode_trials=2)
    play(env, None, 3, most=400)  # random keys never hold still at home: no go cue in 8 s
    path = tmp_path / "episode.json"
    replay_of(env, driver="random").save(path)
    assert main(["verify", str(path)]) == 0
    assert "go cue after a hold at home" in capsys.readouterr().out
    data = json.loads(path.read_text())
    data["task"]["hold_at_home"] = False  # the other rule: go cues, and trials, come anyway
    path.write_text(json.dumps(data))
    assert main(["verify", str(path)]) == 1


def test_a_variant_game_recorded_without_its_section_differs_and_with_it_matches(tmp_path, capsys):
    # What train_ppo.py wrote before: the key timeline alone, which replays the plain game.
    env = gym.make("armgame/ReachField-v1", time_limit=6.0)
    info = play(env, bot_policy("model", env), 3)
    assert info["hits"] >= 3
    bare = Replay.from_session(env.unwrapped.session, "script", driver="bot")
    assert not bare.verify()[0]
    path = tmp_path / "game.json"
    replay_of(env, driver="model bot").save(path)
    assert main(["verify", str(path)]) == 0
    out = capsys.readouterr().out
    assert "matches" in out and "armgame/ReachField-v1" in out and "curl field" in out
    # The section is what the result depends on: a changed field is another game.
    data = json.loads(path.read_text())
    data["task"]["field"]["b"] = -2.0
    path.write_text(json.dumps(data))
    assert main(["verify", str(path)]) == 1
    assert "DIFFERS" in capsys.readouterr().out


# ------------------------------------------------------------------ item 4: fields that stay physical
def pump(observation):
    """The keys that push each joint the way it turns: all the energy the muscles can feed the arm."""
    w1, w2 = observation[2], observation[3]
    return np.array([w1 > 0, w1 <= 0, w2 > 0, w2 <= 0], dtype=np.int8)


@pytest.mark.parametrize(("field", "strength"), [("curl", MAX_FIELD_STRENGTH), ("curl", -MAX_FIELD_STRENGTH),
                                                 ("viscous", MAX_VISCOUS_STRENGTH), ("viscous", -MAX_VISCOUS_STRENGTH)])
def test_every_field_at_its_extremes_plays_whole_games_within_the_declared_bounds(field, strength):
    env = gym.make("armgame/Reach-v1", field=field, field_strength=strength, time_limit=5.0,
                   observation_dtype="float64")
    space = env.observation_space
    assert np.isfinite(space.low).all() and np.isfinite(space.high).all()
    for policy in (None, pump):
        observation, _ = env.reset(seed=2)
        env.action_space.seed(2)
        done = False
        while not done:
            observation, _, terminated, truncated, info = env.step(
                env.action_space.sample() if policy is None else policy(observation))
            assert space.contains(observation)
            done = terminated or truncated
        assert truncated and not terminated and "stopped" not in info  # the whole game, no runaway


def test_a_field_beyond_its_range_is_refused_in_one_line():
    for field, strength in (("viscous", 3.0), ("viscous", -2.5), ("curl", 51.0)):
        with pytest.raises(EnvArgumentError, match="field_strength") as caught:
            gym.make("armgame/Reach-v1", field=field, field_strength=strength)
        assert "\n" not in str(caught.value)


def test_a_runaway_stops_the_game_cleanly_and_its_replay_verifies():
    env = gym.make("armgame/Reach-v1", time_limit=10.0, observation_dtype="float64")
    env.unwrapped.variant = ReachVariant(field="viscous", field_strength=10.0)  # beyond the range, set directly
    observation, _ = env.reset(seed=3)
    done = False
    while not done:
        observation, _, terminated, truncated, info = env.step(pump(observation))
        assert env.observation_space.contains(observation)
        done = terminated or truncated
    assert terminated and not truncated and "past 34.4 rad/s" in info["stopped"] and "\n" not in info["stopped"]
    with pytest.raises(gym.error.ResetNeeded):
        env.step(pump(observation))
    replay = Replay.from_bytes(replay_of(env).to_bytes())
    assert replay.task.stopped and replay.verify()[0]


# ------------------------------------------------------------------ item 6: the batched reward's round-off
def test_the_batched_dense_reward_is_the_single_envs_to_round_off():
    batched = gym.make_vec("armgame/Reach-v1", num_envs=8, time_limit=4.0)
    single = gym.make_vec("armgame/Reach-v1", num_envs=8, time_limit=4.0, vectorization_mode="sync")
    assert type(batched).__name__ == "ReachV1VectorEnv"
    batched.reset(seed=0)
    single.reset(seed=0)
    batched.action_space.seed(1)
    largest, returns = 0.0, np.zeros((2, 8))
    for _ in range(200):
        action = batched.action_space.sample()
        rb, rs = batched.step(action)[1], single.step(action)[1]
        largest = max(largest, float(np.abs(rb - rs).max()))
        returns += rb, rs
    assert largest <= REWARD_TOLERANCE and np.abs(returns[0] - returns[1]).max() <= 200 * REWARD_TOLERANCE
    assert returns.std() > 0  # the rewards were not all zero


# ------------------------------------------------------------------ item 1: the committed PPO runs
@pytest.mark.slow  # some hundred games replayed: seconds, which the README's minute has no room for
def test_every_committed_ppo_run_s_kept_game_verifies():
    """Each protocol run's ``game.json`` (``train_ppo.py --out``) replays to what it recorded, on every id."""
    from armgame.commands import read_env_games, read_lab_replays

    read_lab_replays()  # as the commands that verify do: records' own readers never need them
    read_env_games()
    games = sorted((Path(__file__).resolve().parent.parent / "benchmarks" / "results").glob("ppo*/*/seed*/game.json"))
    assert len(games) >= 16 * 5
    for path in games:
        assert Replay.load(path).verify()[0], path


def test_the_committed_ppo_runs_are_whole_and_summarised_by_their_curves():
    """benchmarks/results/ppo* hold train_ppo.py --out runs (curve, result, a game): each result's mean is its 100
    test games', and ``reference_scores.py curves`` reports every run from its files (their games verify: above)."""
    import importlib.util

    root = Path(__file__).resolve().parent.parent
    spec = importlib.util.spec_from_file_location("reference_scores", root / "benchmarks" / "reference_scores.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    folders = sorted(path for path in (root / "benchmarks" / "results").glob("ppo*") if path.is_dir())  # a budget each
    assert folders
    for folder in folders:
        report = module.curves(folder)
        for path in sorted(folder.rglob("result.json")):
            result = json.loads(path.read_text(encoding="utf-8"))
            hits = result["test_hits"]
            assert len(hits) == 100 and result["mean_hits"] == pytest.approx(sum(hits) / 100)
            assert result["env_steps"] >= result["budget_steps"] and f"{result['mean_hits']:.1f}" in report
            assert (path.parent / "game.json").is_file()
    # docs/programs.md reports every id's runs of each budget once five seeds are in: ``runs-table`` of the files.
    text = (root / "docs" / "programs.md").read_text(encoding="utf-8")
    table = module.runs_table()
    assert table in text
    five_seeded = [id_folder for folder in folders for id_folder in folder.iterdir()
                   if len(list(id_folder.glob("seed*/result.json"))) >= 5]
    rows = table.splitlines()[2:]
    assert len(rows) == len(five_seeded) >= 4
    for id_folder in five_seeded:
        means = [json.loads(path.read_text(encoding="utf-8"))["mean_hits"]
                 for path in sorted(id_folder.glob("seed*/result.json"))]
        assert any(f"`{id_folder.name}`" in row and f"**{sum(means) / len(means):.1f}**" in row
                   and ", ".join(f"{m:.1f}" for m in means) in row for row in rows), id_folder
    # The curves the page says fall over the last half are the table's falling ones.
    prose = " ".join(text.split())
    falling = [row.split("`")[1] for row in rows if "| falling:" in row]
    assert f"Some curves fall over the last half ({', '.join(falling)})" in prose
    # CenterOut's ids at 1 M: the median over seeds hits every trial by half the budget (the table's 1/2 column).
    centre = [row for row in rows if "`CenterOut" in row]
    assert len(centre) == 4 and all(row.split("|")[2].strip() == "1 M, 5" and row.split("|")[6].strip() == "8.0"
                                     for row in centre)
    assert "CenterOut's four ids at 2 times (`--steps 1000000 --out benchmarks/results/ppo-1m`: their median over " \
           "seeds hits every trial by half of it)" in prose
    # CenterOutHold-v1: the seeds whose last policy fell had hit every trial in validation up to 900,000 steps.
    runs = {json.loads(p.read_text(encoding="utf-8"))["training_seed"]: p.parent
            for p in (root / "benchmarks" / "results" / "ppo-1m" / "CenterOutHold-v1").glob("seed*/result.json")}
    means = {seed: json.loads((folder / "result.json").read_text(encoding="utf-8"))["mean_hits"]
             for seed, folder in runs.items()}
    fell = sorted(seed for seed, mean in means.items() if f"{mean:.1f}" != "8.0")
    for seed in fell:
        curve = (runs[seed] / "curve.csv").read_text(encoding="utf-8").splitlines()[1:]
        assert all(float(line.split(",")[2]) == 8.0 for line in curve if 500_000 <= int(line.split(",")[0]) <= 900_000)
    assert len(fell) == 2 and len(means) == 5
    assert (f"two seeds' validation games hit every trial up to 900,000 steps, and their last policies score "
            f"{means[fell[0]]:.1f} and {means[fell[1]]:.1f} on the test games, so PPO's mean there is "
            f"{sum(means.values()) / 5:.1f} of the 8.0 its other three seeds score") in prose
    # PPO's aggregate over the 4 M runs is ``aggregate``'s report of them, as printed, under protocols 3 and 2.
    for protocol in (3, 2):
        report = module.aggregate(root / "benchmarks" / "results" / "ppo", protocol)
        assert "\n".join("    " + line for line in report.splitlines()) in text and "x 12 ids" in report
        assert f"(protocol {protocol})" in report
    # The prose's range of PPO's protocol 3 scores, id by id, is its longest runs'.
    from armgame.env.evaluation import normalised_score

    scores = [normalised_score(env_id, sum(by_budget[max(by_budget)]) / len(by_budget[max(by_budget)]), protocol=3)
              for env_id, by_budget in module.long_runs().items() if env_id in module.IDS and "CenterOut" not in env_id]
    assert len(scores) == 12
    assert f"id for id within {min(scores):.2f} to {max(scores):.2f}" in text
    assert f"PPO's protocol 3 score is {min(scores):.2f} to {max(scores):.2f} on every Reach id of the suite" in text
    # The page's reading of ReachHard-v1's rows: protocol 1's 500 k far below, still rising at 10 M by a fifth of
    # the rise at 4 M, about 3 hits for another 5 M.
    from armgame.env.references import REFERENCE_HITS

    hard = {row.split("|")[2].strip(): row for row in rows if "`ReachHard-v1`" in row}
    slopes = {budget: float(row.split("|")[9].split(":")[1].split("(")[0]) for budget, row in hard.items()}
    assert f"far from PPO's reach on ReachHard-v1 ({REFERENCE_HITS['armgame/ReachHard-v1']['ppo']:.1f} hits)" in prose
    assert "rising" in hard["10 M, 5"] and round(slopes["4 M, 5"] / slopes["10 M, 5"]) == 5
    assert round(slopes["10 M, 5"] * 5) == 3 and "by a fifth as much, about 3 hits more for another 5 M" in prose


@pytest.mark.slow
def test_protocol_runs_go_on_where_the_last_sitting_stopped(tmp_path, capsys):
    """``reference_scores.py runs``: every (id, seed) a ``train_ppo.py --out`` run; a finished one is skipped, one a
    sitting left unfinished (no result.json) is started again from nothing, and the curves are printed at the end."""
    pytest.importorskip("stable_baselines3")  # the rl extra, not the test extra: run where it is installed
    import importlib.util

    root = Path(__file__).resolve().parent.parent
    spec = importlib.util.spec_from_file_location("reference_scores", root / "benchmarks" / "reference_scores.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    ask = dict(out=tmp_path, ids=["armgame/ReachHold-v1"], seeds=[0, 1], steps=256, test_games=2, every=4096)
    module.protocol_runs(**ask)
    first = capsys.readouterr().out
    results = sorted(tmp_path.glob("ReachHold-v1/seed*/result.json"))
    assert [path.parent.name for path in results] == ["seed0", "seed1"] and "test games (2): " in first
    assert "armgame/ReachHold-v1: PPO, training seeds [0, 1]" in first and "next: " in first
    kept = results[0].read_bytes()
    results[1].unlink()  # seed 1 cut off by the end of a sitting: its curve half written
    (results[1].parent / "curve.csv").write_text("env_steps,wall_seconds,mean_hits,min_hits,max_hits\n")
    module.protocol_runs(**ask)
    again = capsys.readouterr().out
    assert "seed 0: done before" in again and "seed 1: 256 env steps into" in again  # a rollout: 4,096 steps
    assert results[0].read_bytes() == kept and results[1].is_file()
    assert json.loads(results[1].read_text(encoding="utf-8"))["training_seed"] == 1
    # A run another process holds (the same command in another terminal) is left to it, its files untouched.
    from armgame.records.locking import file_lock

    results[1].unlink()
    with file_lock(tmp_path / "ReachHold-v1" / "seed1.lock", wait=0.0):
        module.protocol_runs(**ask)
    held = capsys.readouterr().out
    assert "seed 1: another process is training it" in held and "still training elsewhere: ReachHold-v1 seed 1" in held
    assert (results[1].parent / "curve.csv").is_file() and not results[1].exists()


@pytest.mark.slow
def test_the_docs_figure_of_the_ppo_curves_is_drawn_from_the_committed_runs(tmp_path):
    """docs/img/ppo_curves.png is ``reference_scores.py figure`` of the committed runs: a panel for every id of the
    runs table, at its longest budget, and the committed picture the size a fresh one is (a panel more or less
    changes it: the figure was not redrawn)."""
    import importlib.util

    from matplotlib.image import imread

    root = Path(__file__).resolve().parent.parent
    spec = importlib.util.spec_from_file_location("reference_scores", root / "benchmarks" / "reference_scores.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    titles = module.curves_figure(tmp_path / "curves.png")
    listed = {row.split("|")[1].strip().strip("`") for row in module.runs_table().splitlines()[2:]}
    assert sorted(title.split(",")[0] for title in titles) == sorted(listed)
    assert imread(tmp_path / "curves.png").shape == imread(root / "docs" / "img" / "ppo_curves.png").shape
    assert "(img/ppo_curves.png)" in (root / "docs" / "programs.md").read_text(encoding="utf-8")


def test_the_protocols_example_in_the_docs_prints_what_its_comment_says():
    """docs/programs.md's aggregate example, its made-up runs normalised by the ceilings (protocol 2)."""
    runs = {"armgame/ReachHold-v1": [61.2, 60.7, 62.3, 44.0, 61.0],
            "armgame/ReachDelay-v1": [60.3, 61.2, 66.8, 58.1, 63.0]}
    printed = armgame.env.aggregate_runs(runs, reps=2_000).summary()
    guide = (Path(__file__).resolve().parent.parent / "docs" / "programs.md").read_text(encoding="utf-8")
    assert f"# {printed.split(' over ')[0]} over 5 ..." in guide
    assert all(", ".join(map(str, hits)) in guide for hits in runs.values())
