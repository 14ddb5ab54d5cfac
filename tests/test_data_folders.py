"""The lab's kept runs and the score table sit side by side in one per-user folder on every platform."""

import platformdirs

from armgame.commands.lab import default_runs_dir
from armgame.records import scores


def test_the_lab_keeps_its_runs_beside_the_tables_folder(monkeypatch, tmp_path):
    # Whatever the platform's convention (macOS's Application Support, Windows' LOCALAPPDATA), one answer.
    monkeypatch.setattr(platformdirs, "user_data_dir", lambda *a, **k: str(tmp_path / "Application Support" / a[0]))
    monkeypatch.delenv(scores.SCORES_ENV, raising=False)
    monkeypatch.setattr(scores, "__file__", str(tmp_path / "site-packages" / "armgame" / "records" / "scores.py"))
    assert default_runs_dir() == tmp_path / "Application Support" / "armgame" / "lab"
    assert scores.default_scores_dir() == tmp_path / "Application Support" / "armgame" / "scores"
