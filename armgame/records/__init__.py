"""Records and trust: durable checked files, replays, rulesets and the high-score table. No pygame.

``storage`` is the one way armgame reads and writes files (regular files only, never blocking,
atomic, no symlink followed out of a folder, JSON strictly as data); ``replay`` turns a game's
configuration and input timeline into a file that recomputes its result; ``rulesets`` names the
games that rank, by the digest of their configuration; ``scores`` keeps the high-score table,
each entry backed by its replay, with a per-user cache of verdicts. The limits every reader and
writer shares are in ``armgame.limits``.
"""
