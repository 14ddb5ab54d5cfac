"""Many games in lockstep: a class's scripts, a batch of replays, a vector of environments.

``BatchGameSession`` runs N games at once, one array per quantity, and each of its games equals
the single ``GameSession`` fed the same inputs: hits, score, resets and steps exactly, the joint
state bit for bit (or, where stated, within ``STATE_TOLERANCE``). One module per job, each saying
what it owns and which part of that promise it keeps:

* ``session``: ``BatchGameSession`` (state, input, hit test and scoring, ``play``) and the batch's
  numbers (``STATE_TOLERANCE``, ``SERIES_MIN_GAMES``, ``FAST_MAX_SECONDS``, ``KNIFE_EDGE``). Start here.
* ``replays``: ``replay_many``, recorded games replayed in batches, each result the single session's.
* ``variant``: the harder tasks' motor noise, field at the hand and speed guard, which the compiled
  kernel steps (``BatchGameSession(variant=...)``).
* ``schedule``: input timelines turned into the commands the kernels apply between steps, each at
  the step where the single session applies it.
* ``numpy_kernel``: the single session's RK4 step written out on arrays, exact or fast; the
  fallback where the compiled kernel is not built, and the Euler schemes.
* ``compiled``: the wrapper of the C kernel (``armgame/game/_ckernel.c``), the default for RK4
  where ``pip install`` could build it.
* ``scripts``: a class's script files played in one batch, everything bounded and checked first.

The names below are the package's interface; change a number where it is defined (the module
named above), which is where the code reads it.
"""

from .replays import replay_many
from .scripts import MAX_SCRIPT_EVENTS, MAX_SCRIPTS, MAX_SCRIPTS_BYTES, files_in, play_scripts, script_paths
from .session import (
    BATCH_INTEGRATORS,
    FAST_MAX_SECONDS,
    KERNELS,
    KNIFE_EDGE,
    PER_GAME_FIELDS,
    SERIES_MIN_GAMES,
    STATE_TOLERANCE,
    BatchGameSession,
    batch_problem,
)

__all__ = ["BATCH_INTEGRATORS", "FAST_MAX_SECONDS", "KERNELS", "KNIFE_EDGE", "MAX_SCRIPTS", "MAX_SCRIPTS_BYTES",
           "MAX_SCRIPT_EVENTS", "PER_GAME_FIELDS", "SERIES_MIN_GAMES", "STATE_TOLERANCE", "BatchGameSession",
           "batch_problem", "files_in", "play_scripts", "replay_many", "script_paths"]
