"""Records and trust: durable checked files, replays, and the high-score table. No pygame.

``storage`` writes files atomically and reads them strictly as data; ``replay`` turns a game's
configuration and input timeline into a file that recomputes its result; ``scores`` keeps the
high-score table, each entry backed by its replay.
"""
