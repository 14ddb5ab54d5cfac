"""The layers never reach upward: physics <- game <- records <- lab <- ui <- commands.

Each layer's modules are imported in a fresh interpreter, and nothing above the layer may
have been imported with them. Records in particular knows no lab: a lab replay's task
section is read by the reader the lab registers, and every command that reads replays
registers it first, whatever was imported before. The game knows no records: what both read
files with (``armgame.files``) sits below every layer, with ``errors``, ``limits`` and ``words``, and so
does what a valid field of a file is (``armgame.valid``), which every layer's readers check with.

Within a package, no modules import each other in a circle: a piece two modules share lives
below both (``env.errors``, ``ui.palette``, ``commands.seed_argument``, ``game.batch.kernel_inputs``).
An import under ``if TYPE_CHECKING:`` counts like any other: it never runs, but it is knowledge of
the module it names, and a circle of knowledge is what the layers forbid (``game/batch``'s kernels
once named ``BatchGameSession`` so and read its private attributes).
"""

import ast
import functools
import json
import subprocess
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest

import armgame
from armgame.cli import main
from armgame.errors import UserError
from armgame.game.bots import Autopilot
from armgame.lab.bots import make_lab_bot
from armgame.lab.perturbations import Perturbation
from armgame.lab.protocol import Block, Protocol
from armgame.lab.record import LabTask
from armgame.lab.session import LabSession, lab_config
from armgame.records import replay as replay_module
from armgame.records.replay import Replay, now_iso

ABOVE_LAB = ("armgame.ui", "armgame.commands", "armgame.cli", "armgame.demos", "armgame.env", "armgame.bench",
             "armgame.classroom", "pygame")
#: What each layer must never import, anywhere in its files (inside functions too: a lazy import is a dependency).
LAYERS = {
    "armgame.physics": ("armgame.game", "armgame.lab", "armgame.records", *ABOVE_LAB),
    "armgame.game": ("armgame.records", "armgame.lab", *ABOVE_LAB),
    "armgame.records": ("armgame.lab", *ABOVE_LAB),
    "armgame.lab": ABOVE_LAB,
    # The live class: above records, lab and game, below the commands; pygame only through ui (class show).
    "armgame.classroom": tuple(name for name in ABOVE_LAB if name != "armgame.classroom"),
}
ROOT = Path(armgame.__file__).parent
#: The modules below every layer: each may import only the others.
BASE = ("armgame._native", "armgame.errors", "armgame.files", "armgame.limits", "armgame.valid", "armgame.words")


def imported_names(path: Path, module: str) -> Iterator[tuple[int, str]]:
    """(line, absolute module name) of every import in the file, relative ones resolved."""
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    for node in ast.walk(_parsed(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            yield from ((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = ".".join(package[:len(package) - node.level + 1]) if node.level else ""
            name = ".".join(p for p in (base, node.module or "") if p)
            # ``from . import x`` may name a module: check the names as modules too.
            yield from ((node.lineno, f"{name}.{alias.name}") for alias in node.names)


def reaches(name: str, tops: Sequence[str]) -> bool:
    return any(name == top or name.startswith(top + ".") for top in tops)


@pytest.mark.parametrize("layer", list(LAYERS))
def test_no_file_of_a_layer_imports_from_above_it(layer):
    files = sorted((ROOT / layer.split(".")[1]).rglob("*.py"))
    assert files
    found = []
    for path in files:
        module = ".".join(("armgame", *path.relative_to(ROOT).with_suffix("").parts))
        found += [f"{path.relative_to(ROOT)}:{line} imports {name}" for line, name in imported_names(path, module)
                  if reaches(name, LAYERS[layer])]
    assert found == []


def test_the_modules_below_every_layer_import_only_each_other():
    found = []
    for module in BASE:
        path = ROOT / f"{module.split('.')[1]}.py"
        found += [f"{path.name}:{line} imports {name}" for line, name in imported_names(path, module)
                  if name.startswith("armgame") and not reaches(name, BASE)]
    assert found == []


def test_what_valid_means_imports_nothing_of_armgame():
    """``armgame.valid`` is below every layer and beside the other base modules too: the standard library only, in
    its file and when it is imported alone (nothing else of armgame loaded with it)."""
    path = ROOT / "valid.py"
    assert [name for _, name in imported_names(path, "armgame.valid") if name.startswith("armgame")] == []
    code = "import json, sys\nimport armgame.valid\nprint(json.dumps(sorted(sys.modules)))\n"
    loaded = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                       check=True).stdout)
    assert [m for m in loaded if reaches(m, ("armgame",))] == ["armgame", "armgame.valid"]


# ----------------------------------------------------------------- no import circles within a package

def runtime_imports(path: Path, module: str, lazy: bool) -> Iterator[tuple[int, str, tuple[str, ...]]]:
    """(line, the module named after ``from`` or ``import``, the names imported from it) of every import
    at module level (those under ``if TYPE_CHECKING:`` included), and with ``lazy`` those inside
    functions too."""
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]

    def walk(node: ast.AST) -> Iterator[tuple[int, str, tuple[str, ...]]]:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)) and not lazy:
                continue
            if isinstance(child, ast.Import):
                yield from ((child.lineno, alias.name, ()) for alias in child.names)
            elif isinstance(child, ast.ImportFrom):
                base = ".".join(package[:len(package) - child.level + 1]) if child.level else ""
                yield child.lineno, ".".join(p for p in (base, child.module or "") if p), \
                    tuple(alias.name for alias in child.names)
            elif isinstance(child, (ast.stmt, ast.excepthandler, ast.match_case)):  # no expression holds an import
                yield from walk(child)

    yield from walk(_parsed(path.read_text(), str(path)))


@functools.cache
def _parsed(text: str, name: str) -> ast.Module:
    """A file's syntax tree, parsed once for both of the circle tests (keyed by its text: files change)."""
    return ast.parse(text, name)


def import_circles(folder: Path, package: str, lazy: bool) -> list[list[str]]:
    """The circles among the modules of one package (its ``__init__`` one of them): each as the import
    statements that make it. ``from P import x`` imports P itself and, where x is a module of P, x."""
    modules = {(package if f.name == "__init__.py" else f"{package}.{f.stem}"): f for f in folder.glob("*.py")}
    edges: dict[str, dict[str, int]] = {m: {} for m in modules}
    for module, path in modules.items():
        for line, name, names in runtime_imports(path, module, lazy):
            for target in (name, *(f"{name}.{n}" for n in names)):
                if target in modules and target != module:
                    edges[module].setdefault(target, line)
    circles, done = [], set()
    for start in sorted(modules):  # depth first from each module: a path back to one on it is a circle
        stack = [(start, iter(sorted(edges[start])))]
        on_path = [start]
        while stack:
            module, following = stack[-1]
            target = next(following, None)
            if target is None:
                stack.pop()
                on_path.pop()
                done.add(module)
            elif target in on_path:
                ring = on_path[on_path.index(target):]
                following_ring = ring[1:] + ring[:1]
                circles.append([f"{a} (line {edges[a][b]}) -> {b}" for a, b in zip(ring, following_ring, strict=True)])
            elif target not in done:
                stack.append((target, iter(sorted(edges[target]))))
                on_path.append(target)
    return circles


PACKAGES = sorted(".".join(("armgame", *p.parent.relative_to(ROOT).parts)) for p in ROOT.rglob("__init__.py"))


@pytest.mark.parametrize("lazy", [False, True], ids=["module-level", "with-lazy-imports"])
def test_no_modules_of_a_package_import_each_other_in_a_circle(lazy):
    found = {package: import_circles(ROOT.joinpath(*package.split(".")[1:]), package, lazy) for package in PACKAGES}
    assert "armgame.game.batch" in found and "armgame.commands" in found
    assert {package: circles for package, circles in found.items() if circles} == {}


def test_the_circle_check_sees_circles_typing_only_ones_too(tmp_path):
    """The check above can fail: a lazy import makes a circle (lazy imports counted), so does one under
    ``if TYPE_CHECKING:`` (the old ``game.batch`` kernels' ``BatchGameSession``), and so does ``from . import
    b`` back into a package whose ``__init__`` imports the module (the old ``game.batch.session``'s ``from .
    import compiled``)."""
    (tmp_path / "__init__.py").write_text("")
    (tmp_path / "a.py").write_text("from .b import f\nx = 1\n")
    (tmp_path / "b.py").write_text("def f():\n    from .c import y\n")
    (tmp_path / "c.py").write_text("from .a import x\ny = 2\n")
    assert import_circles(tmp_path, "p", lazy=False) == []
    assert import_circles(tmp_path, "p", lazy=True) == [["p.a (line 1) -> p.b", "p.b (line 2) -> p.c",
                                                         "p.c (line 1) -> p.a"]]
    (tmp_path / "b.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .c import y\n")
    assert import_circles(tmp_path, "p", lazy=False) == [["p.a (line 1) -> p.b", "p.b (line 3) -> p.c",
                                                          "p.c (line 1) -> p.a"]]
    (tmp_path / "__init__.py").write_text("from .a import x\n")
    (tmp_path / "b.py").write_text("from . import c\n")
    assert ["p (line 1) -> p.a", "p.a (line 1) -> p.b", "p.b (line 1) -> p"] in \
        import_circles(tmp_path, "p", lazy=False)


def test_the_static_check_sees_relative_and_lazy_imports(tmp_path):
    """The check above can fail: a lazy relative import of the lab from records is caught."""
    path = tmp_path / "replay.py"
    path.write_text("def f():\n    from ..lab.record import LabTask\n")
    names = [name for _, name in imported_names(path, "armgame.records.replay")]
    assert names == ["armgame.lab.record.LabTask"] and reaches(names[0], LAYERS["armgame.records"])


def test_importing_every_records_module_loads_no_lab_window_or_command():
    code = ("import importlib, json, pkgutil, sys\n"
            "import armgame.records as package\n"
            "for info in pkgutil.walk_packages(package.__path__, 'armgame.records.'):\n"
            "    importlib.import_module(info.name)\n"
            "print(json.dumps(sorted(sys.modules)))\n")
    loaded = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                       check=True).stdout)
    assert "armgame.records.scores" in loaded and "armgame.game.session" in loaded
    assert [m for m in loaded if reaches(m, LAYERS["armgame.records"])] == []


@pytest.fixture(scope="module")
def lab_replay(tmp_path_factory):
    """A short lab run's replay, alone in a folder."""
    kinds = (Perturbation(), Perturbation.make("curl", b=2.0), Perturbation())
    protocol = Protocol("short", tuple(Block(n, 1, k) for n, k in zip(("a", "b", "c"), kinds, strict=True)),
                        timeout=0.5)
    session = LabSession(lab_config(protocol, 3), protocol)
    Autopilot(session, make_lab_bot("model")).play()
    folder = tmp_path_factory.mktemp("lab") / "runs"
    folder.mkdir()
    path = folder / "run.json"
    Replay(session.config, tuple(session.timeline), session.result(), "bot", "model", "Ann", now_iso(),
           task=LabTask.of(session)).save(path)
    return path


@pytest.fixture
def lab_unregistered(monkeypatch):
    """As if the lab had never been imported: records reads no task section."""
    monkeypatch.setattr(replay_module, "_TASK_READERS", {})


def test_records_alone_reads_no_task_section(lab_replay, lab_unregistered):
    with pytest.raises(UserError, match=r"task\.kind 'centre-out': no kind of task section is registered"):
        Replay.load(lab_replay)


@pytest.mark.parametrize("argv, code, expected", [
    (["verify", "{file}"], 0, "matches"),
    (["verify", "{folder}"], 0, "1 replay"),
    (["replay", "{file}", "--headless"], 0, "as recorded"),
    (["analyze", "{file}", "--out", "{tmp}/trials.csv"], 0, "trials.csv"),
    (["analyze", "--class", "{folder}", "--out", "{tmp}", "--no-figures"], 0, "class_curve.csv"),
    (["scores", "--scores", "{tmp}/table", "--add", "{file}"], 2, "only a whole game enters the table"),
])
def test_every_command_reads_a_lab_replay_whatever_was_imported_before(lab_replay, lab_unregistered, tmp_path,
                                                                       capsys, argv, code, expected):
    names = {"file": lab_replay, "folder": lab_replay.parent, "tmp": tmp_path}
    assert main([a.format(**names) for a in argv]) == code
    said = capsys.readouterr()
    assert expected in said.out + said.err and "task.kind" not in said.err
