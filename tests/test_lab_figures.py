"""The lab's figures and the class curve, on a synthetic experiment: the two-rate learner driving reaches."""

import builtins
import csv
import math
import struct

import numpy as np
import pytest
from lab_synthetic import HOME, protocol, student, targets

from armgame.errors import UserError
from armgame.lab import figures
from armgame.lab.figures import blocks_of, class_curve, class_figure, learning_figure, paths_figure
from armgame.lab.metrics import class_columns, write_class_csv


@pytest.fixture(scope="module")
def experiment():
    return student(seed=1)


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_the_synthetic_experiment_shows_learning_and_an_after_effect(experiment):
    # Guards the data the figures are looked at with: the measures carry the textbook picture.
    rows, _ = experiment
    error = {r["trial"]: r["initial_direction_error_deg"] for r in rows}
    assert all(abs(error[n]) < 1.0 for n in range(1, 17))            # baseline: straight
    assert error[17] > 30.0 and error[80] < 0.6 * error[17]           # exposure: large, then decaying
    assert error[81] < -15.0                                          # washout: the after-effect
    assert error[30] < 0.0                                            # a catch trial errs the other way


def test_blocks_and_catch_trials_are_found_from_the_rows():
    rows = [{"block": b, "trial": n, "perturbation": p} for n, (b, p) in enumerate(protocol(), start=1)]
    spans = blocks_of(rows)
    assert [(s["block"], s["first"], s["last"], s["perturbation"]) for s in spans] == [
        ("baseline", 1, 16, "none"), ("exposure", 17, 80, "curl"), ("washout", 81, 104, "none")]
    assert spans[1]["catch"] == [30, 46, 62] and spans[0]["catch"] == spans[2]["catch"] == []


def test_learning_figure_is_a_1920_by_1080_png(tmp_path, experiment):
    rows, _ = experiment
    for metric in ("initial_direction_error_deg", "max_perpendicular_error_m", "path_length_ratio"):
        path = tmp_path / f"{metric}.png"
        learning_figure(rows, path, metric=metric)
        assert png_size(path) == (1920, 1080)
    assert not list(tmp_path.glob(".*.tmp"))


def test_paths_figure_draws_any_number_of_panels(tmp_path, experiment):
    _, paths = experiment
    groups = {"baseline": [paths[n] for n in range(9, 17)], "early exposure": [paths[n] for n in range(17, 25)],
              "late exposure": [paths[n] for n in range(73, 81)], "early washout": [paths[n] for n in range(81, 89)]}
    paths_figure(groups, HOME, targets(), tmp_path / "paths.png", target_radius=0.01, caption="what to see")
    assert png_size(tmp_path / "paths.png") == (1920, 1080)
    paths_figure({"one": [paths[1]], "empty": []}, HOME, targets(), tmp_path / "two.png")
    assert png_size(tmp_path / "two.png") == (1920, 1080)
    with pytest.raises(UserError, match="no hand paths"):
        paths_figure({}, HOME, targets(), tmp_path / "none.png")


def test_class_curve_means_and_sems_by_trial_with_uneven_students():
    def rows(values, block="exposure"):
        return [{"block": block, "trial": n, "perturbation": "curl", "initial_direction_error_deg": v}
                for n, v in enumerate(values, start=1)]

    curve = class_curve([rows([1.0, 2.0, 3.0]), rows([3.0, float("nan")]), rows([5.0, 4.0, 6.0, 7.0], "other")])
    assert [c["trial"] for c in curve] == [1, 2, 3, 4]
    assert [c["n"] for c in curve] == [3, 2, 2, 1]
    assert [c["mean"] for c in curve] == [3.0, 3.0, 4.5, 7.0]
    assert curve[0]["sem"] == pytest.approx(2.0 / math.sqrt(3))          # sd 2 over sqrt(3)
    assert curve[1]["sem"] == pytest.approx(math.sqrt(2.0) / math.sqrt(2))
    assert math.isnan(curve[3]["sem"]) and curve[3]["block"] == "other"
    assert curve[0]["block"] == "exposure"                                 # what most students had
    nobody = class_curve([rows([float("nan")])])
    assert nobody[0]["n"] == 0 and math.isnan(nobody[0]["mean"])
    assert class_curve([]) == []
    with pytest.raises(UserError, match="student 2 has trial 1 twice"):
        class_curve([rows([1.0]), rows([1.0]) * 2])
    with pytest.raises(UserError, match="unknown measure"):
        class_curve([rows([1.0])], metric="score")


def test_class_figure_and_csv(tmp_path):
    students = [student(seed=s)[0] for s in range(5)]
    students[2] = students[2][:60]  # one student stopped early
    curve = class_curve(students)
    assert [c["n"] for c in curve[:60]] == [5] * 60 and curve[-1]["n"] == 4
    class_figure(curve, tmp_path / "class.png")
    assert png_size(tmp_path / "class.png") == (1920, 1080)
    class_figure(class_curve(students[:2]), tmp_path / "even.png", metric="initial_direction_error_deg")
    write_class_csv(tmp_path / "class.csv", curve, "initial_direction_error_deg")
    with open(tmp_path / "class.csv", newline="") as f:
        table = list(csv.DictReader(f))
    # The mean and s.e.m. name their measure and its unit.
    assert list(table[0]) == list(class_columns("initial_direction_error_deg")) == \
        ["trial", "block", "perturbation", "mean_initial_direction_error_deg", "sem_initial_direction_error_deg", "n"]
    assert len(table) == len(curve)
    assert float(table[20]["mean_initial_direction_error_deg"]) == curve[20]["mean"] and int(table[-1]["n"]) == 4
    assert table[0]["sem_initial_direction_error_deg"] != ""
    assert float(table[0]["sem_initial_direction_error_deg"]) == curve[0]["sem"]


def test_bad_requests_are_one_line_user_errors(tmp_path, experiment):
    rows, _ = experiment
    with pytest.raises(UserError, match="unknown measure 'score'"):
        learning_figure(rows, tmp_path / "x.png", metric="score")
    with pytest.raises(UserError, match="no trials"):
        learning_figure([], tmp_path / "x.png")
    with pytest.raises(UserError, match="no trials"):
        class_figure([], tmp_path / "x.png")
    (tmp_path / "folder.png").mkdir()
    with pytest.raises(UserError, match="not a regular file"):
        learning_figure(rows, tmp_path / "folder.png")
    (tmp_path / "link.png").symlink_to(tmp_path / "elsewhere.png")
    with pytest.raises(UserError, match="not a regular file"):
        learning_figure(rows, tmp_path / "link.png")
    assert not (tmp_path / "elsewhere.png").exists()


def test_missing_matplotlib_is_one_clear_line(tmp_path, monkeypatch, experiment):
    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name == "matplotlib" or name.startswith("matplotlib."):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    with pytest.raises(UserError, match=r"pip install 'armgame\[plot\]'"):
        learning_figure(experiment[0], tmp_path / "x.png")
    assert class_curve([experiment[0]])[0]["n"] == 1  # the curve itself needs no matplotlib


def test_figures_leave_matplotlibs_global_settings_alone(tmp_path, experiment):
    import matplotlib

    before = matplotlib.rcParams["font.size"]
    learning_figure(experiment[0], tmp_path / "x.png")
    assert matplotlib.rcParams["font.size"] == before


def test_nan_measures_are_gaps_not_errors(tmp_path, experiment):
    rows = [dict(r) for r in experiment[0]]
    for r in rows[20:25]:
        r["initial_direction_error_deg"] = float("nan")
    learning_figure(rows, tmp_path / "gaps.png")
    curve = class_curve([rows, experiment[0]])
    assert curve[21]["n"] == 1 and np.isnan(curve[21]["sem"])
    class_figure(curve, tmp_path / "class.png")


def test_trials_numbered_per_block_are_drawn_in_row_order(tmp_path, experiment, monkeypatch):
    rows = [dict(r) for r in experiment[0]]
    first = {}
    for r in rows:  # renumber within each block: 1..16, 1..64, 1..24
        first.setdefault(r["block"], r["trial"])
        r["trial"] = r["trial"] - first[r["block"]] + 1
    drawn = []
    monkeypatch.setattr(figures, "_shade_blocks", lambda ax, spans: drawn.extend(spans))
    learning_figure(rows, tmp_path / "per_block.png")
    assert [(s["first"], s["last"], s["catch"]) for s in drawn] == [(1, 16, []), (17, 80, [30, 46, 62]),
                                                                    (81, 104, [])]


def test_the_adaptation_figure_draws_the_channel_trials(tmp_path):
    rows = [{"block": "exposure" if n <= 12 else "clamp", "trial": n,
             "perturbation": "channel" if n in (6, 9) or n > 12 else "curl",
             "adaptation_index": 0.1 * n if n in (6, 9) or n > 12 else float("nan")} for n in range(1, 21)]
    figures.adaptation_figure(rows, tmp_path / "a.png")
    assert png_size(tmp_path / "a.png") == (1920, 1080)
    with pytest.raises(UserError, match="no channel trial"):
        figures.adaptation_figure([{**r, "perturbation": "curl"} for r in rows], tmp_path / "b.png")
