"""armgame lab and armgame analyze end to end: the adapting bot's learning curve, replays that verify,
the trials table recomputed from a replay bit for bit, tampered and foreign files left out, one-line errors."""

import json

import numpy as np
import pytest

from armgame.cli import main
from armgame.lab.metrics import read_trials_csv

SHORT = """
name = "short"
targets = 4
timeout = 1.5

[[blocks]]
name = "baseline"
trials = 4

[[blocks]]
name = "exposure"
trials = 8
perturbation = "curl"
b = 2.0

[[blocks]]
name = "washout"
trials = 4
"""


@pytest.fixture(scope="module")
def curl_run(tmp_path_factory):
    """The issue's command, once: armgame lab curl --bot adaptive --headless --out DIR (and a replay)."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("curl")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        code = main(["lab", "curl", "--bot", "adaptive", "--headless", "--out", str(out / "run"), "--no-figures",
                     "--record", str(out / "curl.json")])
    assert code == 0
    (out / "printed.txt").write_text(printed.getvalue())
    return out


def block_values(rows, block, metric="max_perpendicular_error_m"):
    return np.array([r[metric] for r in rows if r["block"] == block])


def test_adaptive_bot_draws_the_textbook_learning_curve(curl_run):
    """Error jumps when the field comes on (clockwise: negative), decays over exposure, and the first
    washout reaches err the opposite way (the after-effect), decaying in turn."""
    rows = read_trials_csv(curl_run / "run" / "trials.csv")
    assert len(rows) == 120 and all(r["hit"] for r in rows)
    baseline, exposure, washout = (block_values(rows, b) for b in ("baseline", "exposure", "washout"))
    assert np.all(np.abs(baseline) < 0.012) and abs(baseline.mean()) < 0.002  # the motor noise's scatter, no bias
    early, late = exposure[:8].mean(), exposure[-8:].mean()
    assert early < -0.015  # centimetres to the right of the reach
    assert early < late < 0.0 and abs(late) < 0.6 * abs(early)
    assert washout[:8].mean() > 0.006  # the after-effect: the other side
    assert washout[-8:].mean() < washout[:8].mean()
    assert exposure[0] < -0.01 and washout[0] > 0.01  # already on the first trial of each


def test_the_lab_replay_verifies(curl_run, capsys):
    assert main(["verify", str(curl_run / "curl.json")]) == 0
    assert "matches: lab run (curl, bot, seed 10, 120 trials)" in capsys.readouterr().out


def test_the_curl_preset_bot_has_a_persons_motor_noise_and_says_so(curl_run):
    """A lab report's preset: its bot carries the human level by default, seeded by the run's seed, stated in the
    run's output and kept in the replay."""
    printed = (curl_run / "printed.txt").read_text()
    assert ("motor noise 0.3 (the s.d. of the command as a fraction of it, correlated over 50 ms, seed 10), the curl "
            "preset's default (--motor-noise 0 turns it off)") in printed
    task = json.loads((curl_run / "curl.json").read_text())["task"]
    assert task["motor_noise"] == {"level": 0.3, "correlation_time_s": 0.05, "seed": 10}


def test_a_folder_of_replays_verifies_lab_runs_and_games_each_by_their_own_rules(curl_run, tmp_path, capsys):
    """``verify FOLDER`` batches the standard games; a lab run is compared trial by trial, never as a game."""
    import shutil

    folder = tmp_path / "mixed"
    folder.mkdir()
    shutil.copy(curl_run / "curl.json", folder / "lab.json")
    assert main(["play", "--headless", "--duration", "2", "--record", str(folder / "game.json")]) == 0
    capsys.readouterr()
    assert main(["verify", str(folder)]) == 0
    out = capsys.readouterr().out
    assert "lab run (curl" in out and "120 trials" in out and "2 replays, 0 differ" in out
    data = json.loads((folder / "lab.json").read_text())
    data["task"]["trials"][5][3] = not data["task"]["trials"][5][3]  # a miss claimed as a hit, or the reverse
    (folder / "lab.json").write_text(json.dumps(data))
    assert main(["verify", str(folder)]) == 1
    assert "1 differ" in capsys.readouterr().out


def test_analyze_recomputes_the_trials_table_bit_for_bit(curl_run, tmp_path, capsys):
    assert main(["analyze", str(curl_run / "curl.json"), "--out", str(tmp_path / "again.csv")]) == 0
    assert "  adaptive bot, motor noise 0.3 (" in capsys.readouterr().out
    # One table leads each row with whose run it is; the measures that follow are the lab's, byte for byte.
    lines = (tmp_path / "again.csv").read_text().splitlines()
    replay = str(curl_run / "curl.json")
    assert lines[0].startswith("player,replay,") and all(line.startswith(f",{replay},") for line in lines[1:])
    assert [line.split(",", 2)[2] for line in lines] == (curl_run / "run" / "trials.csv").read_text().splitlines()
    assert main(["analyze", str(curl_run / "curl.json"), "--out", str(tmp_path / "each")]) == 0
    assert (tmp_path / "each" / "curl.trials.csv").read_bytes() == (curl_run / "run" / "trials.csv").read_bytes()


@pytest.fixture(scope="module")
def short_class(tmp_path_factory):
    """Three students' short lab runs (seeds 1, 2, 3), recorded once for the tests that analyse them: the third
    with motor noise (a class's curve may mix runs with it and without: the protocol is the same)."""
    where = tmp_path_factory.mktemp("short")
    protocol = where / "short.toml"
    protocol.write_text(SHORT)
    for seed in (1, 2, 3):
        assert main(["lab", str(protocol), "--bot", "adaptive", "--headless", "--seed", str(seed),
                     "--record", str(where / f"student{seed}.json"), "--name", f"Student {seed}"]
                    + ["--motor-noise", "human"] * (seed == 3)) == 0
    return where


def _short_runs(short_class, tmp_path, seeds):
    """A fresh folder of the given students' recorded runs, the test's own to change."""
    folder = tmp_path / "class"
    folder.mkdir()
    for seed in seeds:
        name = f"student{seed}.json"
        (folder / name).write_bytes((short_class / name).read_bytes())
    return folder


def test_analyze_leaves_out_what_does_not_verify(short_class, tmp_path, capsys):
    folder = _short_runs(short_class, tmp_path, [1])
    good = folder / "student1.json"
    data = json.loads(good.read_text())
    data["timeline"][5][0] += 1  # a key pressed one step later than recorded
    bad = folder / "tampered.json"
    bad.write_text(json.dumps(data))
    assert main(["analyze", str(bad), "--out", str(tmp_path / "t.csv")]) == 2
    err = capsys.readouterr().err
    assert "tampered.json: DIFFERS" in err and "no replay could be analysed" in err
    assert main(["analyze", str(good), str(bad), "--out", str(tmp_path / "t.csv")]) == 1
    assert len(read_trials_csv(tmp_path / "t.csv")) == 16


def test_one_table_of_several_runs_says_whose_each_row_is(short_class, tmp_path):
    import csv

    folder = _short_runs(short_class, tmp_path, [1])
    data = json.loads((folder / "student1.json").read_text())
    data["player"] = "=HYPERLINK(1)"  # a name a spreadsheet would run as a formula (not part of the game)
    (folder / "student2.json").write_text(json.dumps(data))
    out = tmp_path / "all.csv"
    assert main(["analyze", str(folder / "student1.json"), str(folder / "student2.json"), "--out", str(out)]) == 0
    with out.open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 32
    assert {(r["player"], r["replay"]) for r in rows[:16]} == {("Student 1", str(folder / "student1.json"))}
    assert {(r["player"], r["replay"]) for r in rows[16:]} == {("'=HYPERLINK(1)", str(folder / "student2.json"))}
    assert [r["trial"] for r in rows[16:]][:1] == ["1"]  # each run's trials restart: the columns tell them apart
    assert len(read_trials_csv(out)) == 32  # the lab's own reader still reads it


def test_class_curve_merges_verified_students(short_class, tmp_path, capsys):
    folder = _short_runs(short_class, tmp_path, [1, 2, 3])
    data = json.loads((folder / "student3.json").read_text())
    data["task"]["trials"][0][3] = not data["task"]["trials"][0][3]  # a miss recorded as a hit, or back
    (folder / "cheat.json").write_text(json.dumps(data))
    game = tmp_path / "game.json"
    assert main(["play", "--headless", "--duration", "1", "--record", str(game)]) == 0
    (folder / "game.json").write_bytes(game.read_bytes())
    capsys.readouterr()
    code = main(["analyze", "--class", str(folder), "--out", str(tmp_path / "curve"), "--no-figures"])
    captured = capsys.readouterr()
    assert code == 1, captured.err
    assert "cheat.json: DIFFERS" in captured.err and "game.json: a game, not a lab run" in captured.err
    lines = (tmp_path / "curve" / "class_curve.csv").read_text().splitlines()
    assert lines[0] == "trial,block,perturbation,mean_max_perpendicular_error_m,sem_max_perpendicular_error_m,n"
    assert "class curve of 3 students (2 left out), 16 trials, max_perpendicular_error_m" in captured.out
    noise = [json.loads((folder / f"student{seed}.json").read_text())["task"].get("motor_noise") for seed in (1, 2, 3)]
    assert noise[:2] == [None, None] and noise[2]["level"] == 0.3  # one protocol, with noise and without
    assert len(lines) == 17 and all(line.endswith(",3") for line in lines[1:])
    # The mean is the mean over the three students' own tables.
    students = []
    for seed in (1, 2, 3):
        assert main(["analyze", str(folder / f"student{seed}.json"), "--out", str(tmp_path / f"s{seed}.csv")]) == 0
        students.append(read_trials_csv(tmp_path / f"s{seed}.csv"))
    fifth = lines[5].split(",")
    values = [s[4]["max_perpendicular_error_m"] for s in students]
    assert float(fifth[3]) == pytest.approx(np.mean(values), rel=1e-12)
    assert float(fifth[4]) == pytest.approx(np.std(values, ddof=1) / np.sqrt(3), rel=1e-12)


@pytest.mark.parametrize("argv, message", [
    (["lab", "curl", "--headless"], "--headless needs a --bot"),
    (["lab", "spiral"], "unknown lab protocol 'spiral'"),
    (["lab", "curl", "--headless", "--bot", "clever"], "unknown lab bot 'clever'"),
    (["lab", "curl", "--headless", "--bot", "model", "--retention", "0.5", "0.9"], "add --bot adaptive"),
    (["lab", "curl", "--headless", "--bot", "adaptive", "--retention", "0.995", "0.9"], "must forget faster"),
    (["lab", "curl", "--headless", "--bot", "model", "--catch", "80"], "--catch 80: blocks[1].catch_trials"),
    (["lab", "null", "--headless", "--bot", "model", "--catch", "3"], "has no perturbed block"),
    (["lab", "curl", "--headless", "--bot", "model", "--record", "/no/such/dir/r.json"], "its folder does not exist"),
    (["lab", "curl", "--headless", "--bot", "model", "--record", "/dev/null"], "is a device"),  # before the run
    (["lab", "curl", "--headless", "--bot", "model", "--record", "~nosuchuser/r.json"], "no such user"),
    (["lab", "curl", "--headless", "--bot", "model", "--out", "~nosuchuser/run"], "no such user"),
    (["analyze", "--out", "x.csv"], "no replay given"),
    (["lab", "lesson", "--speed", "2"], "--speed sets a bot's run in the window"),
    (["lab", "lesson", "--bot", "adaptive", "--headless", "--speed", "4"], "--headless runs as fast as it can"),
])
def test_command_errors_are_one_line(argv, message, capsys, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err and err.startswith(f"armgame {argv[0]}: error:")


def test_lab_out_writes_the_figures(tmp_path, capsys):
    protocol = tmp_path / "short.toml"
    protocol.write_text(SHORT)
    assert main(["lab", str(protocol), "--bot", "adaptive", "--headless", "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out
    for name in ("trials.csv", "learning.png", "paths.png"):
        assert f"wrote {tmp_path / 'run' / name}" in out and (tmp_path / "run" / name).is_file()
    assert (tmp_path / "run" / "learning.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "run" / "paths.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(read_trials_csv(tmp_path / "run" / "trials.csv")) == 16


def test_replay_headless_recomputes_a_lab_run(curl_run, capsys):
    assert main(["replay", str(curl_run / "curl.json"), "--headless", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert (result["hits"], result["scene"]) == (120, "lab")


def test_a_record_target_that_is_no_regular_file_is_refused_before_the_run(capsys):
    assert main(["lab", "curl", "--headless", "--bot", "model", "--record", "/dev/null"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "is a device" in captured.err  # no trial was run only to be lost


CHANNELS = SHORT.replace('b = 2.0\n', 'b = 2.0\nchannel_trials = 2\n') + """
[[blocks]]
name = "clamp"
trials = 3
channel_trials = 3
"""


def test_channel_trials_end_to_end(tmp_path, capsys):
    """A run with channel trials: the lab prints the adaptation index, trials.csv carries the channel
    columns, analyze recomputes them bit for bit from the replay, and --fit fits the errors or the indices."""
    protocol = tmp_path / "channels.toml"
    protocol.write_text(CHANNELS)
    assert main(["lab", str(protocol), "--bot", "adaptive", "--headless", "--out", str(tmp_path / "run"),
                 "--no-figures", "--record", str(tmp_path / "run.json")]) == 0
    out = capsys.readouterr().out
    assert "exposure: 2 channel trials; adaptation index" in out and "clamp: 3 channel trials" in out
    rows = read_trials_csv(tmp_path / "run" / "trials.csv")
    channel = [r for r in rows if r["perturbation"] == "channel"]
    assert len(channel) == 5 and all(np.isfinite(r["adaptation_index"]) for r in channel)
    assert all(np.isnan(r["adaptation_index"]) for r in rows if r["perturbation"] != "channel")
    assert main(["analyze", str(tmp_path / "run.json"), "--out", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "run.trials.csv").read_bytes() == (tmp_path / "run" / "trials.csv").read_bytes()
    capsys.readouterr()
    assert main(["analyze", str(tmp_path / "run.json"), "--out", str(tmp_path / "fit"), "--fit", "two-rate"]) == 0
    out = capsys.readouterr().out
    assert "two-rate fit to max_perpendicular_error_m (14 trials)" in out and "A_s = " in out and "R^2" in out
    assert " cm over 14 trials" in out and " cm per unit of field" in out  # a student reads cm
    assert (tmp_path / "fit" / "run.fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # Beside the figure, the fit as a file: each rate with its interval, the residual in the data's unit, R^2.
    kept = json.loads((tmp_path / "fit" / "run.fit.json").read_text())
    assert kept["measure"] == "max_perpendicular_error_m" and kept["trials"] == 14 and kept["residual_unit"] == "m"
    assert set(kept["parameters"]) == {"A_f", "A_s", "B_f", "B_s", "k"} and kept["gain_unit"] == "m per unit of field"
    a_s = kept["parameters"]["A_s"]
    assert f"A_s = {a_s['value']:.4g}  (95% CI {a_s['ci95_low']:.4g} to {a_s['ci95_high']:.4g})" in out
    assert f"rms {100 * kept['residual_rms']:.4g} cm" in out and f"R^2 = {kept['r_squared']:.3f}" in out
    # Without --out the fit is printed, and nothing is written.
    before = sorted(tmp_path.rglob("*"))
    assert main(["analyze", str(tmp_path / "run.json"), "--fit", "two-rate"]) == 0
    assert f"A_s = {a_s['value']:.4g}" in capsys.readouterr().out and sorted(tmp_path.rglob("*")) == before
    # 5 channel trials cannot pin four rates: one line saying so, the replay left out.
    assert main(["analyze", str(tmp_path / "run.json"), "--out", str(tmp_path / "fit"), "--fit", "two-rate",
                 "--fit-on", "index", "--no-figures", "--force"]) == 2
    err = capsys.readouterr().err
    assert "cannot fit the two-rate model to its adaptation_index: 5 trials with a value" in err


@pytest.mark.parametrize("argv, message", [
    (["analyze", "r.json", "--out", "x.csv", "--fit-on", "index"], "--fit-on applies with --fit only"),
    (["analyze", "r.json", "--out", "x.csv", "--no-figures"], "--no-figures applies with --class or --fit only"),
])
def test_fit_argument_errors_are_one_line(argv, message, capsys, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err
    with pytest.raises(SystemExit):  # argparse's own one line for a model it does not know
        main(["analyze", "r.json", "--out", "x.csv", "--fit", "three-rate"])
    assert "invalid choice: 'three-rate'" in capsys.readouterr().err
