"""Speed of ``armgame scores`` and ``armgame verify`` on a big table: cold, then from the cache.

    python benchmarks/scores_speed.py                 # 1,000 standard 60 s games (about 2 min to build)
    python benchmarks/scores_speed.py --entries 200
    python benchmarks/scores_speed.py --planted old-format --entries 100
    python benchmarks/scores_speed.py --planted hit-storm
    python benchmarks/scores_speed.py --planted failing --entries 600

Builds a table of standard games with busy timelines in a temporary folder, then times, in
subprocesses: ``scores --all`` with an empty verification cache, the same again (every verdict
cached), ``scores`` (the top 10) and ``verify``. Figures are single runs: report them as ratios.

``--planted KIND`` builds instead a table a classmate planted to keep ``scores`` and every save
busy, with 10 honest keyboard games below, and times ``scores`` cold and cached, ``scores
--no-check --top 1`` and ``play --name`` (a 0.2 s game entered, ranked on the way):

* ``old-format``: entries of a format 1 table (no ruleset field), each with its own 4 MB replay
  (100,000 events);
* ``hit-storm``: one custom game whose target covers the arm's whole reach, an hour long, claiming
  100,000 hits, each costing a full draw of 1,000 postures;
* ``failing``: standard replays with a forged score of 99 (one busy game under many names, each its
  own replay file), above every honest game.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.records.replay import Replay
from armgame.records.scores import ScoreTable, table_bytes
from armgame.records.storage import atomic_write_bytes

KEYS = "dfjk"


def busy_game(seed: int) -> Replay:
    return Replay.from_session(busy_session(seed), "script", "busy.txt", f"player {seed}")


def busy_session(seed: int, shift: int = 0) -> GameSession:
    session = GameSession(GameConfig(seed=seed))
    for start in range(shift, session.total_steps, 150):
        session.advance(start - session.steps)
        session.key_event(KEYS[start // 150 % 4], "down")
        session.advance(40)
        session.key_event(KEYS[start // 150 % 4], "up")
    session.advance(session.total_steps)
    return session


def build(folder: Path, n: int) -> None:
    table = ScoreTable(folder)
    entries = []
    for seed in range(n):
        replay = busy_game(seed)
        path = table.save_replay(replay)
        entries.append(table_entry(table, replay, path))
    atomic_write_bytes(folder / "scores.json", table_bytes(entries), "score table")


def table_entry(table: ScoreTable, replay: Replay, path: Path):
    import hashlib
    import uuid

    from armgame.records.scores import ScoreEntry, replay_claims

    claims = replay_claims(replay)
    r = replay.result
    return ScoreEntry.from_dict(dict(
        id=uuid.uuid4().hex, name=replay.player, driven=replay.driven, driver=replay.driver, score=r.score,
        hits=r.hits, resets=r.resets, seed=r.seed, scene=r.scene, duration=r.duration, date=replay.date,
        version=replay.version, replay=path.name, replay_sha256=hashlib.sha256(path.read_bytes()).hexdigest(),
        ruleset=claims["ruleset"], config_sha256=claims["config_sha256"], game_sha256=claims["game_sha256"],
        complete=claims["complete"]))


def planted(folder: Path, kind: str, n: int) -> None:
    """A table of ``n`` planted entries of ``kind`` (see the module docstring) and 10 honest games."""
    import json

    table = ScoreTable(folder)
    entries = []
    for seed in range(10):  # the table's seed, each its own game
        honest = Replay.from_session(busy_session(10, seed), "keyboard", None, f"honest {seed}")
        entries.append(table_entry(table, honest, table.save_replay(honest)))
    if kind == "old-format":
        session = GameSession(GameConfig(seed=10))
        for _ in range(50_000):  # 100,000 events at step 0: a big replay of a standard game
            session.key_event("d", "down")
            session.key_event("d", "up")
        session.advance(session.total_steps)
        base = Replay.from_session(session, "keyboard", None, "old")
        for i in range(n):
            replay = base.with_player(f"old {i}")
            entry = table_entry(table, replay, table.save_replay(replay)).as_dict()
            for key in ("ruleset", "config_sha256", "game_sha256", "complete", "entered", "entered_at"):
                entry.pop(key, None)
            entries.append(entry)
        rows = [e if isinstance(e, dict) else json.loads(table_bytes([e]))["entries"][0] for e in entries]
        atomic_write_bytes(folder / "scores.json", json.dumps(
            {"format": "armgame-scores", "format_version": 1, "entries": rows}).encode(), "score table")
        return
    if kind == "hit-storm":
        for i in range(n):
            config = GameConfig(seed=i, time_limit=3600.0, target_radius=0.5, view=(-20.0, 20.0, -20.0, 20.0),
                                target_shoulder_range=(45.0, 45.0), target_elbow_range=(90.0, 90.0))
            session = GameSession(config)
            session.advance(10)
            forged = Replay.from_session(session, "keyboard", None, f"storm {i}").as_dict()
            forged["result"].update(score=100_000, hits=100_000, steps=config.total_steps)
            replay = Replay.from_dict(json.loads(json.dumps(forged)))
            entries.append(table_entry(table, replay, table.save_replay(replay)))
    elif kind == "failing":
        base = Replay.from_session(busy_session(1000), "keyboard", None, "forger").as_dict()
        base["result"].update(score=99, hits=99)
        for i in range(n):  # one forged game under many names: each its own replay file, each replayed
            replay = Replay.from_dict({**base, "player": f"forger {i}"})
            entries.append(table_entry(table, replay, table.save_replay(replay)))
    else:
        raise SystemExit(f"unknown --planted kind {kind!r}")
    atomic_write_bytes(folder / "scores.json", table_bytes(entries), "score table")


def timed(argv: list[str], env: dict[str, str]) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "armgame", *argv], check=True, env=env, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--entries", type=int, default=1000)
    parser.add_argument("--planted", choices=("old-format", "hit-storm", "failing"), default=None)
    args = parser.parse_args()
    if args.planted:
        return run_planted(args.planted, args.entries)
    with tempfile.TemporaryDirectory() as tmp:
        folder, cache = Path(tmp) / "table", Path(tmp) / "cache"
        start = time.perf_counter()
        build(folder, args.entries)
        print(f"built {args.entries} entries in {time.perf_counter() - start:.0f} s")
        env = {**os.environ, "ARMGAME_CACHE": str(cache)}
        print(f"scores --all, cold: {timed(['scores', '--all', '--scores', str(folder)], env):.1f} s")
        print(f"scores --all, cached: {timed(['scores', '--all', '--scores', str(folder)], env):.1f} s")
        print(f"scores (top 10), cached: {timed(['scores', '--scores', str(folder)], env):.1f} s")
        print(f"verify, cached: {timed(['verify', str(folder)], env):.1f} s")


def run_planted(kind: str, n: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder, cache = Path(tmp) / "table", Path(tmp) / "private" / "cache"
        start = time.perf_counter()
        planted(folder, kind, n)
        print(f"planted {n} {kind} entries above 10 honest ones in {time.perf_counter() - start:.0f} s")
        env = {**os.environ, "ARMGAME_CACHE": str(cache)}
        print(f"scores, cold: {timed(['scores', '--scores', str(folder)], env):.1f} s")
        print(f"scores, cached: {timed(['scores', '--scores', str(folder)], env):.1f} s")
        quick = ["scores", "--no-check", "--top", "1", "--scores", str(folder)]
        print(f"scores --no-check --top 1: {timed(quick, env):.1f} s")
        play = ["play", "--headless", "--duration", "0.2", "--name", "Late", "--scores", str(folder)]
        print(f"play --name (a 0.2 s game entered): {timed(play, env):.1f} s")


if __name__ == "__main__":
    main()
