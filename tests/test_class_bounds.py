"""The class's bounds (``armgame.classroom.bounds``): each with its reason and a reader, none defined elsewhere, the
couplings between them held, and docs/development.md's table the module's own.

``python tests/test_class_bounds.py`` writes the table into docs/development.md after a bound changes.
"""

from __future__ import annotations

import ast
import functools
import sys
from pathlib import Path

from armgame import limits
from armgame.classroom import bounds

ROOT = Path(__file__).resolve().parents[1]
CLASSROOM = ROOT / "armgame" / "classroom"
SOURCE = CLASSROOM / "bounds.py"
DOC = ROOT / "docs" / "development.md"
BEGIN = "<!-- the class's bounds: written by python tests/test_class_bounds.py -->"
END = "<!-- end of the class's bounds -->"
#: Numbers at a class module's top level that are not bounds on what the class may cost, each with why.
NOT_BOUNDS = {
    ("app.py", "OTHER_CLASS"): "an HTTP status",
    ("client.py", "DEFAULT_PORT"): "where the class listens unless told",
    ("memberships.py", "FORMAT"): "a file format's version",
    ("memberships.py", "_LATEST"): "a time far past any clock's, to check a field against",
    ("roster.py", "FORMAT_VERSION"): "a file format's version",
    ("wire.py", "CODE_LENGTH"): "the join code's form, a rule both sides check (wire.py)",
}
#: A round's rules (its clock, its grace, its winners) are the round's, not what the class may cost.
ROUND_RULES = "rounds.py"


def defined() -> list[tuple[str, int | float, str, str]]:
    """Each bound in the module's order: its name, its value, its section, its reason (its ``#:`` lines)."""
    lines = SOURCE.read_text(encoding="utf-8").splitlines()
    out, section = [], ""
    for node in ast.parse("\n".join(lines)).body:
        if not isinstance(node, ast.Assign):
            continue
        name = node.targets[0].id  # type: ignore[attr-defined]
        above, at = [], node.lineno - 2
        while at >= 0 and lines[at].startswith("#:"):
            above.insert(0, lines[at][2:].strip())
            at -= 1
        for line in reversed(lines[:node.lineno - 1]):
            if line.startswith("# ---"):
                section = line.strip("# -")
                break
        out.append((name, getattr(bounds, name), section, " ".join(above)))
    return out


@functools.cache
def _imported_from_bounds() -> dict[str, frozenset[str]]:
    """Each class module's names imported from bounds.py (every module parsed once: 50 bounds asked of 20 files)."""
    out = {}
    for path in sorted(CLASSROOM.glob("*.py")):
        out[path.name] = frozenset(a.name for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
                                   if isinstance(node, ast.ImportFrom) and node.module == "bounds" and node.level == 1
                                   for a in node.names)
    return out


def readers(name: str) -> list[str]:
    """The class's modules that import ``name`` from bounds.py."""
    return [module for module, names in _imported_from_bounds().items() if name in names]


def shown(value: int | float, why: str) -> str:
    """A bound's value in the table, in its unit (its reason says which: "Seconds ...", "Bytes ...")."""
    if why.startswith("Seconds"):
        return f"{value:,g} s"
    if why.startswith("Bytes") and value % 1024 == 0:
        kib = value // 1024
        return f"{kib // 1024} MiB" if kib % 1024 == 0 else f"{kib} KiB"
    return f"{value:,}" if isinstance(value, int) else f"{value:g}"


def table() -> str:
    """The docs' table of the bounds, from the module."""
    rows = [BEGIN, "", "| bound | value | read by | why |", "|---|---|---|---|"]
    for name, value, _, why in defined():
        rows.append(f"| `{name}` | {shown(value, why)} | {', '.join(readers(name))} | {why.replace('``', '`')} |")
    return "\n".join([*rows, "", END])


def test_every_bound_has_its_reason_and_a_reader():
    names = [name for name, *_ in defined()]
    assert names, "no bounds found"
    assert len(names) == len(set(names))
    for name, value, section, why in defined():
        assert isinstance(value, int | float), name
        assert section and len(why) > 20, f"{name}: no reason given in a #: comment above it"
        assert readers(name), f"{name}: no module of the class imports it"
        assert not name.endswith("_SECONDS") or why.startswith("Seconds"), f"{name}: say its unit first"
        assert not name.endswith("_BYTES") or why.startswith("Bytes"), f"{name}: say its unit first"
    assert set(names) == {n for n in vars(bounds) if n.isupper()}, "a name in bounds.py the table does not show"


def test_no_module_of_the_class_keeps_a_bound_of_its_own():
    """A number at a class module's top level is a bound, and belongs in bounds.py (or in NOT_BOUNDS, saying why)."""
    found = []
    for path in sorted(CLASSROOM.glob("*.py")):
        if path in (SOURCE,) or path.name == ROUND_RULES:
            continue
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            target = node.targets[0] if isinstance(node, ast.Assign) else getattr(node, "target", None)
            value = getattr(node, "value", None)
            if isinstance(target, ast.Name) and target.id.isupper() and value is not None and \
                    all(isinstance(n, ast.Constant | ast.BinOp | ast.operator | ast.UnaryOp)
                        and not isinstance(getattr(n, "value", 0), str) for n in ast.walk(value)) and \
                    (path.name, target.id) not in NOT_BOUNDS:
                found.append(f"{path.name}: {target.id}")
    assert not found, f"bounds outside bounds.py: {found}"


def test_the_bounds_hold_together():
    b = bounds
    # A slow body is answered 408 by the app before the connection's own deadline closes it with no answer: the
    # deadline counts from the headers, through the wait for an upload's place and the body's own deadline.
    assert b.UPLOAD_WAIT + b.BODY_SECONDS < b.REQUEST_SECONDS
    # The largest hand-in arrives within the body's deadline at half a megabyte a second (slow school Wi-Fi).
    assert b.MAX_HANDIN_BYTES / 500_000 <= b.BODY_SECONDS
    # Every large body being read fits the queue behind them at once, and the largest hand-in fits it alone.
    assert b.QUEUE_BYTES >= b.UPLOADS * b.MAX_HANDIN_BYTES
    # The small uploads' places hold 16 MiB together, and a small upload is smaller than the largest.
    assert b.SMALL_UPLOADS * b.SMALL_UPLOAD_BYTES == 16 * 1024 * 1024
    assert b.SMALL_UPLOAD_BYTES < b.MAX_HANDIN_BYTES
    # A hand-in the class takes is a replay any reader takes, and costs no more to check than any replay may.
    assert b.MAX_HANDIN_BYTES <= limits.MAX_REPLAY_BYTES
    assert b.MAX_HANDIN_WORK <= limits.MAX_VERIFY_WORK
    # A machine with its live pages open and its hand-ins uploading still has connections for a join and a page.
    assert b.PER_ADDRESS >= b.STREAMS_PER_ADDRESS + b.UPLOADS_PER_ADDRESS + 2
    assert b.STREAMS_PER_ADDRESS <= b.MAX_STREAMS and b.UPLOADS_PER_ADDRESS <= b.UPLOADS
    # uvicorn's limit keeps a reserve for the teacher's machine past the other machines' and those on probation.
    assert b.CONCURRENCY - b.CONNECTIONS >= b.PROBATION + 64
    # One read of asyncio's (256 KiB) is held back whole before a connection is closed for holding too much.
    assert b.HELD_BYTES >= 256 * 1024
    # A batch is never larger than the queue it is taken from; a player has a place in it.
    assert b.BATCH <= b.HANDIN_QUEUE and b.TOKEN_SHARE >= 1
    # The waits grow from the first to the longest; the class takes at least what one machine may join.
    assert b.GUESS_WAIT <= b.MAX_GUESS_WAIT and b.JOINS_PER_MINUTE <= b.CLASS_JOINS_PER_MINUTE
    # The client asks a busy class again for longer than the class makes a hand-in wait for its place.
    assert b.BUSY_PATIENCE > b.UPLOAD_WAIT


def test_the_docs_table_is_the_modules():
    text = DOC.read_text(encoding="utf-8")
    assert BEGIN in text and END in text, "docs/development.md has no table of the class's bounds"
    current = text[text.index(BEGIN):text.index(END) + len(END)]
    assert current == table(), "docs/development.md's table of the class's bounds is stale: " \
                               "run python tests/test_class_bounds.py"


def test_the_bounds_import_nothing():
    """The student's client imports bounds.py: it must load none of the server, nor anything else."""
    tree = ast.parse(SOURCE.read_text(encoding="utf-8"))
    imports = [n for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom)]
    assert [ast.unparse(n) for n in imports] == ["from __future__ import annotations"]


if __name__ == "__main__":
    text = DOC.read_text(encoding="utf-8")
    if BEGIN not in text or END not in text:
        sys.exit(f"{DOC}: no {BEGIN!r} ... {END!r} to write the table between")
    DOC.write_text(text[:text.index(BEGIN)] + table() + text[text.index(END) + len(END):], encoding="utf-8")
    print(f"wrote the class's bounds into {DOC}")
