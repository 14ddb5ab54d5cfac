"""A writer of the score table in a process of its own, started by ``spawn`` (what Windows and macOS
use): a small module, so each child imports only the records and the game, not the test module and
pytest; and a ``spawn`` child does not inherit the parent's simulated platform, so it sets it up
itself before armgame is imported."""

import no_posix

no_posix.install_if_asked()

from pathlib import Path  # noqa: E402

from armgame.game.rules import GameConfig  # noqa: E402
from armgame.game.session import GameSession  # noqa: E402
from armgame.records.replay import Replay  # noqa: E402
from armgame.records.scores import ScoreTable  # noqa: E402


def finished_game(player: str, seed: int) -> Replay:
    """A finished 0.2 s game of one's own (a game enters once): cheap to write and to verify."""
    session = GameSession(GameConfig(time_limit=0.2, seed=seed))
    session.advance(sum(map(ord, player)) % 40)
    session.key_event("d", "down")
    session.advance(session.total_steps)
    return Replay.from_session(session, "script", player=player)


def write(folder: str, who: int, count: int, barrier) -> None:
    replays = [finished_game(f"writer {who}", seed=who * count + k) for k in range(count)]
    barrier.wait()  # every writer saves at once
    table = ScoreTable(Path(folder))
    for replay in replays:
        table.add(replay)
