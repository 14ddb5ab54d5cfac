"""Many recorded games replayed in batches: ``replay_many``, the class's and the verifier's way to check games.

Owns the grouping of recorded games into batches (games whose configurations may share one, at most
``batch_size`` at a time; the rest one at a time) and the fallback that keeps its promise: each result equals
``GameSession(config).play(timeline, stop_step)``, a game decided at a knife edge by the fast kernel played
again alone.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields

from ..rules import GameConfig
from ..session import GameResult, GameSession, InputEvent
from .session import BATCH_INTEGRATORS, PER_GAME_FIELDS, BatchGameSession


def replay_many(configs: Sequence[GameConfig], timelines: Sequence[Sequence[InputEvent]],
                stop_steps: Sequence[int | None] | None = None, batch_size: int = 4096,
                exact: bool = False, kernel: str | None = None) -> list[GameResult]:
    """Play many recorded games, in batches where their configurations allow; results in input order.

    Games whose configurations can share a batch (``batch_problem``) run together, at most
    ``batch_size`` at a time; the others (an implicit integrator) run one at a time in a
    ``GameSession``. Each result equals ``GameSession(config).play(timeline, stop_step)``.

    The batches run the compiled kernel where built (exact), else numpy's fast kernel unless
    ``exact``: then a game in which some hit was decided within ``KNIFE_EDGE`` of a target's
    edge (where round-off could tip it) is played again alone, so the results are the single
    session's either way. ``kernel`` is ``BatchGameSession``'s.
    """
    n = len(configs)
    if len(timelines) != n:
        raise ValueError(f"{n} configurations but {len(timelines)} timelines")
    stops = [None] * n if stop_steps is None else list(stop_steps)
    results: list[GameResult | None] = [None] * n
    groups: dict[tuple, list[int]] = {}
    for i, c in enumerate(configs):
        if c.integrator in BATCH_INTEGRATORS:
            key = tuple(getattr(c, f.name) for f in fields(GameConfig) if f.name not in PER_GAME_FIELDS)
            groups.setdefault(key, []).append(i)
        else:
            results[i] = GameSession(c).play(timelines[i], stops[i])
    for members in groups.values():
        for lo in range(0, len(members), batch_size):
            part = members[lo:lo + batch_size]
            if len(part) == 1:  # a batch of one costs more than the single session
                i = part[0]
                results[i] = GameSession(configs[i]).play(timelines[i], stops[i])
                continue
            batch = BatchGameSession([configs[i] for i in part], exact=exact, kernel=kernel)
            played = batch.play([timelines[i] for i in part], [stops[i] for i in part])
            for i, r, edge in zip(part, played, batch.knife_edge.tolist(), strict=True):
                results[i] = GameSession(configs[i]).play(timelines[i], stops[i]) if edge else r
    return results  # type: ignore[return-value]
