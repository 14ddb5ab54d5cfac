"""armgame simulate, end to end through the command line."""

import csv
import subprocess
import sys
import warnings

import numpy as np
import pytest

from armgame.cli import main


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


def test_passive_scene_csv(tmp_path):
    out = tmp_path / "passive.csv"
    assert main(["simulate", "--scene", "passive", "--duration", "1", "--out", str(out)]) == 0
    header, data = read_csv(out)
    assert header == ["t", "q1", "q2", "qd1", "qd2", "hand_x", "hand_y", "tau1", "tau2", "energy"]
    np.testing.assert_allclose(data[0, 5:7], [0.4554, -0.3384], atol=1e-12)
    assert data[-1, 0] == pytest.approx(1.0)
    assert len(data) == 201  # 200 Hz by default
    assert np.ptp(data[:, -1]) / abs(data[0, -1]) < 1e-9


def test_pendulum_with_reference_solver_and_initial_state(tmp_path):
    out = tmp_path / "pendulum.csv"
    code = main(["simulate", "--scene", "pendulum", "--integrator", "dop853", "--duration", "2",
                 "--initial=-60,0", "--out", str(out)])
    assert code == 0
    header, data = read_csv(out)
    assert header == ["t", "q1", "qd1", "hand_x", "hand_y", "tau1", "energy"]
    assert data[0, 1] == pytest.approx(np.radians(-60))


def test_fixed_step_matches_reference_in_csv(tmp_path):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    main(["simulate", "--scene", "passive", "--integrator", "gauss4", "--dt", "0.002", "--duration", "2",
          "--out", str(a)])
    main(["simulate", "--scene", "passive", "--integrator", "dop853", "--dt", "0.002", "--duration", "2",
          "--out", str(b)])
    _, x = read_csv(a)
    _, y = read_csv(b)
    assert x.shape == y.shape
    assert np.max(np.abs(x[:, 5:7] - y[:, 5:7])) < 1e-8


def in_process(capsys, argv):
    """``armgame`` on ``argv`` in this process, as a subprocess would see it: the exit code (argparse's
    own exit included), stdout, and stderr with any warning Python would print there (a subprocess shows them;
    pytest would otherwise collect them out of sight). A traceback fails the test by itself."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code
    out, err = capsys.readouterr()
    return code, out, err + "".join(f"{w.category.__name__}: {w.message}\n" for w in caught)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--scene", "nope"], "unknown scene"),
        (["--scene", "passive", "--dt", "-0.1"], "--dt"),
        (["--scene", "passive", "--duration", "-5"], "--duration"),
        (["--scene", "passive", "--duration", "nan"], "--duration"),
        (["--scene", "passive", "--integrator", "leapfrog"], "unknown integrator"),
        (["--scene", "passive", "--initial", "1,2,3"], "--initial"),
        (["--scene", "passive", "--dt", "abc"], "--dt"),
        (["--scene", "stiff", "--integrator", "euler", "--dt", "0.03"], "blew up"),
        (["--scene", "propeller", "--integrator", "gauss4", "--dt", "0.03"], "blew up"),
    ],
)
def test_bad_arguments_give_one_line_and_nonzero_exit(tmp_path, args, message, capsys):
    out = tmp_path / "x.csv"
    code, _, err = in_process(capsys, ["simulate", *args, "--out", str(out)])
    assert code not in (0, None)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], err
    assert not out.exists()


def test_unwritable_output_is_reported(tmp_path, capsys):
    code, _, err = in_process(capsys, ["simulate", "--scene", "passive", "--duration", "0.1",
                                    "--out", str(tmp_path / "missing" / "x.csv")])
    assert code == 2 and "does not exist" in err


def test_help_imports_no_heavy_package():
    code = ("import sys, armgame.cli as c\n"
            "try:\n    c.main(['--help'])\nexcept SystemExit:\n    pass\n"
            "print(sorted(m for m in ('numpy', 'scipy', 'pygame') if m in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.stdout.strip().splitlines()[-1] == "[]"


def test_simulate_imports_scipy_only_for_the_reference_solver():
    """scipy.integrate costs about half a second to import: a fixed-step run must not pay it."""
    code = ("import sys, armgame.simulation, armgame.physics.reference; "
            "assert 'scipy.integrate' not in sys.modules, 'imported scipy.integrate'")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
