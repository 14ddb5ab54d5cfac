"""The README and docs/ say what is true: every shell example runs as printed or parses, links resolve.

Each fenced block's info string says what it needs (docs/development.md, "The docs are tested"):
``sh run`` blocks run in order, one temporary folder per file: a line that is one plain ``armgame``
command through ``armgame.cli.main`` in this process (what the installed console script calls, without
a new Python per line), every other line through bash, a block with shell state across its lines
(a loop over lines, a variable, ``cd``) through one bash; ``text file=NAME`` / ``toml file=NAME``
blocks are written there first; ``python run`` blocks run with this Python; ``sh window``, ``sh setup``
and ``sh long`` blocks are not run, but every ``armgame`` command in them must parse with the real
parser.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
SHELL_TAGS = {"run", "window", "setup", "long"}
FENCE = re.compile(r"^```([^\n`]*)\n(.*?)^```\s*$", re.S | re.M)


@dataclass(frozen=True)
class Block:
    path: Path
    line: int
    language: str
    tags: tuple[str, ...]
    text: str

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"

    def tag(self, name: str) -> str | None:
        return next((t.split("=", 1)[1] for t in self.tags if t.startswith(f"{name}=")), None)


def blocks(path: Path) -> list[Block]:
    text = path.read_text(encoding="utf-8")
    found = []
    for match in FENCE.finditer(text):
        info = match.group(1).split()
        line = text.count("\n", 0, match.start()) + 1
        found.append(Block(path, line, info[0] if info else "", tuple(info[1:]), match.group(2)))
    return found


def commands(block: Block) -> list[str]:
    """The block's command lines: comments dropped, continuation lines joined."""
    lines, pending = [], ""
    for raw in block.text.splitlines():
        line = pending + raw
        if line.rstrip().endswith("\\"):
            pending = line.rstrip()[:-1] + " "
            continue
        pending = ""
        if line.strip() and not line.lstrip().startswith("#"):
            lines.append(line)
    return lines


def armgame_argvs(block: Block) -> list[list[str]]:
    """Every ``armgame ...`` invocation in a shell block, split as the shell would (loops and && included)."""
    argvs = []
    for line in commands(block):
        for part in re.split(r"&&|;|\|\||\|", line):
            words = shlex.split(part, comments=True)
            while words and words[0] in ("do", "then", "time"):
                words = words[1:]
            if words and words[0] == "armgame":
                argvs.append(words[1:])
            elif words[:3] == ["python", "-m", "armgame"]:
                argvs.append(words[3:])
    return argvs


ALL_BLOCKS = [b for path in DOCS for b in blocks(path)]


def test_the_docs_exist_and_the_readme_is_short():
    names = {p.name for p in DOCS}
    assert {"teaching.md", "game.md", "scores.md", "lab.md", "demos.md", "programs.md", "performance.md",
            "development.md"} <= names
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 300


@pytest.mark.parametrize("block", [b for b in ALL_BLOCKS if b.language in ("sh", "console", "bash", "shell", "")],
                         ids=lambda b: b.where)
def test_every_shell_block_says_what_it_needs(block):
    assert block.language == "sh", f"{block.where}: a command block is ```sh with a tag ({', '.join(SHELL_TAGS)})"
    assert len(block.tags) == 1 and block.tags[0] in SHELL_TAGS, \
        f"{block.where}: tag the block with one of {sorted(SHELL_TAGS)}, got {block.tags}"


@pytest.mark.parametrize("block", [b for b in ALL_BLOCKS if b.language == "sh" and set(b.tags) & SHELL_TAGS],
                         ids=lambda b: b.where)
def test_every_documented_command_line_parses(block, capsys):
    """A renamed command or option fails here, in the docs of windows and installs too."""
    from armgame.cli import build_parser

    parser = build_parser()
    for argv in armgame_argvs(block):
        try:
            args, extra = parser.parse_known_args(argv)
        except SystemExit as exc:  # argparse's one-line error, or --help/--version
            pytest.fail(f"{block.where}: 'armgame {shlex.join(argv)}' does not parse (exit {exc.code}): "
                        f"{capsys.readouterr().err.strip()}")
        assert not extra, f"{block.where}: 'armgame {shlex.join(argv)}': unrecognized {extra}"
        assert getattr(args, "run", None), f"{block.where}: 'armgame {shlex.join(argv)}' names no command"


@pytest.mark.parametrize("block", [b for b in ALL_BLOCKS if b.language == "toml" and b.tag("file")],
                         ids=lambda b: b.where)
def test_every_toml_example_is_valid(block):
    data = tomllib.loads(block.text)
    if "blocks" in data:  # a lab protocol: the lab's own reader, every key checked
        from armgame.lab.protocol_file import protocol_from_dict

        protocol_from_dict(data)
    else:  # a settings file
        from armgame.ui.settings import from_toml

        from_toml(block.text.encode(), block.where)


def _isolated_env(home: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ARMGAME_", "XDG_"))}
    bin_dir = str(Path(sys.executable).parent)
    env.update({
        "HOME": str(home), "USERPROFILE": str(home),
        "XDG_CONFIG_HOME": str(home / ".config"), "XDG_DATA_HOME": str(home / ".local" / "share"),
        "XDG_CACHE_HOME": str(home / ".cache"),
        "ARMGAME_SCORES": str(home / "scores"), "ARMGAME_CACHE": str(home / ".cache" / "armgame"),
        "PATH": bin_dir + os.pathsep + env.get("PATH", ""),
        "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy", "MPLBACKEND": "Agg",
    })
    (home / "scores").mkdir(parents=True)
    return env


RUNNABLE = [p for p in DOCS if any(b.tags[:1] == ("run",) for b in blocks(p))]


#: A line with any of these runs through bash: pipes, lists, redirections, expansions, globs, loops.
SHELL_SYNTAX = re.compile(r"[|&;<>()$`*?\[\]{}~=!]|^\s*(for|if|while|time|cd|export)\b")


def _plain_armgame_line(line: str) -> list[str] | None:
    """The argv of a line that is one plain ``armgame`` command (words and quotes, no shell syntax
    outside a trailing comment), else None: that line runs in bash."""
    try:
        words = shlex.split(line, comments=True)
    except ValueError:
        return None
    if not words or words[0] != "armgame":
        return None
    code = shlex.join(words)
    return words[1:] if not SHELL_SYNTAX.search(code) else None


#: A block with any of these keeps one shell for all its lines: a compound command over several
#: lines, a here-document, a variable, a function or a change of folder that later lines rely on.
ONE_SHELL = re.compile(r"^\s*(for|while|until|if|case|select)\b(?!.*\b(done|fi|esac)\b)|<<|^\s*\w+=|"
                       r"^\s*(cd|export|source|\.|function|alias|set|pushd|popd)\b|[{(]\s*$")


def _run_in_process(argv: list[str], where: str, work: Path, env: dict[str, str], monkeypatch, capfd) -> None:
    """``armgame ARGV`` as ``armgame.cli.main`` runs it for the console script, in this process: the
    same parser, commands and exit code, without starting a Python (and numpy) for every line."""
    from armgame.cli import main

    with monkeypatch.context() as patch:
        for name in [k for k in os.environ if k not in env]:
            patch.delenv(name)
        for name, value in env.items():
            patch.setenv(name, value)
        patch.chdir(work)
        patch.setattr(sys, "argv", ["armgame", *argv])
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse's errors and --help
            code = exc.code if isinstance(exc.code, int) else 1
    out, err = capfd.readouterr()
    assert not code, f"{where}: 'armgame {shlex.join(argv)}' failed (exit {code}):\n{out[-2000:]}\n{err[-2000:]}"
    assert "Traceback" not in err, f"{where}:\n{err[-2000:]}"


def _run_in_bash(script: str, where: str, work: Path, env: dict[str, str], python: bool = False) -> None:
    argv = [sys.executable, "-c", script] if python else ["bash", "-e", "-o", "pipefail", "-c", script]
    proc = subprocess.run(argv, cwd=work, env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, (
        f"{where} failed (exit {proc.returncode}):\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    assert "Traceback" not in proc.stderr, f"{where}:\n{proc.stderr[-2000:]}"


#: The guides whose examples serve a class and train and evaluate programs end to end (4 and 3 s): CI's slow tier
#: runs them after the suite, so the README's command keeps its minute.
SLOW_GUIDES = {"teaching.md", "programs.md"}


@pytest.mark.skipif(shutil.which("bash") is None, reason="the examples are POSIX shell")
@pytest.mark.parametrize("path", [pytest.param(p, marks=pytest.mark.slow) if p.name in SLOW_GUIDES else p
                                  for p in RUNNABLE], ids=lambda p: p.name)
def test_runnable_examples_run_as_printed(path, tmp_path, monkeypatch, capfd):
    """A file's ``run`` blocks, in order, in one folder, as a user would type them: each line that is
    one plain ``armgame`` command through ``armgame.cli.main`` (what the console script calls), in
    this process; every other line (pipes, loops, mkdir, head) through bash as printed."""
    if shutil.which("armgame", path=str(Path(sys.executable).parent)) is None:
        pytest.skip("armgame is not installed beside this Python (pip install -e '.[test]')")
    home = tmp_path / "home"
    work = tmp_path / "work"
    work.mkdir()
    env = _isolated_env(home)
    checkout_table = sorted((ROOT / "scores").iterdir())
    for block in blocks(path):
        if block.tag("file"):
            (work / block.tag("file")).write_text(block.text, encoding="utf-8")
            continue
        if block.tags[:1] != ("run",):
            continue
        if block.language == "python":
            _run_in_bash(block.text, block.where, work, env, python=True)
            continue
        assert block.language == "sh", block.where
        lines = commands(block)
        if any(ONE_SHELL.search(line) for line in lines):
            _run_in_bash(block.text, block.where, work, env)
            continue
        for line in lines:
            argv = _plain_armgame_line(line)
            if argv is None:
                _run_in_bash(line, block.where, work, env)
            else:
                _run_in_process(argv, block.where, work, env, monkeypatch, capfd)
    assert sorted((ROOT / "scores").iterdir()) == checkout_table  # examples never touch the checkout's table


def test_plain_armgame_lines_are_told_from_shell_syntax():
    assert _plain_armgame_line('armgame lab a.toml --name "Bot 1"   # a comment') == ["lab", "a.toml", "--name",
                                                                                     "Bot 1"]
    assert _plain_armgame_line("armgame simulate --initial=-60,0") is None  # '=' and the rest: bash decides
    for line in ("armgame play --json | head -1", "armgame verify a && armgame verify b", "armgame verify *.json",
                 "armgame scores > out.txt", "mkdir x", "for f in a; do armgame verify $f; done",
                 "time armgame play --headless", "armgame play --name ~me"):
        assert _plain_armgame_line(line) is None, line
    for line in ("for f in a b; do", "if true; then", "X=1", "cd folder", "cat <<EOF", "run() {"):
        assert ONE_SHELL.search(line), line
    for line in ("for f in a/*.json; do armgame verify \"$f\"; done", "armgame play --headless", "mkdir -p a b"):
        assert not ONE_SHELL.search(line), line


def test_an_armgame_line_that_fails_fails_the_example(tmp_path, monkeypatch, capfd):
    env = _isolated_env(tmp_path / "home")
    with pytest.raises(AssertionError, match="exit 2"):
        _run_in_process(["verify", "missing.json"], "here", tmp_path, env, monkeypatch, capfd)
    with pytest.raises(AssertionError, match="exit 2"):
        _run_in_process(["play", "--no-such-option"], "here", tmp_path, env, monkeypatch, capfd)
    _run_in_process(["--version"], "here", tmp_path, env, monkeypatch, capfd)


LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def _anchors(path: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces to hyphens."""
    anchors = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            title = line.lstrip("#").strip().lower()
            anchors.add(re.sub(r"[^\w\- ]", "", title).replace(" ", "-"))
    return anchors


@pytest.mark.parametrize("path", DOCS, ids=lambda p: p.name)
def test_every_relative_link_and_anchor_resolves(path):
    text = FENCE.sub("", path.read_text(encoding="utf-8"))
    for target in LINK.findall(text):
        if re.match(r"[a-z]+://", target) or target.startswith("mailto:"):
            continue
        file, _, anchor = target.partition("#")
        linked = (path.parent / file).resolve() if file else path
        assert linked.exists(), f"{path.name}: link to {target} names no file"
        if anchor and linked.suffix == ".md":
            assert anchor in _anchors(linked), f"{path.name}: link to {target}: no such heading"


@pytest.mark.slow  # every picture drawn at full size in a subprocess (about 2.5 s): CI, as the class's script
def test_the_screenshot_script_draws_every_picture(tmp_path):
    """docs/make_screenshots.py cannot rot: it runs here (dummy video driver) into a temporary folder."""
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    proc = subprocess.run([sys.executable, str(ROOT / "docs" / "make_screenshots.py"), "--out", str(tmp_path)],
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    pictures = sorted(p.name for p in tmp_path.iterdir())
    # The live class's pages are drawn by a browser (docs/make_class_screenshots.py, run by test_class_page), and
    # PPO's curves by benchmarks/reference_scores.py figure (test_env_protocol redraws it from the committed runs).
    drawn_elsewhere = {"ppo_curves.png"}
    assert pictures == sorted(p.name for p in (ROOT / "docs" / "img").glob("*.png")
                              if not p.name.startswith("class_") and p.name not in drawn_elsewhere)
    for name in pictures:
        data = (tmp_path / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) < 200_000
    referenced = set(re.findall(r"docs/img/([\w.-]+\.png)", (ROOT / "README.md").read_text(encoding="utf-8")))
    assert referenced <= set(pictures)


def test_ci_installs_and_tests_as_the_readme_says():
    """The README's two set-up commands are what CI runs: the install with the test extra, then pytest."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    setup = next(b for b in blocks(ROOT / "README.md") if b.tags == ("setup",))
    install = re.search(r"pip install (-e '\.\[test\]')", setup.text)
    assert install and "python -m pytest" in setup.text and "Quick start" in readme
    ci = [line.strip() for line in (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()]
    assert any(line.endswith(f"pip install --quiet {install.group(1)}") for line in ci)
    assert "python -m pytest" in ci  # exactly the README's test command, its options in pyproject.toml
    assert any(re.fullmatch(r'"\$python" -m venv "\.venv-\$version"', line) for line in ci)  # fresh, per Python


def test_the_test_time_the_readme_states_is_the_committed_runs():
    """The README's and development.md's test times are benchmarks/suite_time.py's committed run, idle and
    beside busy programs (issue 51: a newcomer held "about a minute" to a loaded laptop)."""
    import json

    root = ROOT
    run = json.loads((root / "benchmarks" / "results" / "suite_time.json").read_text(encoding="utf-8"))
    walls = {r["busy"]: round(r["wall_s"]) for r in run["runs"]}
    assert sorted(walls) == [0, 2, 4]
    readme = " ".join((root / "README.md").read_text(encoding="utf-8").split())
    assert (f"tests took {walls[0]} s on two idle cores, {walls[2]} s beside two busy programs and {walls[4]} s "
            f"beside four") in readme
    development = (root / "docs" / "development.md").read_text(encoding="utf-8")
    for r in run["runs"]:
        beside = "nothing (idle)" if r["busy"] == 0 else f"{r['busy']} busy programs"
        counted = f"{r['counted']['passed']:,} passed, {r['counted']['skipped']} skipped"
        row = f"| {beside} | {round(r['wall_s'])} s | {r['load_before']:.1f} | {counted} |"
        assert row in development, row
    assert f"On the {run['machine']['processor']}, {run['machine']['cores']} cores, Python {run['machine']['python']}" \
        in " ".join(development.split())
