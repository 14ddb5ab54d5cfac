"""The one set of limits shared by every writer and reader of games, replays and runs.

A writer refuses up front (or stops cleanly) whatever the matching reader would refuse
later, so nothing is ever recorded that cannot be replayed: ``play`` checks a game's length
against ``MAX_GAME_STEPS`` before it starts and stops a game at ``MAX_EVENTS`` input events;
the replay reader refuses files over ``MAX_REPLAY_BYTES``, timelines over ``MAX_EVENTS`` and
games over ``MAX_GAME_STEPS`` before replaying anything. A ranked game costs exactly its
ruleset (15,000 steps for ``standard``); these bounds are for everything else.

No imports: every layer may read these numbers. The README's "Limits" section states them. The live
class's own bounds (the largest hand-in, its deadlines, queues and shares) are ``armgame.classroom.bounds``.
"""

from __future__ import annotations

#: Longest game a replay may describe, in physics steps: one hour at the standard step (1/250 s).
#: Verifying it costs about a minute of one core in the worst case.
MAX_GAME_STEPS = 900_000
#: Longest game in seconds, whatever the step.
MAX_GAME_SECONDS = 3600.0
#: Input events in one game (key downs and ups). A keyboard player pressing 20 keys a second for an
#: hour makes 144,000; a bot acting every control period stays far below.
MAX_EVENTS = 200_000
#: Hits one replay may claim; verification stops as soon as the replay passes its claim.
MAX_HITS = 100_000
#: The most work one verification of a game spends, in ``records.checking.replay_work``'s units (physics
#: steps of the compiled loop: 6 a target posture tried, 20 an input event), counted as it runs: the
#: longest game with the most events, hitting 5 targets a second, is under 6,000,000, so no game whose
#: targets land clear of the hand comes near it. A "hit storm" (targets drawn on the hand, so that every
#: step hits and each hit tries 1,000 postures) stops here, after about 7 s, rather than after the
#: minutes 100,000 claimed hits take.
MAX_VERIFY_WORK = 60_000_000
#: Size of one replay file: MAX_EVENTS events at about 40 bytes each, and the rest.
MAX_REPLAY_BYTES = 16 * 1024 * 1024
#: Size of a score table: at least 100,000 entries of about 330 bytes each, with room.
MAX_TABLE_BYTES = 64 * 1024 * 1024
#: Entries of one table: a full table refuses a new entry rather than drop an old one.
MAX_TABLE_ENTRIES = 150_000
#: A script for headless play.
MAX_SCRIPT_BYTES = 16 * 1024 * 1024

#: ``simulate``: physics steps, output rows and memory of one run.
MAX_SIMULATE_STEPS = 20_000_000
MAX_SIMULATE_ROWS = 5_000_000
#: Bytes per output row of the CSV at full precision (10 columns of up to 24 characters).
SIMULATE_ROW_BYTES = 240

#: The game's seed unless asked otherwise (the 2012 game's: every class sees the same targets), and so
#: the seed a new high-score table ranks.
DEFAULT_SEED = 10
