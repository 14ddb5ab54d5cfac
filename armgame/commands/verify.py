"""armgame verify: recompute a replay's game and compare it with the recorded result."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "verify",
        help="check that a replay (or every entry of a score table) reproduces its score",
        description="Replay the game of FILE from its input timeline and compare the result with the recorded "
        "one. FILE is a replay, or a score table (scores.json, or its folder): then every entry is checked "
        "against its replay, or a folder of replays: then every *.json file in it (symbolic links are not "
        "followed). Many games are recomputed together in batches. "
        "Exit status: 0 if everything matches, 1 if not, 2 on a bad file.",
    )
    p.add_argument("file", metavar="FILE", help="a replay file, a scores.json, a scores folder or a folder of replays")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..records.scores import TABLE_NAME

    path = Path(args.file)
    if path.is_dir() and not (path / TABLE_NAME).exists():
        return _verify_folder(path)
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
    from ..records.replay import Replay

    replay = Replay.load(path)
    return _report(path, replay, *replay.verify())


def _verify_folder(folder) -> int:
    from ..errors import UserError
    from ..records.batch_verify import replay_files, verify_files
    from ..records.scores import TABLE_NAME

    paths = replay_files(folder)
    if not paths:
        raise UserError(f"{folder}: no score table ({TABLE_NAME}) and no replays (*.json) there")
    differ = bad = 0
    for path, replay, got, ok in verify_files(paths):
        if got is None:
            bad += 1
            print(f"{path}: BAD REPLAY: {str(replay).removeprefix(f'{path}: ')}")
        else:
            differ += _report(path, replay, ok, got)
    print(f"{folder}: {len(paths)} replays, {differ} differ, {bad} unreadable")
    return 2 if bad else 1 if differ else 0


def _report(path, replay, ok: bool, got) -> int:
    """One line on a recomputed replay; 0 if it matches, else 1."""
    from .. import __version__

    r = replay.result
    who = f"{replay.player}'s game" if replay.player else "game"
    about = f"{who} ({replay.driven}, seed {r.seed}, {r.duration:g} s)"
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
    from ..records.batch_verify import check_entries
    from ..records.scores import ScoreTable

    table = ScoreTable(folder)
    if not table.path.is_file():
        raise UserError(f"{table.path}: no score table there")
    entries, damage = table.read()
    if damage:
        print(f"armgame verify: {damage.describe(table.path)}", file=sys.stderr)
    flagged = 0
    for e, c in check_entries(table, sorted(entries, key=lambda e: e.when)):
        flagged += not c.ok
        line = f"{e.name}: score {e.score} ({e.how}, {e.date[:16].replace('T', ' ')}): {c.label}"
        print(line + (f": {c.detail}" if c.detail else ""))
    print(f"{table.path}: {len(entries)} entries, {flagged} flagged")
    return 2 if damage else 1 if flagged else 0
