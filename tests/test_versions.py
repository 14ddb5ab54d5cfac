"""One version everywhere: the package's, the envs' version histories, the docs' and CITATION.cff's.

A paper names the armgame it ran and the env ids it used; both must mean one thing. The package's
``__version__`` is the one source (pyproject reads it); every "armgame X.Y" the code and docs name is
no newer than it; each env's "Version History" puts its own version first and names the armgame
version in which each env version is new; and the citation file cites the version installed.
"""

from __future__ import annotations

import importlib
import inspect
import json
import re
import tomllib
from pathlib import Path

import gymnasium as gym
import pytest

import armgame
import armgame.env  # registers the ids

ROOT = Path(__file__).resolve().parent.parent
VERSION = tuple(int(p) for p in armgame.__version__.split("."))
NAMED = re.compile(r"\barmgame[ =]+v?(\d+(?:\.\d+){1,2})\b")
#: A history's bullet: "* vN: what changed (armgame X.Y)." on one or more lines.
BULLET = re.compile(r"^\* v(\d+): (.*?)\(armgame (\d+)\.(\d+)\)\.?$", re.DOTALL)


def version_tuple(text: str) -> tuple[int, ...]:
    return tuple(int(p) for p in text.split("."))


def test_the_version_has_one_source():
    assert re.fullmatch(r"\d+\.\d+\.\d+", armgame.__version__)
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert project["project"]["dynamic"] == ["version"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "armgame.__version__"}


def named_versions() -> list[tuple[str, str]]:
    files = [*sorted((ROOT / "armgame").rglob("*.py")), *sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md",
             *sorted((ROOT / "examples").glob("*.py")), *sorted((ROOT / "benchmarks").glob("*.py"))]
    return [(f"{path.relative_to(ROOT)}", m.group(1)) for path in files for m in NAMED.finditer(path.read_text())]


def test_no_file_names_an_armgame_newer_than_the_package():
    named = named_versions()
    assert len(named) >= 5  # the envs' histories are read (a pattern that matched nothing would pass)
    newer = [(f, v) for f, v in named if version_tuple(v) > VERSION[:len(version_tuple(v))]]
    assert not newer, f"armgame is {armgame.__version__}, but these name a newer one: {newer}"


def history(env_id: str) -> list[tuple[int, tuple[int, int]]]:
    """An id's env class's "Version History": (env version, armgame (major, minor)) newest first."""
    entry = gym.spec(env_id).entry_point
    if isinstance(entry, str):
        module, name = entry.split(":")
        entry = getattr(importlib.import_module(module), name)
    doc = inspect.getdoc(entry) or ""
    assert "## Version History" in doc, f"{env_id}: {entry.__name__} has no Version History"
    section = doc.split("## Version History", 1)[1].split("\n## ", 1)[0].strip()
    bullets = re.split(r"\n(?=\* )", section)
    out = []
    for bullet in bullets:
        match = BULLET.match(" ".join(bullet.split()))
        assert match, f"{env_id}: a history bullet must read '* vN: ... (armgame X.Y).', got {bullet!r}"
        out.append((int(match.group(1)), (int(match.group(3)), int(match.group(4)))))
    return out


def armgame_ids() -> list[str]:
    return sorted(i for i in gym.registry if i.startswith("armgame/"))


@pytest.mark.parametrize("env_id", armgame_ids())
def test_each_env_history_starts_at_its_own_version_and_runs_back_in_order(env_id):
    entries = history(env_id)
    assert entries[0][0] == gym.spec(env_id).version, f"{env_id}: its history's first bullet is v{entries[0][0]}"
    env_versions = [v for v, _ in entries]
    assert env_versions == sorted(env_versions, reverse=True) and len(set(env_versions)) == len(env_versions)
    named = [a for _, a in entries]
    assert named == sorted(named, reverse=True), f"{env_id}: a newer env version names an older armgame"
    assert named[0] <= VERSION[:2]


def test_the_newest_env_version_names_no_newer_armgame():
    # The v1 envs are what 0.2 brought; 0.3 changed no env (its own sine moved states by round-off and no
    # game's result: docs/performance.md, "The arm's own sine"), so the newest may be older than the package.
    newest = max(history(i)[0][1] for i in armgame_ids())
    assert (0, 2) <= newest <= VERSION[:2], \
        f"the newest env version says armgame {newest}, the package is {armgame.__version__}"


# ------------------------------------------------------------------ CITATION.cff
PLAIN = re.compile(r"[A-Za-z][A-Za-z0-9.-]*|\d+\.\d+\.\d+")  # words YAML reads as strings, not numbers


def scalar(text: str) -> str:
    """A double-quoted string (JSON's escapes are a subset of YAML's) or a plain word."""
    if text.startswith('"'):
        return json.loads(text)
    assert PLAIN.fullmatch(text), f"quote {text!r}: YAML could read it as something other than a string"
    return text


def read_flat_cff(text: str) -> dict:
    """The subset of YAML CITATION.cff is kept to: ``key: scalar``, ``key:`` then ``  - scalar`` items or
    ``  - key: scalar`` mappings (further keys at 4 spaces). Any other line fails."""
    data: dict = {}
    key = None
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        if m := re.fullmatch(r"([a-z][a-z-]*):(?: (.+))?", line):
            key = m.group(1)
            assert key not in data, f"line {number}: {key} twice"
            data[key] = scalar(m.group(2)) if m.group(2) else []
        elif m := re.fullmatch(r"  - (?:([a-z][a-z-]*): )?(.+)", line):
            assert key is not None and isinstance(data[key], list), f"line {number}: an item outside a list"
            data[key].append({m.group(1): scalar(m.group(2))} if m.group(1) else scalar(m.group(2)))
        elif m := re.fullmatch(r"    ([a-z][a-z-]*): (.+)", line):
            assert key is not None and data[key] and isinstance(data[key][-1], dict), f"line {number}"
            data[key][-1][m.group(1)] = scalar(m.group(2))
        else:
            raise AssertionError(f"CITATION.cff line {number} is outside the flat subset: {line!r}")
    return data


def test_the_citation_file_is_cff_1_2_and_cites_this_version():
    text = (ROOT / "CITATION.cff").read_text()
    cff = read_flat_cff(text)
    # CFF 1.2.0's required keys, and the types its schema asks of the ones used here.
    assert cff["cff-version"] == "1.2.0"
    assert {"cff-version", "message", "title", "authors"} <= set(cff)
    assert all(isinstance(cff[k], str) and cff[k] for k in ("message", "title", "abstract"))
    assert cff["authors"] and all(isinstance(a, dict) and (a.get("name") or a.get("family-names"))
                                  for a in cff["authors"])
    assert cff["type"] in ("software", "dataset")
    assert cff["version"] == armgame.__version__
    assert cff["license"] == tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"]
    assert all(isinstance(k, str) for k in cff["keywords"])
    try:
        import yaml
    except ImportError:
        return  # the flat reader above is the check; where PyYAML is installed, it must agree
    assert yaml.safe_load(text) == cff


def test_the_flat_reader_refuses_what_it_does_not_read():
    for bad in ("version: 0.2\n", "authors:\n  - name: [a, b]\n", "title: 'single'\n", "a:\n   - x\n",
                "title: x\ntitle: y\n"):
        with pytest.raises(AssertionError):
            read_flat_cff(bad)
    assert read_flat_cff('authors:\n  - name: "A"\n    email: "a@b"\nlicense: MIT\n') == {
        "authors": [{"name": "A", "email": "a@b"}], "license": "MIT"}


def test_the_docs_say_how_to_cite():
    for doc in ("README.md", "docs/programs.md"):
        assert "CITATION.cff" in (ROOT / doc).read_text(), doc
