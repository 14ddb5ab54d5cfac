"""The class's guard (armgame/classroom/guard.py) subclasses uvicorn's httptools protocol, whose internals are not
uvicorn's public API: pyproject.toml pins uvicorn to the versions it is tested on, and this says, by name, what
changed when a uvicorn the guard was not written for takes its place.

What the guard relies on is read from guard.py itself (its methods and the ``self.x`` it reads), so a rule added
there is checked here without a word changed.
"""

from __future__ import annotations

import ast
import asyncio
import inspect
import re
import textwrap
from importlib.metadata import version
from pathlib import Path

import pytest
import uvicorn
from packaging.requirements import Requirement
from packaging.version import Version
from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol, RequestResponseCycle
from uvicorn.server import ServerState

from armgame.classroom import guard as class_guard
from armgame.classroom.guard import Guard, guarded_protocol

ROOT = Path(__file__).resolve().parents[1]
#: The uvicorn.Config options the class's server passes (``serve.open_class``).
CONFIG_OPTIONS = ("http", "limit_concurrency", "timeout_keep_alive", "timeout_graceful_shutdown", "proxy_headers",
                  "lifespan", "access_log", "log_level")


def uvicorn_requirement() -> Requirement:
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    found = [Requirement(m) for m in re.findall(r'"(uvicorn[^"]*)"', text)]
    assert len(found) == 1, f"pyproject.toml should name uvicorn once, found {found}"
    return found[0]


def test_uvicorn_is_pinned_to_the_versions_the_guard_is_tested_on():
    spec = uvicorn_requirement().specifier
    uppers = [s for s in spec if s.operator in ("<", "<=", "~=", "==")]
    assert uppers, f"pyproject.toml's uvicorn{spec} has no upper bound: guard.py subclasses uvicorn's internals"
    installed = Version(version("uvicorn"))
    assert installed in spec, (f"uvicorn {installed} is installed, outside uvicorn{spec}, the versions the class's "
                               f"guard is tested on: run this file's tests against it before widening the pin")


def _guard_class() -> tuple[type, ast.ClassDef]:
    cls = guarded_protocol(Guard())
    tree = ast.parse(Path(inspect.getfile(class_guard)).read_text(encoding="utf-8"))
    found = [node for node in ast.walk(tree) if isinstance(node, ast.ClassDef) and node.name == cls.__name__]
    assert len(found) == 1, f"guard.py should define {cls.__name__} once"
    return cls, found[0]


def _self_reads(node: ast.AST, name: str = "self") -> dict[str, set[str]]:
    """Every ``name.x`` in ``node``, and for each x, the ``name.x.y`` read of it."""
    reads: dict[str, set[str]] = {}
    for sub in ast.walk(node):
        if isinstance(sub, ast.Attribute) and isinstance(sub.value, ast.Name) and sub.value.id == name:
            reads.setdefault(sub.attr, set())
        if (isinstance(sub, ast.Attribute) and isinstance(sub.value, ast.Attribute)
                and isinstance(sub.value.value, ast.Name) and sub.value.value.id == name):
            reads.setdefault(sub.value.attr, set()).add(sub.attr)
    return reads


def _assigned(cls: type, method: str | None = "__init__") -> set[str]:
    """The ``self.x = ...`` names of ``cls.__init__`` (``method`` None: of any of its methods, e.g. ``self.url``,
    which uvicorn's protocol sets as each request begins)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cls if method is None else getattr(cls, method))))
    return {t.attr for node in ast.walk(tree) if isinstance(node, (ast.Assign, ast.AnnAssign))
            for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
            if isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name) and t.value.id == "self"}


def _super_calls(node: ast.ClassDef) -> set[str]:
    """The names of the guard's methods that call ``super().<their own name>``."""
    found = set()
    for method in node.body:
        if isinstance(method, ast.FunctionDef | ast.AsyncFunctionDef):
            for sub in ast.walk(method):
                if (isinstance(sub, ast.Attribute) and sub.attr == method.name and isinstance(sub.value, ast.Call)
                        and isinstance(sub.value.func, ast.Name) and sub.value.func.id == "super"):
                    found.add(method.name)
    return found


def internals_problems(base: type = HttpToolsProtocol, cycle: type = RequestResponseCycle) -> list[str]:
    """What the guard relies on that ``base`` (uvicorn's protocol) and ``cycle`` (its request's) no longer hold,
    one line each, naming it."""
    guarded, node = _guard_class()
    problems = []
    own = {k for k in vars(guarded) if not (k.startswith("__") and k.endswith("__"))}
    extended = _super_calls(node)  # a method that calls uvicorn's own of its name is an override, on purpose
    for name in sorted(own):
        theirs = getattr(base, name, None)
        if name.startswith("_") and name not in extended:
            if theirs is not None:
                problems.append(f"uvicorn's {base.__name__} now has its own {name}, which the guard's hides")
            continue
        if theirs is None:
            problems.append(f"the guard overrides {base.__name__}.{name}, which uvicorn no longer has")
            continue
        if callable(theirs):
            mine = list(inspect.signature(getattr(guarded, name)).parameters)
            if list(inspect.signature(theirs).parameters) != mine:
                problems.append(f"{base.__name__}.{name} now takes {inspect.signature(theirs)}, the guard's "
                                f"{inspect.signature(getattr(guarded, name))}")
    config = uvicorn.Config(app=lambda scope, receive, send: None, log_level="warning")
    config.load()
    loop = asyncio.new_event_loop()
    try:
        protocol = base(config, ServerState(), {}, _loop=loop)
    finally:
        loop.close()
    cycle_fields = _assigned(cycle)
    set_later = _assigned(base, None)
    for name, reads in sorted(_self_reads(node).items()):
        if name in own:
            continue
        if not hasattr(protocol, name) and name not in set_later:
            problems.append(f"the guard reads self.{name}, which uvicorn's {base.__name__} no longer sets")
        if name == "cycle":
            problems += [f"the guard reads self.cycle.{attr}, which uvicorn's {cycle.__name__} no longer sets"
                         for attr in sorted(reads - cycle_fields) if not hasattr(cycle, attr)]
    options = inspect.signature(uvicorn.Config).parameters
    problems += [f"uvicorn.Config no longer takes {option}=, which the class's server passes"
                 for option in CONFIG_OPTIONS if option not in options]
    return problems


def test_the_internals_the_guard_relies_on_are_uvicorns():
    problems = internals_problems()
    assert not problems, (f"uvicorn {version('uvicorn')} changed what armgame/classroom/guard.py relies on:\n"
                          + "\n".join(problems))


def test_a_change_in_uvicorns_internals_is_named():
    """The check has teeth: a protocol whose hooks and fields moved is named, each thing that moved."""

    class Moved(HttpToolsProtocol):
        on_response_complete = None  # type: ignore[assignment]  # a hook gone

        def on_headers_complete(self, parser: object = None) -> None:  # a hook whose signature changed
            pass

        def __init__(self, *args: object, **kwargs: object) -> None:
            super().__init__(*args, **kwargs)  # type: ignore[arg-type]
            del self.pipeline  # a field gone

        def _arm(self) -> None:  # a name of the guard's own, now uvicorn's
            pass

    class Cycle(RequestResponseCycle):
        message_event = None

        def __init__(self) -> None:
            pass

    problems = "\n".join(internals_problems(Moved, Cycle))
    for expected in ("Moved.on_response_complete, which uvicorn no longer has",
                     "Moved.on_headers_complete now takes", "self.pipeline, which uvicorn's Moved no longer sets",
                     "Moved now has its own _arm", "self.cycle.response_complete"):
        assert expected in problems, problems


@pytest.mark.parametrize("option", CONFIG_OPTIONS)
def test_the_server_passes_the_options_named_here(option):
    """CONFIG_OPTIONS is what serve.py passes to uvicorn.Config (so the check above covers them)."""
    assert re.search(rf"\b{option}=", (ROOT / "armgame/classroom/serve.py").read_text(encoding="utf-8"))
