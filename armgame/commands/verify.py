"""armgame verify: recompute a replay's game and compare it with the recorded result."""

from __future__ import annotations

import argparse

from ..words import plural
from . import read_lab_replays


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "verify",
        help="check that a replay (or every entry of a score table) reproduces its score",
        description="Replay the game of FILE from its input timeline and compare the result with the recorded "
        "one, and name the ruleset it plays (standard, or custom). FILE is a replay, a score table "
        "(scores.json, or its folder: every entry is checked against its replay) or a folder of replays "
        "(every *.json file in it; symbolic links are not followed). Many games are recomputed together "
        "in batches. Exit status: 0 if everything matches, 1 if not, 2 on a bad file.",
    )
    p.add_argument("file", metavar="FILE", help="a replay file, a scores.json, a scores folder or a folder of replays")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..records.scores import TABLE_NAME
    from ..records.storage import user_path

    read_lab_replays()
    path = user_path(args.file, "FILE")
    if path.is_dir() and not (path / TABLE_NAME).exists() and not (path / TABLE_NAME).is_symlink():
        return _verify_folder(path)
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
    print(f"{folder}: {plural(len(paths), 'replay')}, {differ} differ, {bad} unreadable")
    return 2 if bad else 1 if differ else 0


def _report(path, replay, ok: bool, got) -> int:
    """One line on a recomputed replay; 0 if it matches, else 1."""
    from .. import __version__
    from ..records.rulesets import ruleset_name

    r = replay.result
    who = f"{replay.player}'s game" if replay.player else "game"
    about = f"{who} ({ruleset_name(replay.config)} rules, {replay.driven}, seed {r.seed}, {r.duration:g} s)"
    if replay.task is not None:  # a lab run: its trials were compared too
        who = f"{replay.player}'s lab run" if replay.player else "lab run"
        about = (f"{who} ({replay.task.protocol.name}, {replay.driven}, seed {r.seed}, "
                 f"{plural(len(replay.task.trials), 'trial')})")
    if ok:
        print(f"{path}: matches: {about}: score {r.score}, {plural(r.hits, 'hit')}, {plural(r.resets, 'reset')}")
        return 0
    note = f" (recorded with armgame {replay.version}, checked with {__version__})" \
        if replay.version != __version__ else ""
    print(f"{path}: DIFFERS: {about}: recorded score {r.score}, {plural(r.hits, 'hit')}, "
          f"{plural(r.resets, 'reset')}, {plural(r.steps, 'step')}; the replay gives score {got.score}, "
          f"{plural(got.hits, 'hit')}, {plural(got.resets, 'reset')}, {plural(got.steps, 'step')}{note}")
    return 1


def _verify_table(folder) -> int:
    import sys

    from ..errors import UserError
    from ..records.batch_verify import check_entries
    from ..records.identity import FirstEntries
    from ..records.scores import ScoreTable, VerificationCache, entry_order

    cache = VerificationCache()
    table = ScoreTable(folder, cache=cache)
    if not table.path.is_file() or table.path.is_symlink():
        raise UserError(f"{table.path}: no score table there")
    entries, damage = table.read()
    if damage:
        print(f"armgame verify: {damage.describe(table.path)}", file=sys.stderr)
    flagged = 0
    first: FirstEntries = FirstEntries()
    for e, c in check_entries(table, sorted(entries, key=entry_order)):  # the table's order, never a claimed date
        twin = first.copy_of(e, e.replay_sha256, c.game, c.ok)
        if twin is not None and twin.replay_sha256 == e.replay_sha256:
            c = type(c)(False, "DUPLICATE", f"the same replay as {twin.name}'s earlier entry", c.ruleset)
        elif twin is not None:
            c = type(c)(False, "DUPLICATE", f"the same game as {twin.name}'s earlier entry", c.ruleset)
        flagged += not c.ok
        rules = f", {c.ruleset} rules" if c.ruleset else ""
        line = f"{e.name}: score {e.score} ({e.how}{rules}, {e.date[:16].replace('T', ' ')}): {c.label}"
        print(line + (f": {c.detail}" if c.detail else ""))
    cache.save()
    print(f"{table.path}: {plural(len(entries), 'entry')}, {flagged} flagged")
    return 2 if damage else 1 if flagged else 0
