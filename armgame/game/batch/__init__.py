"""Many games in lockstep (moved here from ``armgame/game/batch.py``; split into modules next)."""

from .session import (
    BATCH_INTEGRATORS,
    FAST_MAX_SECONDS,
    KERNELS,
    KNIFE_EDGE,
    MAX_SCRIPT_EVENTS,
    MAX_SCRIPTS,
    MAX_SCRIPTS_BYTES,
    PER_GAME_FIELDS,
    SERIES_MIN_GAMES,
    STATE_TOLERANCE,
    BatchGameSession,
    batch_problem,
    files_in,
    play_scripts,
    replay_many,
    script_paths,
)

__all__ = ["BATCH_INTEGRATORS", "FAST_MAX_SECONDS", "KERNELS", "KNIFE_EDGE", "MAX_SCRIPTS", "MAX_SCRIPTS_BYTES",
           "MAX_SCRIPT_EVENTS", "PER_GAME_FIELDS", "SERIES_MIN_GAMES", "STATE_TOLERANCE", "BatchGameSession",
           "batch_problem", "files_in", "play_scripts", "replay_many", "script_paths"]
