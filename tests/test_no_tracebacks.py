"""Inputs that gave a traceback or ran on (issue 16, class 8): each is now one line and a non-zero
exit, refused before any work."""

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest

from armgame.cli import main


@pytest.fixture
def deep_toml(tmp_path):
    path = tmp_path / "deep.toml"
    path.write_text("keys = " + "[" * 20_000 + "]" * 20_000 + "\n")  # 40 KB: under the size limits
    return path


def one_line(capsys, argv) -> str:
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    return err


def test_deeply_nested_toml_settings_and_protocol(capsys, deep_toml, tmp_path):
    assert "nested too deeply" in one_line(capsys, ["settings", "--settings", deep_toml])
    assert "nested too deeply" in one_line(capsys, ["lab", deep_toml, "--headless", "--bot", "adaptive",
                                                    "--out", tmp_path / "o"])


@pytest.mark.parametrize("argv", [
    ["settings", "--settings", "~nosuchuser/s.toml"],
    ["analyze", "x.json", "--out", "~nosuchuser/o.csv"],
    ["demo", "passive", "--headless", "--out", "~nosuchuser/o"],
])
def test_no_such_users_home(capsys, argv):
    assert "no such user's home folder" in one_line(capsys, argv)


@pytest.mark.parametrize(("argv", "message"), [
    (["demo", "passive", "--headless", "--duration", "1e308"], "more than a demo runs"),
    (["demo", "chaos", "--headless", "--duration", "1e6"], "more than a demo runs"),
    (["demo", "passive", "--headless", "--dt", "1e-12"], "--dt must be from"),
    (["demo", "passive", "--headless", "--dt", "1e-5", "--duration", "1e3"], "more than a demo runs"),
])
def test_demo_work_is_bounded_before_it_starts(capsys, tmp_path, argv, message):
    assert message in one_line(capsys, [*argv, "--out", tmp_path / "o"])
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(("argv", "message"), [
    (["derive", "one", "--states", "1000000000"], "--states must be from 1 to"),
    (["derive", "one", "--seed", "-5"], "--seed must be"),
])
def test_derive_arguments_are_bounded(capsys, argv, message):
    pytest.importorskip("sympy")
    assert message in one_line(capsys, argv)


def test_demo_out_expands_the_home_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.chdir(tmp_path)
    assert main(["demo", "pendulum", "--headless", "--no-figures", "--duration", "0.05", "--out", "~/x"]) == 0
    assert (tmp_path / "home" / "x" / "pendulum.csv").is_file() and not (tmp_path / "~").exists()


def test_a_vector_env_too_big_for_memory_says_its_estimate_before_allocating():
    from armgame.env.reach import EnvArgumentError
    from armgame.env.vector import MAX_ENVS, ReachVectorEnv

    with pytest.raises(EnvArgumentError, match=r"about 5\.7 GiB \(6 KiB a game\).*at most 349,525 games"):
        ReachVectorEnv(1_000_000)
    assert MAX_ENVS * 6 * 1024 <= 2 * 1024**3
