"""Records and trust: durable checked files, replays, rulesets and the high-score table. No pygame.

``storage`` is the one way armgame reads and writes files (regular files only, never blocking,
atomic, no symlink followed out of a folder, JSON strictly as data); ``replay`` turns a game's
configuration and input timeline into a file that recomputes its result; ``rulesets`` names the
games that rank, by the digest of their configuration; ``scores`` keeps the high-score table
(``ScoreTable``: its lists and ranks), each entry backed by its replay. The table is four concepts,
each a module: ``entry`` (``ScoreEntry``, each field checked, its orders), ``tableformat`` (its bytes:
parsed or salvaged, its head and counters, written one entry a line), ``tablefile`` (the file: read and
written whole under its lock, its journal) and ``checking`` (each entry against its replay, within a
cost counted beforehand), with ``cache`` (the per-user verdicts)
and ``teacher`` (the account that started a table keeps its seed and order of entry where no
classmate writes); ``listing`` decides which entries a listing replays, counts and flags. The limits
every reader and writer shares are in ``armgame.limits``, what a valid field is in ``armgame.valid``.
"""
