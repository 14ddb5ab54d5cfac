"""The game: muscles, rules, the fixed-step session and its batched twin. Nothing here draws.

Pure Python and numpy, but for ``_ckernel.c``, the batched games' optional compiled kernel
(``batch/compiled.py`` says when it is used; without it the batch runs numpy).
"""
