"""The evaluation protocol: a policy's hits per game on held-out game seeds, with a confidence interval.

``evaluate(policy, env_id)`` plays whole games of ``env_id`` on the suite's evaluation seeds
(``armgame.env.suite.EVALUATION_SEEDS``, which no training example uses), one single env, one game
per seed, and returns an ``Evaluation``: the hits of every game, their mean with a 95 % confidence
interval (Student's t over games), the score, the rates per minute (so games of another
``time_limit`` compare; hits a minute with its interval over the games' hits and lengths, ``ratio_interval``, since a
CenterOut episode lasts as long as its trials take) and, where the id has a reference, the normalised score of
protocol 3 (``armgame.env.suite.PROTOCOL_VERSION``): 0 for the random policy, 1 for the id's fixed reference
(``REFERENCES_V3``: the shooting controller's mean hits on a Reach id, the model bot's hits a minute on a
CenterOut id). ``normalised_score(..., protocol=2)`` still gives protocol 2's (by ``CEILINGS``, the best mean
hits measured when it was published).

The same policy, id, seeds and arguments give the same result, bit for bit: every game is reset
with its seed and a policy that samples (``"random"``) samples from a generator seeded by it.

**Every game starts with a fresh policy.** A game's result must not depend on the games played before
it, or the score of a seed would depend on where it stands in the list. The game's bots are made anew for
each game (their plans, their memory of the last target and their own clocks are a game's, not a
policy's); a policy of your own that keeps state between steps gets its ``reset()`` called before each
game, if it has one (``armgame.env.policies``' bots have one), or pass ``policy_factory``, called once a
game. (Until this was so, CenterOutHold-v1's naive bot scored 0 on seed 7,000,002 after another game and
1 hit alone: its clock ran on from one game into the next.)

**Stateful and recurrent models.** A model with SB3's ``predict`` and no ``reset()`` plays ``BATCH`` games at a
time, one ``predict`` call a step for all of them. Where its ``predict`` takes ``state`` and ``episode_start``
(``takes_state``: every SB3 model's does, and sb3-contrib's ``RecurrentPPO`` needs them), its recurrent state is
carried from step to step for every game, ``episode_start`` true at each game's first step only, so each game
starts from a fresh state. A model with a ``reset()`` (an SB3 model given one included) keeps a state of its own
that games played together would share, so its games are played one at a time: ``reset()`` is called before
each, and its recurrent state, where ``predict`` takes one, starts afresh with ``episode_start`` true at the
game's first step. (Before issue 52 a model's ``reset()`` was never called and no recurrent state was passed, so
a stateful model scored a seed differently alone and after other games.)

Several training seeds of one algorithm are summarised with ``aggregate_runs``: the interquartile mean
of their scores over the ids, with a stratified bootstrap interval (``armgame.env.statistics``).

>>> from armgame.env.evaluation import evaluate
>>> result = evaluate("model", "armgame/Reach-v1", games=2, time_limit=5.0)
>>> result.games, result.seeds
(2, (1000000000, 1000000001))
"""

from __future__ import annotations

import dataclasses
import inspect
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from .errors import EnvArgumentError
from .suite import EVALUATION_SEED_COUNT, EVALUATION_SEEDS, PROTOCOL_VERSION, PROTOCOLS

#: Games ``evaluate`` plays by default: a 95 % interval of about +-1 hit on Reach-v1's bots.
DEFAULT_GAMES = 100
#: The most games one call plays (a bound known before it starts).
MAX_GAMES = 10_000
BOT_NAMES = ("random", "naive", "model")

Policy = Callable[[np.ndarray], Any]


@dataclasses.dataclass(frozen=True)
class Evaluation:
    """What ``evaluate`` measured; ``hits`` and ``scores`` one entry a game, in ``seeds``' order."""

    env_id: str
    policy: str
    seeds: tuple[int, ...]
    hits: tuple[int, ...]
    scores: tuple[int, ...]
    minutes: float  # of game time a game, on average (an episode of CenterOut lasts as its trials do)
    normalised: float | None
    #: CenterOut ids: each game's mean seconds from a trial's go cue to its hit, over the trials it hit (nan: none);
    #: empty for Reach. Where every policy hits every trial, this is what still ranks them.
    reach_seconds: tuple[float, ...] = ()
    #: Each game's length in minutes of game time, in ``seeds``' order (``minutes`` is their mean): a Reach game lasts
    #: its ``time_limit``, a CenterOut episode as long as its trials take. Empty where not measured (made by hand).
    game_minutes: tuple[float, ...] = ()

    @property
    def games(self) -> int:
        return len(self.hits)

    @property
    def mean_hits(self) -> float:
        return float(np.mean(self.hits))

    @property
    def ci95(self) -> tuple[float, float]:
        """The mean hits' 95 % confidence interval (Student's t over games, never below 0: ``mean_interval``; the mean
        twice for one game)."""
        return mean_interval(self.hits, low=0.0)

    @property
    def mean_score(self) -> float:
        return float(np.mean(self.scores))

    @property
    def hits_per_minute(self) -> float:
        return self.mean_hits / self.minutes

    @property
    def hits_per_minute_ci95(self) -> tuple[float, float]:
        """``hits_per_minute``'s 95 % confidence interval over the games (``ratio_interval`` of each game's hits and
        minutes); without ``game_minutes``, the hits' interval over a game of the mean minutes."""
        if len(self.game_minutes) != len(self.hits):
            low, high = self.ci95
            return low / self.minutes, high / self.minutes
        return ratio_interval(self.hits, self.game_minutes, low=0.0)

    @property
    def score_per_minute(self) -> float:
        return self.mean_score / self.minutes

    @property
    def mean_reach_seconds(self) -> float | None:
        """The mean over games (those with a hit) of ``reach_seconds``; None for Reach or where nothing was hit."""
        times = [t for t in self.reach_seconds if not math.isnan(t)]
        return float(np.mean(times)) if times else None

    def summary(self) -> str:
        low, high = self.ci95
        norm = "" if self.normalised is None else f", normalised {self.normalised:.2f}"
        reach = self.mean_reach_seconds
        time = "" if reach is None else f", {reach:.2f} s from the go cue to a hit"
        return (f"{self.policy} on {self.env_id}: {self.mean_hits:.1f} hits a game (95% CI {low:.1f} to {high:.1f}, "
                f"{self.games} games), {self.hits_per_minute:.1f} a minute{time}{norm}")


def mean_interval(values: Sequence[float], *, low: float = -math.inf,
                  high: float = math.inf) -> tuple[float, float]:
    """The mean's 95 % confidence interval by Student's t, clipped to ``[low, high]``: the values the mean can take.

    A count's mean is never below 0 (``low=0``), yet t's symmetric interval goes below it where a few runs are far
    above the rest (PPO's seeds on ReachMemory-v1: 0.5, 0.2, 0.0, 0.3 and 16.1 hits give -5.4 to 12.3). Clipping
    keeps t's interval and its coverage: the true mean lies in ``[low, high]``, so the clipped part never held it
    and the clipped interval holds it whenever t's did; it only stops printing values the quantity cannot take. (A
    skew-aware interval, a bootstrap's, would move the upper end too, but with five seeds a bootstrap's coverage
    is worse than t's, so the tables keep t.)"""
    from scipy.stats import t

    x = np.asarray(values, dtype=np.float64)
    mean = float(x.mean())
    if len(x) < 2:
        return mean, mean
    half = float(t.ppf(0.975, len(x) - 1) * x.std(ddof=1) / math.sqrt(len(x)))
    return max(mean - half, low), min(mean + half, high)


def ratio_interval(numerators: Sequence[float], denominators: Sequence[float], *, low: float = -math.inf,
                   high: float = math.inf) -> tuple[float, float]:
    """The 95 % confidence interval of a ratio of means, ``sum(numerators) / sum(denominators)`` (hits a minute: all
    games' hits over all their minutes), by the delta method with Student's t over the ``n`` pairs, clipped to
    ``[low, high]`` as ``mean_interval`` is.

    The ratio's linearisation ``R + mean(y - R x) / mean(x)`` has standard error ``s / (sqrt(n) mean(x))``, ``s``
    the standard deviation of the residuals ``y_i - R x_i`` (Cochran's ratio estimator); the interval is ``R +- t
    s / (sqrt(n) mean(x))`` with t's 97.5 % quantile on ``n - 1`` degrees of freedom. So games that all hit every
    trial still give an interval, from the spread of their lengths, and games of one length give the hits' t
    interval over that length (``mean_interval(y) / x``), the same as before there were lengths to spread. The
    delta method rather than a bootstrap: it is closed-form (no seed, no resampling cost in a table), and with 100
    games of a smooth ratio whose denominator never comes near 0 its normal approximation is sound. One pair, or
    residuals all 0 (every game the same rate), give the ratio twice."""
    from scipy.stats import t

    y = np.asarray(numerators, dtype=np.float64)
    x = np.asarray(denominators, dtype=np.float64)
    if y.shape != x.shape or y.ndim != 1 or len(y) == 0:
        raise ValueError(f"ratio_interval needs as many numerators as denominators, at least one, got {y.shape} "
                         f"and {x.shape}")
    if not x.sum() > 0:
        raise ValueError("ratio_interval's denominators must add up to more than 0")
    ratio = float(y.sum() / x.sum())
    if len(y) < 2:
        return ratio, ratio
    half = float(t.ppf(0.975, len(y) - 1) * (y - ratio * x).std(ddof=1) / (math.sqrt(len(y)) * x.mean()))
    return max(ratio - half, low), min(ratio + half, high)


def evaluate(policy: Policy | str | Any, env_id: str, *, seeds: Sequence[int] | None = None,
             games: int = DEFAULT_GAMES, deterministic: bool = True,
             policy_factory: Callable[[gym.Env], Policy] | None = None, **env_kwargs: Any) -> Evaluation:
    """Play ``games`` whole games of ``env_id`` with ``policy`` and measure its hits.

    ``policy``: ``"random"`` (the action space sampled, seeded by each game's seed), ``"naive"`` or
    ``"model"`` (the game's bots through ``BotPolicy``; Reach ids), a callable ``observation ->
    action``, or a model with SB3's ``predict(observation, deterministic=...)``. ``seeds``: the
    game seeds (default: the first ``games`` evaluation seeds). ``env_kwargs`` go to
    ``gymnasium.make`` (e.g. ``time_limit``); the normalised score is given only for the id's own
    arguments, those its reference scores were measured with.

    Every game gets a fresh policy: the bots are made anew, a policy with a ``reset()`` method has it
    called before each game, and ``policy_factory(env)`` (then ``policy`` only names it) makes a new
    policy for each game.
    """
    if seeds is None:
        if isinstance(games, bool) or not isinstance(games, int) or not 1 <= games <= min(MAX_GAMES,
                                                                                          EVALUATION_SEED_COUNT):
            raise EnvArgumentError(f"games must be a whole number from 1 to {MAX_GAMES}, got {games!r}")
        seeds = EVALUATION_SEEDS[:games]
    seeds = tuple(int(s) for s in seeds)
    if not 1 <= len(seeds) <= MAX_GAMES:
        raise EnvArgumentError(f"seeds must hold 1 to {MAX_GAMES} game seeds, got {len(seeds)}")
    if policy_factory is not None and not callable(policy_factory):
        raise EnvArgumentError(f"policy_factory must be a callable env -> policy, got {policy_factory!r}")
    # A model with a reset() keeps a state of its own, so its games are played one at a time.
    if policy_factory is None and not isinstance(policy, str) and hasattr(policy, "predict") \
            and not callable(getattr(policy, "reset", None)):
        name = type(policy).__name__
        hits, scores, durations, reach = _play_batched(policy, env_id, seeds, deterministic, env_kwargs)
    else:
        name, hits, scores, durations, reach = _play_one_by_one(policy, env_id, seeds, deterministic, env_kwargs,
                                                                policy_factory)
    mean_hits = float(np.mean(hits))
    minutes = float(np.mean(durations))
    normalised = None if env_kwargs else normalised_score(env_id, mean_hits, hits_per_minute=mean_hits / minutes)
    return Evaluation(env_id, name, seeds, hits, scores, minutes, normalised, reach, durations)


def _play_one_by_one(policy: Any, env_id: str, seeds: tuple[int, ...], deterministic: bool,
                     env_kwargs: dict[str, Any], policy_factory: Callable[[gym.Env], Policy] | None = None,
                     ) -> tuple[str, tuple[int, ...], tuple[int, ...], tuple[float, ...], tuple[float, ...]]:
    """The games one after another in one single env: (the policy's name, hits, scores, each game's minutes, each
    game's seconds from a go cue to a hit: CenterOut's).

    The policy is fresh for each game (``evaluate``): made anew by ``policy_factory`` or, for a bot's name,
    by ``bot_policy``; else its ``reset()``, where it has one, is called before the game."""
    env = gym.make(env_id, **env_kwargs)
    try:
        if policy_factory is not None:
            name = policy if isinstance(policy, str) else getattr(policy_factory, "__name__", "policy")
        else:
            act, name = _policy(policy, env, deterministic)
        hits, scores, durations, reach = [], [], [], []
        for seed in seeds:
            if policy_factory is not None:
                act = _policy(policy_factory(env), env, deterministic)[0]
            elif isinstance(policy, str) and policy in ("naive", "model"):
                act = _policy(policy, env, deterministic)[0]  # a new bot: nothing of the last game in it
            else:
                if callable(getattr(policy, "reset", None)):
                    policy.reset()
                if not isinstance(policy, str) and hasattr(policy, "predict"):
                    act = _policy(policy, env, deterministic)[0]  # a recurrent state of its own starts afresh
            observation, info = env.reset(seed=seed)
            if name == "random":
                env.action_space.seed(seed)
            done = False
            while not done:
                observation, _, terminated, truncated, info = env.step(act(observation))
                done = terminated or truncated
            hits.append(int(info["hits"]))
            scores.append(int(info.get("score", info["hits"])))
            durations.append(_game_minutes(env))
            reach.append(_reach_seconds(env))
    finally:
        env.close()
    return name, tuple(hits), tuple(scores), tuple(durations), _kept(reach)


#: Games a model's evaluation steps together: one ``predict`` call a step for all of them.
BATCH = 100


def _play_batched(model: Any, env_id: str, seeds: tuple[int, ...], deterministic: bool,
                  env_kwargs: dict[str, Any],
                  ) -> tuple[tuple[int, ...], tuple[int, ...], tuple[float, ...], tuple[float, ...]]:
    """A model's games, ``BATCH`` at a time in Gymnasium's ``SyncVectorEnv`` of single envs (each game the single
    env's, seeded alike), the model asked once a step for all of them: a network's forward pass costs
    about as much for a hundred observations as for one."""
    from gymnasium.vector import AutoresetMode

    hits: list[int] = []
    scores: list[int] = []
    durations: list[float] = []
    reach: list[float | None] = []
    for start in range(0, len(seeds), BATCH):
        part = list(seeds[start:start + BATCH])
        envs = gym.make_vec(env_id, num_envs=len(part), vectorization_mode="sync",
                            vector_kwargs={"autoreset_mode": AutoresetMode.DISABLED}, **env_kwargs)
        try:
            observation, info = envs.reset(seed=part)
            done = np.zeros(len(part), dtype=bool)
            final_hits = np.zeros(len(part), dtype=np.int64)
            final_scores = np.zeros(len(part), dtype=np.int64)
            final_minutes = np.zeros(len(part))
            final_reach: list[float | None] = [None] * len(part)
            recurrent = takes_state(model)
            state, starts = None, np.ones(len(part), dtype=bool)
            while not done.all():
                if recurrent:
                    action, state = model.predict(observation, state=state, episode_start=starts,
                                                  deterministic=deterministic)
                else:
                    action, _ = model.predict(observation, deterministic=deterministic)
                observation, _, terminated, truncated, info = envs.step(action)
                over = terminated | truncated
                starts = over.copy()  # a game that ended starts again: its recurrent state with it
                ended = over & ~done
                final_hits[ended] = info["hits"][ended]
                final_scores[ended] = info["score"][ended] if "score" in info else info["hits"][ended]
                for i in np.flatnonzero(ended):
                    final_minutes[i] = _game_minutes(envs.envs[i])
                    final_reach[i] = _reach_seconds(envs.envs[i])
                done |= ended
                if over.any() and not done.all():
                    # A finished game's place plays on, uncounted, until the others end; a game there may end
                    # again (a CenterOut episode is as long as its trials take), so every game that ended now
                    # starts again, not only the counted ones: a vector env without autoreset steps none ended.
                    envs.reset(options={"reset_mask": over})
        finally:
            envs.close()
        hits += final_hits.tolist()
        scores += final_scores.tolist()
        durations += final_minutes.tolist()
        reach += final_reach
    return tuple(hits), tuple(scores), tuple(durations), _kept(reach)


def _policy(policy: Any, env: gym.Env, deterministic: bool) -> tuple[Policy, str]:
    if isinstance(policy, str):
        if policy not in BOT_NAMES:
            raise EnvArgumentError(f"policy must be 'random', 'naive', 'model', a callable or a model with "
                                   f"predict(), got {policy!r}")
        if policy == "random":
            space = env.action_space
            return (lambda _observation: space.sample()), policy
        from .policies import bot_policy

        try:
            return bot_policy(policy, env), policy
        except ValueError as exc:  # an env the game's bots do not play
            raise EnvArgumentError(str(exc)) from None
    if hasattr(policy, "predict"):
        return _predictor(policy, deterministic), type(policy).__name__
    if callable(policy):
        return policy, getattr(policy, "__name__", type(policy).__name__)
    raise EnvArgumentError(f"policy must be 'random', 'naive', 'model', a callable or a model with predict(), "
                           f"got {type(policy).__name__}")


def takes_state(model: Any) -> bool:
    """Whether ``model.predict`` takes SB3's recurrent arguments, ``state`` and ``episode_start`` (every SB3 model
    does; a recurrent one, sb3-contrib's ``RecurrentPPO``, needs them carried through a game)."""
    try:
        names = inspect.signature(model.predict).parameters
    except (TypeError, ValueError):
        return False
    return "state" in names and "episode_start" in names


def _predictor(model: Any, deterministic: bool) -> Policy:
    """A model's ``predict`` as ``observation -> action`` for one game: its recurrent state carried from step to
    step, with ``episode_start`` true at the game's first step only."""
    if not takes_state(model):
        return lambda observation: model.predict(observation, deterministic=deterministic)[0]
    carried: list[Any] = [None, True]

    def act(observation: np.ndarray) -> Any:
        action, carried[0] = model.predict(observation, state=carried[0], episode_start=np.array([carried[1]]),
                                           deterministic=deterministic)
        carried[1] = False
        return action

    return act


def _game_minutes(env: gym.Env) -> float:
    base = env.unwrapped
    settings = getattr(base, "settings", None)
    if settings is not None:
        return settings.config.time_limit / 60.0
    session = base.session
    return session.steps * session.config.dt / 60.0 if session is not None else math.nan


def _reach_seconds(env: gym.Env) -> float | None:
    """A CenterOut episode's mean seconds from a trial's go cue to its hit (the end of the stay in the target), over
    the trials it hit (nan: none); None for an env without trials (Reach)."""
    session = getattr(env.unwrapped, "session", None)
    outcomes = getattr(session, "outcomes", None)
    if outcomes is None or not hasattr(session, "trial_index"):
        return None
    times = [(o.end_step - o.go_step) * session.config.dt for o in outcomes if o.hit]
    return float(np.mean(times)) if times else math.nan


def _kept(reach: list[float | None]) -> tuple[float, ...]:
    """Each game's reach time, or nothing where the env has no trials."""
    return () if any(t is None for t in reach) else tuple(t for t in reach if t is not None)


def normalised_score(env_id: str, mean_hits: float, protocol: int = PROTOCOL_VERSION, *,
                     hits_per_minute: float | None = None) -> float | None:
    """The score on ``env_id`` as ``protocol`` normalises it: 0 for random play, 1 for the id's reference; None for
    an id without one (or a CenterOut id's protocol 3 score without ``hits_per_minute``).

    Protocol 3 (the default): ``(x - random) / (reference - random)`` by ``REFERENCES_V3``, a fixed score never
    made from the runs being scored, so a run above it scores above 1. ``x`` is in the reference's ``unit``: mean
    hits a game on a Reach id, hits a minute on a CenterOut id (``hits_per_minute``, ``Evaluation.hits_per_minute``),
    since every trial of an episode is hit by the reference and by most runs, and speed is what still ranks them.
    Protocol 2: ``(hits - random) / (ceiling - random)`` by ``CEILINGS``, hits a game on every id."""
    from .references import CEILINGS, REFERENCE_HITS, REFERENCES_V3, TIER_HITS

    if protocol not in PROTOCOLS:
        raise ValueError(f"protocol must be one of {', '.join(map(str, PROTOCOLS))}, got {protocol!r}")
    if protocol == 3:
        row = REFERENCES_V3.get(env_id)
        if row is None:
            return None
        x = hits_per_minute if row["unit"] == "hits a minute" else mean_hits
        low, high = row["random"], row["hits"]
    else:
        # The separating tier's random play is in TIER_HITS: it has no protocol 2 ceiling, only protocol 3's.
        reference = REFERENCE_HITS.get(env_id) or TIER_HITS.get(env_id)
        ceiling = CEILINGS.get(env_id)
        if reference is None or ceiling is None:
            return None
        x, low, high = mean_hits, reference["random"], ceiling["hits"]
    return None if x is None or high == low else (x - low) / (high - low)


def _scored_per_minute(env_id: str, protocol: int) -> bool:
    from .references import REFERENCES_V3

    return protocol == 3 and REFERENCES_V3.get(env_id, {}).get("unit") == "hits a minute"


@dataclasses.dataclass(frozen=True)
class Aggregate:
    """Several training seeds' scores over several ids, summarised (``aggregate_runs``).

    ``scores``: one row a training seed, one column an id (``env_ids``' order); each entry that run's
    normalised score on the id (``normalised``) or its mean hits. ``iqm``, ``mean`` and ``median`` are
    (point, 95 % low, 95 % high), the intervals stratified bootstrap ones (``armgame.env.statistics``)."""

    env_ids: tuple[str, ...]
    scores: np.ndarray
    normalised: bool
    iqm: tuple[float, float, float]
    mean: tuple[float, float, float]
    median: tuple[float, float, float]
    protocol: int = PROTOCOL_VERSION  # the normalised scores' (``normalised_score``)

    @property
    def runs(self) -> int:
        return int(self.scores.shape[0])

    def summary(self) -> str:
        what = "normalised score" if self.normalised else "hits a game"
        point, low, high = self.iqm
        under = f" (protocol {self.protocol})" if self.normalised else ""
        return (f"IQM {what}{under} {point:.2f} (95% stratified bootstrap CI {low:.2f} to {high:.2f}) over "
                f"{self.runs} training seeds x {len(self.env_ids)} ids")


def aggregate_runs(runs: Mapping[str, Sequence[Evaluation | Mapping[str, Any] | float]], *, normalise: bool = True,
                   protocol: int = PROTOCOL_VERSION, reps: int = 50_000, seed: int = 0) -> Aggregate:
    """Summarise an algorithm's training seeds over ids: IQM, mean and median with stratified bootstrap intervals.

    ``runs`` maps each id to one score per training seed, in the same seeds' order for every id: an
    ``Evaluation``, a run's ``result.json`` as read (its ``mean_hits``, and ``hits_per_minute`` where it has one)
    or a number of mean hits. ``normalise``: score each by ``normalised_score`` under ``protocol`` (every id needs
    a reference; a CenterOut id's protocol 3 score needs its hits a minute, which a bare number does not carry),
    else by hits. Report the IQM and its interval, the number of training seeds, the budget in env steps and the
    protocol (Agarwal et al. 2021)."""
    if not runs:
        raise EnvArgumentError("aggregate_runs needs at least one id's runs")
    counts = {len(values) for values in runs.values()}
    if len(counts) != 1 or 0 in counts:
        raise EnvArgumentError(f"every id needs the same number of runs, at least 1, got {sorted(counts)}")
    env_ids = tuple(runs)
    columns = []
    for env_id in env_ids:
        column = []
        for value in runs[env_id]:
            if isinstance(value, Evaluation):
                hits, per_minute = value.mean_hits, value.hits_per_minute
            elif isinstance(value, Mapping):
                hits, per_minute = float(value["mean_hits"]), value.get("hits_per_minute")
            else:
                hits, per_minute = float(value), None
            if normalise:
                score = normalised_score(env_id, hits, protocol, hits_per_minute=per_minute)
                if score is None:
                    reason = ("its protocol 3 score is by hits a minute: pass Evaluations or result.json records"
                              if per_minute is None and _scored_per_minute(env_id, protocol)
                              else "it has no reference scores to normalise by: normalise=False")
                    raise EnvArgumentError(f"{env_id}: {reason}")
                hits = score
            column.append(hits)
        columns.append(column)
    from .statistics import iqm, mean_of_tasks, median_of_tasks, stratified_bootstrap_ci

    table = np.array(columns, dtype=np.float64).T
    summaries = []
    for statistic in (iqm, mean_of_tasks, median_of_tasks):
        low, high = stratified_bootstrap_ci(table, statistic, reps=reps, seed=seed)
        summaries.append((float(statistic(table)), low, high))  # type: ignore[arg-type]
    return Aggregate(env_ids, table, normalise, *summaries, protocol=protocol)
