"""The score table's bytes: its format, parsed (or salvaged where damaged), its head, written one entry a line.

Pure data, no files: ``records.tablefile`` reads and writes the table under its lock and calls these.

Trust: the table is parsed as data with a schema check of every field. A damaged table (truncated, not JSON, an
entry failing its checks) still yields every entry that passes the schema, wherever it sits in the text
(``_salvage``, a scan linear in the file's size whatever it holds), with the damage said. Two entries with one id
are damage, and one of them is kept.

The head holds the seed the table ranks and ``next_entry``, the next place in the order of entry. A seed that is not
valid is kept as found, never replaced by the default; counters are bounded and a planted one is repaired at the
next write (``numbered``).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from ..limits import DEFAULT_SEED
from ..valid import COUNT_MAX, INT64_MAX, check_int, check_keys
from ..words import plural
from .entry import _OPTIONAL, ScoreEntry, entry_order, sort_key
from .storage import STRICT_DECODER, parse_json

FORMAT = "armgame-scores"
#: 2 adds each entry's ruleset and config digest; 3 the table's ranked seed and order-of-entry counter, and
#: each entry's game digest, order of entry and whole-clock flag. Older tables are read (and rewritten as 3).
FORMAT_VERSION = 3
READS_FORMATS = (1, 2, 3)


@dataclass(frozen=True)
class Damage:
    reason: str
    recovered: int
    found: int

    def describe(self, path: Path) -> str:
        return f"{path} is damaged ({self.reason}); {plural(self.recovered, 'valid entry')} recovered"


@dataclass(frozen=True)
class TableHead:
    """The table's own fields: the seed it ranks and the next place in its order of entry.

    ``seed`` is None when the table's seed is not valid (``seed_problem`` says how): nothing chooses one for
    it, the file keeps what it holds (``kept_seed``, the seed's JSON as found; None: the table has none).
    A ``next_entry`` that is not valid is read as 1 (``counter_problem``): the next write sets it after the
    last entry, and says so.
    """

    seed: int | None = DEFAULT_SEED
    next_entry: int = 1
    seed_problem: str | None = None
    kept_seed: str | None = None
    counter_problem: str | None = None


def numbered(entries: list[ScoreEntry], head: TableHead, adding: int = 1) -> tuple[list[ScoreEntry], int, str | None]:
    """The entries with every place in the order of entry set, the next place, and a one-line note if a
    counter had to be repaired.

    Entries carried over from an older table get their places, in the order of their dates, once. The
    counter never goes back past a place in use (places are never reused), but it never passes
    ``COUNT_MAX`` either, where a place or ``next_entry`` would no longer read back: a planted
    ``next_entry`` that high is set after the last entry, and a planted ``entered`` that high renumbers
    the entries 1, 2, ... in their order. The ``adding`` entries of this write and the ``next_entry``
    after them must fit.
    """
    last = max([0, *(e.entered or 0 for e in entries)])
    start = max(head.next_entry, last + 1)
    old = sorted((e for e in entries if e.entered is None), key=entry_order)
    note = None
    if head.counter_problem is not None:
        note = f"the table's next_entry counter is not valid ({head.counter_problem}): set after its last entry"
    if start + len(old) + adding > COUNT_MAX:
        if last + 1 + len(old) + adding <= COUNT_MAX:
            note = (f"the table's next_entry counter was {head.next_entry:,}, at its limit ({COUNT_MAX:,}): set "
                    f"after its last entry")
            start = last + 1
        else:
            ordered = sorted(entries, key=lambda e: (e.entered is None, *entry_order(e)))
            note = (f"the table's order of entry had reached {last:,}, its limit ({COUNT_MAX:,}): its "
                    f"{plural(len(ordered), 'entry')} are renumbered 1 to {len(ordered)} in their order")
            return [replace(e, entered=i) for i, e in enumerate(ordered, 1)], len(ordered) + 1, note
    if not old:
        return entries, start, note
    places = {e.id: start + i for i, e in enumerate(old)}
    numbered = [e if e.entered is not None else replace(e, entered=places[e.id]) for e in entries]
    return numbered, start + len(old), note


def parse_table(data: bytes) -> tuple[list[ScoreEntry], Damage | None]:
    """Entries of a table file, and the damage if it is not a clean table.

    A clean table yields all its entries. Otherwise every object in the text that passes
    the entry schema is recovered, wherever it sits (truncated tails, broken brackets).
    """
    entries, damage, _ = parse_with_head(data)
    return entries, damage


def parse_with_head(data: bytes, backed: Callable[[ScoreEntry], bool] | None = None
           ) -> tuple[list[ScoreEntry], Damage | None, TableHead]:
    """``parse_table`` and the table's head (``TableHead``: a seed or counter that is not valid is said there,
    not damage; a damaged table's head is what can be found of it).

    Two entries with one id are damage, and one of them is kept: the one whose replay file ``backed``
    says is its own (``TableFile._replay_backs``), else the first. A copy planted above an honest entry
    under its id must not push the honest one out of the table at the next write."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("utf-8", errors="replace")
        return (*_salvage(text, "not UTF-8 text"), _salvaged_head(text))
    try:
        table = parse_json(text)
    except ValueError as exc:
        return (*_salvage(text, str(exc)), _salvaged_head(text))
    head = TableHead()
    try:
        if not isinstance(table, dict) or table.get("format") != FORMAT:
            raise ValueError(f"not an armgame score table (no \"format\": \"{FORMAT}\")")
        head = _head_of(table)
        check_keys("table", table, {"format", "format_version", "entries"}, frozenset({"seed", "next_entry"}))
        version = check_int("format_version", table["format_version"], 1, 10**6)
        if version not in READS_FORMATS:
            raise ValueError(f"table format {version} is not one this armgame reads "
                             f"({', '.join(map(str, READS_FORMATS))})")
        if not isinstance(table["entries"], list):
            raise ValueError("entries must be a list")
    except ValueError as exc:
        return (*_salvage(text, str(exc)), head)
    entries: list[ScoreEntry] = []
    seen: dict[str, int] = {}
    problem = None
    for i, item in enumerate(table["entries"]):
        try:
            entry = ScoreEntry.from_dict(item)
        except ValueError as exc:
            problem = problem or f"entry {i + 1}: {exc}"
            continue
        first = seen.get(entry.id)
        if first is not None:
            problem = problem or f"entry {i + 1}: id {entry.id} appears twice"
            if backed is not None and not backed(entries[first]) and backed(entry):
                entries[first] = entry
            continue
        seen[entry.id] = len(entries)
        entries.append(entry)
    n = len(table["entries"])
    return entries, (Damage(problem, len(entries), n) if problem else None), head


def _head_of(table: dict) -> TableHead:
    """The head of a table read as JSON. A seed that is not valid is kept as found, never replaced by the
    default: tables of formats 1 and 2 had no seed and rank the default one, a format 3 table without one
    has none (a table of a format this armgame does not read is damage, its seed the default). A
    ``next_entry`` that is not valid is read as 1 (the next write sets it after the last entry)."""
    counter, counter_problem = table.get("next_entry", 1), None
    try:
        counter = check_int("next_entry", counter, 1, COUNT_MAX)
    except ValueError as exc:
        counter, counter_problem = 1, str(exc)
    if "seed" not in table:
        if table.get("format_version") == FORMAT_VERSION:  # armgame writes one in every such table
            return TableHead(None, counter, "is missing", None, counter_problem)
        return TableHead(DEFAULT_SEED, counter, counter_problem=counter_problem)
    raw = table["seed"]
    try:
        return TableHead(check_int("seed", raw, 0, INT64_MAX), counter, counter_problem=counter_problem)
    except ValueError as exc:
        problem = str(exc)
    try:
        kept = json.dumps(raw, ensure_ascii=False, allow_nan=False)
    except (ValueError, RecursionError):
        kept = None
    return TableHead(None, counter, f"is not valid ({problem[:200]})", kept, counter_problem)


#: Where a damaged table's head shows its seed: before its entries, as armgame writes it.
_HEAD_SEED = re.compile(r'"seed"\s*:\s*(\d{1,19})\s*[,}]')
_HEAD_VERSION = re.compile(r'"format_version"\s*:\s*(\d{1,7})\s*[,}]')


def _salvaged_head(text: str) -> TableHead:
    """What can be found of a damaged table's head. A file that does not even say it is a score table has
    no seed to lose (a new table's head); one that does, but whose seed is past saving, has none."""
    end = text.find('"entries"')
    head = text[: 65536 if end < 0 else min(end, 65536)]
    if f'"{FORMAT}"' not in head:
        return TableHead()
    seed = _HEAD_SEED.search(head)
    if seed is not None and int(seed.group(1)) <= INT64_MAX:
        return TableHead(int(seed.group(1)))
    version = _HEAD_VERSION.search(head)
    if '"seed"' not in head and (version is None or int(version.group(1)) != FORMAT_VERSION):
        return TableHead()
    return TableHead(None, 1, "cannot be read (the file is damaged)", None)


#: A flat JSON object (an entry has no nested values), strings honoured. Possessive quantifiers
#: never backtrack, so the scan is linear in the file's size whatever it holds.
_FLAT_OBJECT = re.compile(r'\{(?:[^{}"\[\]]++|"(?:[^"\\]++|\\.)*+")*+\}')


def _salvage(text: str, reason: str) -> tuple[list[ScoreEntry], Damage]:
    entries: list[ScoreEntry] = []
    seen: set[str] = set()
    for match in _FLAT_OBJECT.finditer(text):
        try:
            entry = ScoreEntry.from_dict(STRICT_DECODER.decode(match.group()))
        except (ValueError, RecursionError):
            continue
        if entry.id not in seen:
            seen.add(entry.id)
            entries.append(entry)
    return entries, Damage(reason, len(entries), len(entries))


def table_bytes(entries: list[ScoreEntry], seed: int | None = DEFAULT_SEED, next_entry: int | None = None,
                kept_seed: str | None = None) -> bytes:
    """The table file: one entry a line, best first, so it reads (and diffs) as a list.

    Fields an entry lacks (it came from an older table) are left out rather than written as null. A
    ``seed`` of None writes ``kept_seed`` (the JSON of a seed that is not valid, kept as found), or no
    seed at all."""
    lines = [entry_line(e) for e in sorted(entries, key=sort_key)]
    if next_entry is None:
        next_entry = max([0, *(e.entered or 0 for e in entries)]) + 1
    head = json.dumps({"format": FORMAT, "format_version": FORMAT_VERSION})[:-1]
    if seed is not None:
        head += f', "seed": {seed}'
    elif kept_seed is not None:
        head += f', "seed": {kept_seed}'
    head += f', "next_entry": {next_entry}'
    return (head + ', "entries": [\n' + ",\n".join(lines) + "\n]}\n").encode("utf-8")


def entry_line(e: ScoreEntry) -> str:
    """An entry as one line of JSON: the table's lines and the journal's are the same."""
    return json.dumps({k: v for k, v in e.as_dict().items() if v is not None or k not in _OPTIONAL},
                      sort_keys=True, ensure_ascii=False, allow_nan=False)


def journal_entries(data: bytes) -> tuple[list[ScoreEntry], str | None, int]:
    """The journal's entries, the first problem with a line (None: none), and the lines found. The part after
    the last newline is a write cut off by a kill: never acknowledged, not read, no problem."""
    entries: list[ScoreEntry] = []
    problem = None
    lines = data.split(b"\n")[:-1]
    for i, line in enumerate(lines):
        try:
            entries.append(ScoreEntry.from_dict(parse_json(line)))
        except (ValueError, RecursionError) as exc:
            problem = problem or f"line {i + 1}: {str(exc)[:200]}"
    return entries, problem, len(lines)
