"""armgame verify: recompute a replay's game and compare it with the recorded result."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "verify",
        help="check that a replay (or every entry of a score table) reproduces its score",
        description="Replay the game of FILE from its input timeline and compare the result with the recorded "
        "one, and name the ruleset it plays (standard, or custom). FILE is a replay, or a score table "
        "(scores.json, or its folder): then every entry is checked against its replay. Exit status: 0 if "
        "everything matches, 1 if not, 2 on a bad file.",
    )
    p.add_argument("file", metavar="FILE", help="a replay file, a scores.json or a scores folder")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..records.scores import TABLE_NAME
    from ..records.storage import user_path

    path = user_path(args.file, "FILE")
    if path.is_dir():
        return _verify_table(path)
    if path.name == TABLE_NAME or _looks_like_table(path):
        return _verify_table(path.parent)
    return _verify_replay(path)


def _looks_like_table(path) -> bool:
    import os

    from ..records.storage import DataFileError, open_regular

    try:
        fd = open_regular(path, "file")  # never blocks: a FIFO is refused, not waited on
    except DataFileError:
        return False
    try:
        return b'"armgame-scores"' in os.read(fd, 200)
    except OSError:
        return False
    finally:
        os.close(fd)


def _verify_replay(path) -> int:
    from .. import __version__
    from ..records.replay import Replay
    from ..records.rulesets import ruleset_name

    replay = Replay.load(path)
    ok, got = replay.verify()
    r = replay.result
    who = f"{replay.player}'s game" if replay.player else "game"
    about = f"{who} ({ruleset_name(replay.config)} rules, {replay.driven}, seed {r.seed}, {r.duration:g} s)"
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
    from ..records.scores import ScoreTable, VerificationCache

    cache = VerificationCache()
    table = ScoreTable(folder, cache=cache)
    if not table.path.is_file() or table.path.is_symlink():
        raise UserError(f"{table.path}: no score table there")
    entries, damage = table.read()
    if damage:
        print(f"armgame verify: {damage.describe(table.path)}", file=sys.stderr)
    flagged = 0
    seen: set[str] = set()
    for e in sorted(entries, key=lambda e: e.when):
        c = table.check(e)
        if c.ok and e.replay_sha256 in seen:
            c = type(c)(False, "DUPLICATE", "the same replay is entered more than once", c.ruleset)
        seen.add(e.replay_sha256)
        flagged += not c.ok
        rules = f", {c.ruleset} rules" if c.ruleset else ""
        line = f"{e.name}: score {e.score} ({e.how}{rules}, {e.date[:16].replace('T', ' ')}): {c.label}"
        print(line + (f": {c.detail}" if c.detail else ""))
    cache.save()
    print(f"{table.path}: {len(entries)} entries, {flagged} flagged")
    return 2 if damage else 1 if flagged else 0
