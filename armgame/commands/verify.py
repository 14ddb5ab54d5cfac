"""armgame verify: recompute a replay's game and compare it with the recorded result."""

from __future__ import annotations

import argparse

from ..words import plural
from . import read_env_games, read_lab_replays


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "verify",
        help="check that a replay (or every entry of a score table) reproduces its score",
        description="Replay the game of FILE from its input timeline and compare the result with the recorded "
        "one, and name the ruleset it plays (standard, or custom). FILE is a replay, a score table "
        "(scores.json, or its folder: every entry is checked against its replay) or a folder of replays "
        "(every *.json file in it; symbolic links are not followed). Many games are recomputed together "
        "in batches. Exit status: 0 if everything matches, 1 if something does not, 2 on a bad file or a damaged "
        "table, 3 if nothing differs but some games were left unchecked (--max-work).",
    )
    p.add_argument("file", metavar="FILE", help="a replay file, a scores.json, a scores folder or a folder of replays")
    p.add_argument("--max-work", type=work_arg, metavar="N", help="check no game whose replay counts more than N "
                   "physics steps of work (its steps, 100 a claimed hit under the standard rules and 6,000 under "
                   "others, 20 an input event: counted before it runs; a standard game is 15,000 and its hits and "
                   "events): such games are reported NOT CHECKED. For a folder from a stranger: bounds the run "
                   "(default: every game is checked, whatever it costs)")
    p.set_defaults(run=run)


def work_arg(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 1 <= value <= 10**12:
        raise argparse.ArgumentTypeError(f"must be a whole number of steps from 1 to 10^12, got {text!r}")
    return value


def run(args: argparse.Namespace) -> int:
    from ..records.scores import TABLE_NAME
    from ..records.storage import user_path

    read_lab_replays()
    read_env_games()
    path = user_path(args.file, "FILE")
    limit = getattr(args, "max_work", None)
    if path.is_dir() and not (path / TABLE_NAME).exists() and not (path / TABLE_NAME).is_symlink():
        return _verify_folder(path, limit)
    if path.is_dir():
        return _verify_table(path, limit)
    if path.name == TABLE_NAME or _looks_like_table(path):
        return _verify_table(path.parent, limit)
    return _verify_replay(path, limit)


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


def _verify_replay(path, limit: int | None = None) -> int:
    from ..records.replay import Replay, VerifyCostError
    from ..records.scores import NOT_CHECKED

    replay = Replay.load(path)
    if _over(replay, limit):
        _not_checked(path, replay)
        return 3
    try:
        verdict = replay.verify(_budget(limit))
    except VerifyCostError as exc:  # a hit storm, stopped at its budget: seconds and one line, not minutes
        print(f"{path}: {NOT_CHECKED}: {exc} (--max-work N spends up to N)")
        return 3
    return _report(path, replay, *verdict)


def _budget(limit: int | None) -> int:
    """What one game's verification may spend as it runs (``Replay.verify``): ``MAX_VERIFY_WORK``, or more if
    --max-work asks for more (a game it let through up front never stops on the way)."""
    from ..limits import MAX_VERIFY_WORK

    return MAX_VERIFY_WORK if limit is None else max(limit, MAX_VERIFY_WORK)


def _over(replay, limit: int | None) -> bool:
    from ..records.scores import replay_work

    return limit is not None and replay_work(replay) > limit


def _not_checked(path, replay) -> None:
    from ..records.scores import NOT_CHECKED, not_checked_detail, replay_work

    print(f"{path}: {NOT_CHECKED}: {not_checked_detail(replay, replay_work(replay))}")


def _verify_folder(folder, limit: int | None = None) -> int:
    from ..errors import UserError
    from ..records.batch_verify import replay_files, verify_files
    from ..records.replay import VerifyCostError
    from ..records.scores import NOT_CHECKED, TABLE_NAME

    paths = replay_files(folder)
    if not paths:
        raise UserError(f"{folder}: no score table ({TABLE_NAME}) and no replays (*.json) there")
    differ = bad = unchecked = 0
    skip = (lambda r: _over(r, limit)) if limit is not None else None
    for path, replay, got, ok in verify_files(paths, skip, _budget(limit)):
        if got is None and isinstance(replay, VerifyCostError):  # a hit storm, stopped at its budget
            unchecked += 1
            print(f"{path}: {NOT_CHECKED}: {replay}")
        elif got is None and not isinstance(replay, Exception):
            unchecked += 1
            _not_checked(path, replay)
        elif got is None:
            bad += 1
            print(f"{path}: BAD REPLAY: {str(replay).removeprefix(f'{path}: ')}")
        else:
            differ += _report(path, replay, ok, got)
    over = "--max-work" if limit is not None else "their work budget"  # without it: hit storms stopped on the way
    left = f", {unchecked} not checked (over {over})" if unchecked else ""
    print(f"{folder}: {plural(len(paths), 'replay')}, {differ} differ, {bad} unreadable{left}")
    return 2 if bad else 1 if differ else 3 if unchecked else 0


def _report(path, replay, ok: bool, got) -> int:
    """One line on a recomputed replay; 0 if it matches, else 1."""
    from .. import __version__
    from ..records.replay import same_outcome
    from ..records.rulesets import ruleset_name

    r = replay.result
    who = f"{replay.player}'s game" if replay.player else "game"
    about = f"{who} ({ruleset_name(replay.config)} rules, {replay.driven}, seed {r.seed}, {r.duration:g} s)"
    if replay.task is not None and hasattr(replay.task, "about"):  # a Gymnasium env's game: its variant replayed
        about = f"{who} ({replay.task.about()}, {replay.driven}, seed {r.seed}, {r.duration:g} s)"
    elif replay.task is not None:  # a lab run: its trials were compared too
        who = f"{replay.player}'s lab run" if replay.player else "lab run"
        about = (f"{who} ({replay.task.protocol.name}, {replay.driven}, seed {r.seed}, "
                 f"{plural(len(replay.task.trials), 'trial')})")
    if ok:
        print(f"{path}: matches: {about}: score {r.score}, {plural(r.hits, 'hit')}, {plural(r.resets, 'reset')}")
        return 0
    note = f" (recorded with armgame {replay.version}, checked with {__version__})" \
        if replay.version != __version__ else ""
    apart = getattr(replay.task, "hit_difference", None)  # a Reach env's game: the steps of its hits
    detail = apart(replay.config, replay.timeline, r) if apart is not None and same_outcome(got, r) else None
    if detail is not None:  # the same counts under another ruleset: where the hits part is what differs
        print(f"{path}: DIFFERS: {about}: the same score, hits, resets and steps, but {detail}{note}")
        return 1
    print(f"{path}: DIFFERS: {about}: recorded score {r.score}, {plural(r.hits, 'hit')}, "
          f"{plural(r.resets, 'reset')}, {plural(r.steps, 'step')}; the replay gives score {got.score}, "
          f"{plural(got.hits, 'hit')}, {plural(got.resets, 'reset')}, {plural(got.steps, 'step')}{note}")
    return 1


def _verify_table(folder, limit: int | None = None) -> int:
    import sys

    from ..errors import UserError
    from ..records.batch_verify import check_entries
    from ..records.identity import FirstEntries
    from ..records.scores import NOT_CHECKED, ScoreTable, VerificationCache, entry_order

    def warn(message: str) -> None:
        print(f"armgame verify: {message}", file=sys.stderr)

    cache = VerificationCache(warn=warn)
    table = ScoreTable(folder, warn=warn, cache=cache)
    if not table.path.is_file() or table.path.is_symlink():
        raise UserError(f"{table.path}: no score table there")
    entries, damage = table.read()
    if damage:
        warn(damage.describe(table.path))
    for note in table.notes:  # where this account's record of the table disagrees with it
        warn(note)
    flagged = unchecked = 0
    first: FirstEntries = FirstEntries()
    for e, c in check_entries(table, sorted(entries, key=entry_order), limit):  # the table's order, never a date
        twin = first.copy_of(e, e.replay_sha256, c.game, c.ok)
        if twin is not None and twin.replay_sha256 == e.replay_sha256:
            c = type(c)(False, "DUPLICATE", f"the same replay as {twin.name}'s earlier entry", c.ruleset)
        elif twin is not None:
            c = type(c)(False, "DUPLICATE", f"the same game as {twin.name}'s earlier entry", c.ruleset)
        unchecked += c.label == NOT_CHECKED
        flagged += not c.ok and c.label != NOT_CHECKED
        rules = f", {c.ruleset} rules" if c.ruleset else ""
        line = f"{e.name}: score {e.score} ({e.how}{rules}, {e.date[:16].replace('T', ' ')}): {c.label}"
        print(line + (f": {c.detail}" if c.detail else ""))
    cache.save()
    left = f", {unchecked} not checked (over --max-work)" if unchecked else ""
    print(f"{table.path}: {plural(len(entries), 'entry')}, {flagged} flagged{left}")
    return 2 if damage else 1 if flagged else 3 if unchecked else 0
