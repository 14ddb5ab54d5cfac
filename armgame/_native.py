"""The compiled modules, loaded one way: where built, and only if they speak this package's convention.

``setup.py`` builds five optional C extensions where a compiler is found: ``armgame.game._ckernel``
(the game's loop, the batch's kernel and its event columns), ``armgame.game._cbots`` (the bots' forward
model), ``armgame.physics._ctrig`` (the arm's sine), ``armgame.env._cvector`` (the vector env's passes)
and ``armgame.records._ctimeline`` (a replay's timeline read and its identity's forms).
Each has a Python twin that gives the same bits, so a missing build only costs speed. A build of
another version of its ``.c`` file (a stale ``.so`` left by an older install) is worse than none:
its calling convention may differ, and it would be misread. So each module carries integer
constants (``VERSION``, and ``_ckernel`` its ``PARAMS`` count) that change with its convention,
and ``load`` hands a module over only if they are the ones its caller speaks.

This module sits below every layer (it imports no other part of armgame): the caller names the
module it wants, so a layer loads only its own extensions.
"""

from __future__ import annotations

import importlib
from types import ModuleType


def speaks(module: object, version: int | None, **constants: int) -> bool:
    """Whether ``module`` carries ``VERSION == version`` (None: no version asked) and each of ``constants``."""
    wanted = constants if version is None else {"VERSION": version, **constants}
    return all(getattr(module, name, None) == value for name, value in wanted.items())


def load(name: str, version: int | None, **constants: int) -> ModuleType | None:
    """The compiled module ``name`` (absolute, e.g. ``"armgame.game._cbots"``), or None where it was not
    built or speaks another convention than ``version`` and ``constants`` (see ``speaks``): the caller
    then runs its Python twin. ``version`` None is for a module whose interface has no convention to
    misread (``_ctrig``: floats in, floats out)."""
    try:
        module = importlib.import_module(name)
    except ImportError:
        return None
    return module if speaks(module, version, **constants) else None
