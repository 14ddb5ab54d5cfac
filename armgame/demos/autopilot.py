"""The autopilot demo: "does the brain know about interaction torques?" as a game between two bots.

Both bots play the same game (same seed, same targets) with the same planner, feedback and key
pressing; ``model`` knows the arm's interaction torques and ``naive`` drives each joint as if
the other did not move (see ``armgame.game.bots``). Headless, it plays 60 s games on seeds 0 to
9 and prints (and with ``--out``, writes) the hits per seed for both. The window, where the two arms
play side by side, is ``armgame.ui.autopilot_window``; nothing here imports pygame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import UserError
from ..game.bots import BOT_NAMES, play_bot
from ..game.rules import GameConfig

TABLE_SEEDS = tuple(range(10))
WINDOW_SEED = 10  # the game's own default seed: the targets a class sees in `armgame play`
CAPTION = "Same targets, same planner. Left knows the interaction torques; right drives each joint alone."


@dataclass(frozen=True)
class Row:
    seed: int
    hits: dict[str, int]

    @property
    def ratio(self) -> float:
        return self.hits["model"] / max(self.hits["naive"], 1)


def hits_table(seeds: tuple[int, ...] = TABLE_SEEDS, duration: float = 60.0) -> list[Row]:
    return [Row(seed, {name: play_bot(GameConfig(seed=seed, time_limit=duration), name).rules.board.hits
                       for name in BOT_NAMES}) for seed in seeds]


def format_table(rows: list[Row], duration: float) -> str:
    lines = [f"hits in {duration:g} s per seed (model knows the interaction torques; naive does not)",
             f"{'seed':>4} {'model':>6} {'naive':>6} {'model/naive':>12}"]
    for r in rows:
        lines.append(f"{r.seed:>4} {r.hits['model']:>6} {r.hits['naive']:>6} {r.ratio:>12.2f}")
    lines.append(f"{'all':>4} {sum(r.hits['model'] for r in rows):>6} {sum(r.hits['naive'] for r in rows):>6} "
                 f"{min(r.ratio for r in rows):>12.2f}  (min ratio)")
    return "\n".join(lines)


def run_headless(out: Path | None, duration: float | None, figures: bool = True) -> str:
    """The hits table, printed; with ``out``, written there as ``autopilot.csv`` and (with ``figures``)
    the slide ``autopilot.png``, as every other demo writes its CSV and figure."""
    duration = 60.0 if duration is None else duration
    if out is not None and figures:  # before ten games are played: a missing matplotlib is said first
        from .figures import require_matplotlib

        require_matplotlib()
    rows = hits_table(TABLE_SEEDS, duration)
    text = format_table(rows, duration)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        path = out / "autopilot.csv"
        from ..records.storage import atomic_write_bytes

        try:
            atomic_write_bytes(path, ("seed,duration,model_hits,naive_hits\n" + "".join(
                f"{r.seed},{duration:g},{r.hits['model']},{r.hits['naive']}\n" for r in rows)).encode(), "CSV")
        except OSError as exc:
            raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None
        text += f"\nwrote {path}"
        if figures:
            from .figures import autopilot_figure

            text += f"\nwrote {autopilot_figure(rows, duration, out / 'autopilot.png')}"
    return text
