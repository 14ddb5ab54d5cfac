"""The game: muscles, rules, the fixed-step session and its batched twin. Nothing here draws.

Pure Python and numpy, but for two optional C files that compute exactly what the Python computes:
``_ckernel.c``, the game's loop (one game for ``GameSession``, many for the batch:
``batch/compiled.py`` says when the batch uses it) and ``_cbots.c``, the bots' forward model.
Without a C compiler the same results come from Python and numpy.
"""
