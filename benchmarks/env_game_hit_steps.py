"""Move Reach env games' replays from the ``"reach-env"`` section's version 1 (counts only) to version 2 (issue 52).

Version 2 records the physics step of every hit, which ``armgame verify`` compares one by one, so a ruleset edited
to the same count (a dwell of 50 steps made 1) is refused; this armgame refuses version 1, which could not tell.
The steps are not guessed: each game is replayed under its own section, and a file is rewritten only where the
replay reproduces the recorded score, hits, resets and steps (the version-1 check, the most a version-1 file can
be held to); the rest of the file is kept byte for byte but the section. Run it on files whose history you trust
(the repository's committed games: their git history is the record that the ruleset was not edited):

    python benchmarks/env_game_hit_steps.py benchmarks/results/ppo*/*/seed*/game.json

A file already at version 2 is left alone; one that does not replay to its record is named and left alone, and the
exit status is 1.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

from armgame.commands import read_env_games, read_lab_replays
from armgame.records.env_game import COUNTS_ONLY_VERSION, TASK_KIND, EnvGameTask, hit_steps
from armgame.records.replay import Replay


def migrate(path: Path) -> str:
    """Rewrite ``path`` at version 2 if it is a version-1 Reach env game that replays to its record; what it did."""
    raw = path.read_bytes()
    section = json.loads(raw).get("task")
    if not (isinstance(section, dict) and section.get("kind") == TASK_KIND
            and section.get("version") == COUNTS_ONLY_VERSION):
        return "left alone (no version-1 Reach env section)"
    data = json.loads(raw)
    data["task"] = {**section, "version": 2, "hit_steps": []}  # read as version 2 to load; its steps come next
    replay = Replay.from_bytes(json.dumps(data).encode(), str(path))
    old = EnvGameTask.from_dict(section, replay.config, replay.result.steps, legacy=True)
    ok, got, session = old.verify(replay.config, replay.timeline, replay.result, max_work=None)
    if not ok:
        return f"DIFFERS: recorded {replay.result.hits} hits, the replay gives {got.hits}: left alone"
    moved = replace(replay, task=replace(old, hit_steps=hit_steps(session)))
    if not moved.verify(None)[0]:
        return "DIFFERS at version 2: left alone"
    moved.save(path)
    return f"version 2, {len(moved.task.hit_steps)} hit steps"  # type: ignore[union-attr]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="+", type=Path, help="replays (game.json) to move to version 2")
    args = parser.parse_args(argv)
    read_lab_replays()
    read_env_games()
    failed = 0
    for path in args.files:
        said = migrate(path)
        failed += said.startswith("DIFFERS")
        print(f"{path}: {said}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
