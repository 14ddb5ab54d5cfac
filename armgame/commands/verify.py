"""armgame verify: recompute a replay's game and compare it with the recorded result."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "verify",
        help="check that a replay (or every entry of a score table) reproduces its score",
        description="Replay the game of FILE from its input timeline and compare the result with the recorded "
        "one. FILE is a replay, or a score table (scores.json, or its folder): then every entry is checked "
        "against its replay. Exit status: 0 if everything matches, 1 if not, 2 on a bad file.",
    )
    p.add_argument("file", metavar="FILE", help="a replay file, a scores.json or a scores folder")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..records.scores import TABLE_NAME

    path = Path(args.file)
    if path.is_dir():
        return _verify_table(path)
    if path.name == TABLE_NAME or _looks_like_table(path):
        return _verify_table(path.parent)
    return _verify_replay(path)


def _looks_like_table(path) -> bool:
    try:
        with open(path, "rb") as f:
            return b'"armgame-scores"' in f.read(200)
    except OSError:
        return False


def _verify_replay(path) -> int:
    from .. import __version__
    from ..records.replay import Replay

    replay = Replay.load(path)
    ok, got = replay.verify()
    r = replay.result
    who = f"{replay.player}'s game" if replay.player else "game"
    about = f"{who} ({replay.driven}, seed {r.seed}, {r.duration:g} s)"
    if replay.task is not None:  # a lab run: its trials were compared too
        who = f"{replay.player}'s lab run" if replay.player else "lab run"
        about = f"{who} ({replay.task.protocol.name}, {replay.driven}, seed {r.seed}, {len(replay.task.trials)} trials)"
    if ok:
        print(f"{path}: matches: {about}: score {r.score}, {r.hits} hits, {r.resets} resets")
        return 0
    note = f" (recorded with armgame {replay.version}, checked with {__version__})" \
        if replay.version != __version__ else ""
    print(f"{path}: DIFFERS: {about}: recorded score {r.score}, {r.hits} hits, {r.resets} resets, "
          f"{r.steps} steps; the replay gives score {got.score}, {got.hits} hits, {got.resets} resets, "
          f"{got.steps} steps{note}")
    return 1


def _verify_table(folder) -> int:
    import sys

    from ..errors import UserError
    from ..records.scores import ScoreTable

    table = ScoreTable(folder)
    if not table.path.is_file():
        raise UserError(f"{table.path}: no score table there")
    entries, damage = table.read()
    if damage:
        print(f"armgame verify: {damage.describe(table.path)}", file=sys.stderr)
    flagged = 0
    for e in sorted(entries, key=lambda e: e.when):
        c = table.check(e)
        flagged += not c.ok
        line = f"{e.name}: score {e.score} ({e.how}, {e.date[:16].replace('T', ' ')}): {c.label}"
        print(line + (f": {c.detail}" if c.detail else ""))
    print(f"{table.path}: {len(entries)} entries, {flagged} flagged")
    return 2 if damage else 1 if flagged else 0
