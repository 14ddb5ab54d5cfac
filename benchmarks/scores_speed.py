"""Speed of ``armgame scores`` and ``armgame verify`` on a big table: cold, then from the cache.

    python benchmarks/scores_speed.py                 # 1,000 standard 60 s games (about 2 min to build)
    python benchmarks/scores_speed.py --entries 200

Builds a table of standard games with busy timelines in a temporary folder, then times, in
subprocesses: ``scores --all`` with an empty verification cache, the same again (every verdict
cached), ``scores`` (the top 10) and ``verify``. Figures are single runs: report them as ratios.
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
    session = GameSession(GameConfig(seed=seed))
    for start in range(0, session.total_steps, 150):
        session.advance(start - session.steps)
        session.key_event(KEYS[start // 150 % 4], "down")
        session.advance(40)
        session.key_event(KEYS[start // 150 % 4], "up")
    session.advance(session.total_steps)
    return Replay.from_session(session, "script", "busy.txt", f"player {seed}")


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
        ruleset=claims["ruleset"], config_sha256=claims["config_sha256"]))


def timed(argv: list[str], env: dict[str, str]) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "armgame", *argv], check=True, env=env, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--entries", type=int, default=1000)
    args = parser.parse_args()
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


if __name__ == "__main__":
    main()
