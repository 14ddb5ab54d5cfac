"""Clean failures at the edge: where no window can be opened, one line and a command that runs
without one; a mistyped name answered with the closest valid one."""

import os
import shlex
import subprocess
import sys

import pytest

import armgame.ui.display
from armgame.cli import build_parser, main
from armgame.errors import NoDisplayError
from armgame.words import closest, unknown_name

TINY_PROTOCOL = """
name = "tiny"
targets = 2
timeout = 0.5

[[blocks]]
name = "baseline"
trials = 1

[[blocks]]
name = "exposure"
trials = 1
perturbation = "curl"
b = 2.0
"""

SUGGESTION = "; run it without one: "


def suggested(err: str, command: str) -> list[str]:
    """The command line the one error line suggests, checked to be armgame's own."""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"armgame {command}: error: cannot open a window") and SUGGESTION in lines[0]
    parts = shlex.split(lines[0].split(SUGGESTION, 1)[1])
    assert parts[:2] == ["armgame", command]
    return parts[1:]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="X11 and Wayland are Linux's")
@pytest.mark.parametrize("command", ["play", "lab"])
def test_no_display_gets_one_line_and_a_command_that_runs(command, tmp_path, monkeypatch):
    """A DISPLAY whose server is gone, no XDG_RUNTIME_DIR: SDL's probing used to print first."""
    (tmp_path / "tiny.toml").write_text(TINY_PROTOCOL)
    argv = {"play": ["play", "--duration", "1"], "lab": ["lab", "tiny.toml"]}[command]
    env = {k: v for k, v in os.environ.items()
           if k not in ("SDL_VIDEODRIVER", "WAYLAND_DISPLAY", "XDG_RUNTIME_DIR")} | {"DISPLAY": ":9999"}
    run = subprocess.run([sys.executable, "-m", "armgame", *argv], capture_output=True, text=True, env=env,
                         cwd=tmp_path, timeout=60)
    assert run.returncode == 2 and run.stdout == ""
    again = suggested(run.stderr, command)
    assert "--headless" in again and ("--bot" in again)
    monkeypatch.chdir(tmp_path)
    assert main(again) == 0


@pytest.fixture
def no_display(monkeypatch):
    def refuse() -> None:
        raise NoDisplayError("cannot open a window (no display: SDL chose its invisible 'offscreen' driver)")

    monkeypatch.setattr(armgame.ui.display, "init_display", refuse)


def test_the_replay_suggestion_runs(no_display, tmp_path, capsys):
    replay = tmp_path / "game one.json"  # a space: the suggestion is quoted for the shell
    assert main(["play", "--headless", "--duration", "1", "--record", str(replay)]) == 0
    capsys.readouterr()
    assert main(["replay", str(replay), "--fps", "30"]) == 2
    again = suggested(capsys.readouterr().err, "replay")
    assert again == ["replay", str(replay), "--fps", "30", "--headless"]
    assert main(again) == 0 and "as recorded" in capsys.readouterr().out


def test_the_lab_keeps_a_chosen_bot_and_adds_the_adaptive_one_otherwise(no_display, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tiny.toml").write_text(TINY_PROTOCOL)
    assert main(["lab", "tiny.toml"]) == 2
    assert suggested(capsys.readouterr().err, "lab") == ["lab", "tiny.toml", "--headless", "--bot", "adaptive"]
    assert main(["lab", "tiny.toml", "--bot", "naive"]) == 2
    again = suggested(capsys.readouterr().err, "lab")
    assert again == ["lab", "tiny.toml", "--bot", "naive", "--headless"]
    assert main(again) == 0


@pytest.mark.parametrize("name, added", [("chaos", ["--headless", "--out", "chaos"]),
                                         ("autopilot", ["--headless"])])
def test_the_demo_suggestion_writes_to_a_folder_named_after_it(no_display, name, added, capsys):
    assert main(["demo", name, "--speed", "2"]) == 2
    again = suggested(capsys.readouterr().err, "demo")
    assert again == ["demo", name, "--speed", "2", *added]
    # Running it draws a figure (seconds): parsing it as the command line does is enough here.
    args = build_parser().parse_args(again)
    assert args.headless and args.out == (None if name == "autopilot" else name)


@pytest.mark.parametrize("argv, meant", [
    (["pley"], "play"),
    (["demo", "chaso"], "chaos"),
    (["derive", "tow"], "two"),
    (["bench", "--cases", "pasive"], "passive"),
])
def test_a_mistyped_name_argparse_checks_gets_the_closest(argv, meant, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1 and f"did you mean {meant}?" in err


@pytest.mark.parametrize("argv, meant", [
    (["lab", "crul"], "curl"),
    (["lab", "curl", "--headless", "--bot", "adaptve"], "adaptive"),
    (["play", "--headless", "--bot", "modle", "--duration", "1"], "model"),
    (["simulate", "--scene", "pasive", "--out", "x.csv"], "passive"),
    (["simulate", "--scene", "passive", "--integrator", "rk5", "--out", "x.csv"], "rk4"),
    (["demo", "pendulum", "--headless", "--out", "d", "--integrator", "eluer"], "euler"),
])
def test_a_mistyped_name_gets_the_closest_in_one_line(argv, meant, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"armgame {argv[0]}: error: ") and err.count("\n") == 1
    assert f"did you mean {meant}?" in err
    assert not any(tmp_path.iterdir())  # refused before anything was written


def test_a_name_close_to_nothing_lists_the_choices_only(capsys):
    assert main(["lab", "spiral"]) == 2
    err = capsys.readouterr().err
    assert "did you mean" not in err and "choose one of lesson, null, curl" in err and err.count("\n") == 1
    with pytest.raises(SystemExit):
        main(["xyzzy"])
    err = capsys.readouterr().err
    assert "did you mean" not in err and "invalid choice: 'xyzzy'" in err


def test_closest_ignores_case_and_keeps_the_valid_spelling():
    assert closest("PLEY", ("play", "replay")) == "play"
    assert closest("q", ("play", "replay")) is None
    assert unknown_name("bot", "Model", ("model", "naive")) == \
        "unknown bot 'Model': did you mean model? (choose one of model, naive)"


def test_what_sdl_prints_while_starting_is_shown_only_if_a_window_opens(capfd, monkeypatch):
    import pygame

    noise = "error: XDG_RUNTIME_DIR is invalid or not set in the environment.\n"
    real_init = pygame.display.init

    def noisy_init() -> None:
        os.write(2, noise.encode())  # as libwayland does, below Python's sys.stderr
        real_init()

    monkeypatch.setattr(pygame.display, "init", noisy_init)
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    armgame.ui.display.init_display()  # the driver asked for by name: a window may open
    pygame.display.quit()
    assert capfd.readouterr().err == noise
    monkeypatch.setattr(pygame.display, "get_driver", lambda: "offscreen")  # SDL's own invisible fallback
    with pytest.raises(NoDisplayError, match="invisible 'offscreen' driver"):
        armgame.ui.display.init_display()
    assert capfd.readouterr().err == ""
