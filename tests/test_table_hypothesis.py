"""Drawn tables (issue 16, class 11): honest entries, copies of one game under other names and dates,
the same replay entered twice, old-format entries, forged scores and planted caches, in any mix.
Whatever is drawn, ``scores`` and ``verify`` return 0, 1 or 2 without raising, list each game at most
once, never list a forged score as checked, and write nothing but their own cache."""

import hashlib
import json
import os
from dataclasses import replace

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from armgame import __version__
from armgame.cli import main
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.records.cache import VerificationCache
from armgame.records.identity import game_digest
from armgame.records.listing import listing
from armgame.records.replay import Replay
from armgame.records.scores import ScoreTable, replay_claims
from armgame.records.standings import player_key

_GAMES: list[Replay] = []


def games() -> list[Replay]:
    """Three short, distinct games (built once)."""
    if not _GAMES:
        for press in (3, 9, 20):
            session = GameSession(GameConfig(seed=10, time_limit=0.3))
            session.advance(press)
            session.key_event("j", "down")
            session.advance(session.total_steps)
            _GAMES.append(Replay.from_session(session, "keyboard", None, f"p{press}"))
    return _GAMES


KINDS = st.sampled_from(["honest", "copy", "same replay", "old format", "forged"])


def entry_of(replay: Replay, data: bytes, name: str, n: int, old: bool) -> dict:
    claims = replay_claims(replay)
    r = replay.result
    entry = dict(id=f"{n:032x}", name=name, driven=replay.driven, driver=replay.driver, score=r.score, hits=r.hits,
                 resets=r.resets, seed=r.seed, scene=r.scene, duration=r.duration, date=replay.date,
                 version=replay.version, replay=f"r{n}.json", replay_sha256=hashlib.sha256(data).hexdigest())
    if not old:
        entry.update(ruleset=claims["ruleset"], config_sha256=claims["config_sha256"],
                     game_sha256=claims["game_sha256"], complete=True, entered=n + 1, entered_at=replay.date)
    return entry


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow])
@given(kinds=st.lists(st.tuples(KINDS, st.integers(0, 2)), min_size=1, max_size=6),
       cache=st.sampled_from(["none", "in the table", "others may write", "private ok for forgeries"]))
def test_drawn_tables_hold(tmp_path_factory, kinds, cache):
    root = tmp_path_factory.mktemp("t")
    folder = root / "table"
    (folder / "replays").mkdir(parents=True)
    entries, true_scores, forged_digests = [], {}, {}
    for n, (kind, which) in enumerate(kinds):
        replay = games()[which]
        if kind == "copy":
            replay = replace(replay.with_player(f"copier{n}"), date=f"1970-01-01T00:00:{n:02d}+00:00")
        data = replay.to_bytes()
        if kind == "forged":
            forged = json.loads(data)
            forged["result"].update(score=50, hits=50)
            data = json.dumps(forged).encode()
            replay = Replay.from_bytes(data)
        if kind == "same replay" and entries:
            previous = entries[-1]
            entries.append({**previous, "id": f"{n:032x}", "entered": n + 1})
            continue
        (folder / "replays" / f"r{n}.json").write_bytes(data)
        entry = entry_of(replay, data, replay.player or "x", n, old=kind == "old format")
        entries.append(entry)
        true_scores[entry["id"]] = games()[which].result.score
        if kind == "forged":
            forged_digests[entry["replay_sha256"]] = replay
    version = 1 if any(k == "old format" for k, _ in kinds) else 3
    (folder / "scores.json").write_text(json.dumps({"format": "armgame-scores", "format_version": version,
                                                    "entries": entries}))
    cache_dir = {"none": root / "private" / "cache", "in the table": folder / "cache",
                 "others may write": root / "shared", "private ok for forgeries": root / "private" / "cache"}[cache]
    if cache != "none":
        cache_dir.mkdir(parents=True)
        items = {d: {"ok": True, "label": "ok", "detail": "", "claims": replay_claims(r)}
                 for d, r in forged_digests.items()}
        (cache_dir / f"verified-{__version__}.json").write_text(json.dumps(
            {"format": "armgame-verified", "version": __version__, "items": items}))
        if cache == "others may write":
            os.chmod(cache_dir, 0o777)
    os.environ["ARMGAME_CACHE"] = str(cache_dir)
    before = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    for argv in (["scores", "--scores", str(folder), "--all"], ["scores", "--scores", str(folder), "--no-check"],
                 ["verify", str(folder)]):
        assert main(argv) in (0, 1, 2)
    assert {p: p.read_bytes() for p in folder.rglob("*") if p.is_file() and p.parent != folder / "cache"} == \
        {p: b for p, b in before.items() if p.parent != folder / "cache"}
    table = ScoreTable(folder, warn=lambda m: None, cache=VerificationCache(cache_dir, warn=lambda m: None))
    lists, _ = listing(table, table.all_entries(), None, check=True, per_player=False)  # every game: each its row
    rows = [row.best[0] for rows in lists.values() for row in rows]
    digests = [game_digest(Replay.load(folder / "replays" / e.replay)) for e in rows]
    assert len(digests) == len(set(digests))  # each game listed once
    honest = {game_digest(games()[which]) for kind, which in kinds if kind in ("honest", "copy", "old format")}
    assert honest <= set(digests)  # and every honest game is listed: no copy or forgery pushes it out
    trusted_plant = cache == "private ok for forgeries"  # the user's own cache: trusted by design
    if not trusted_plant:
        assert all(e.score == true_scores[e.id] for e in rows)  # no forged score listed as checked
    # One row a player: each player once, at the first of their games in the every-game list, with all of
    # that list's games of theirs (every entry is checked here, so every game counted checked out).
    players, _ = listing(table, table.all_entries(), None, check=True)
    for name, games_listed in lists.items():
        mine = players[name]
        assert len({player_key(row.name) for row in mine}) == len(mine)
        firsts = {}
        for row in games_listed:
            firsts.setdefault(player_key(row.name), row.best[0].id)
        assert [row.best[0].id for row in mine] == list(firsts.values())
        assert sum(row.games for row in mine) == len(games_listed)
