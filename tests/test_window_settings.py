"""Window settings (TOML, hostile files refused in one line), sounds (optional, never the mixer headless),
the shared window options, and a window command where there is no display."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from armgame.cli import main
from armgame.ui.settings import Settings, SettingsError, default_path, load, save

REPO = Path(__file__).resolve().parents[1]


def test_defaults_when_there_is_no_file(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    settings, path = load()
    assert settings == Settings() and path == tmp_path / "armgame" / "settings.toml"
    monkeypatch.setenv("XDG_CONFIG_HOME", "relative/ignored")  # the XDG spec: relative paths are invalid
    assert default_path() == Path.home() / ".config" / "armgame" / "settings.toml"


def test_round_trip_and_atomic_rewrite(tmp_path):
    path = tmp_path / "cfg" / "settings.toml"
    wanted = Settings(keys="asdf", mute=True, palette="classic", size=(1366, 768))
    save(wanted, path)
    assert load(path) == (wanted, path)
    assert not [p for p in path.parent.iterdir() if p.name != "settings.toml"]  # no temporary file left
    save(wanted.with_changes(mute=False), path)
    assert load(path)[0].mute is False


@pytest.mark.parametrize(("text", "named"), [
    ('keys = "dfj"', "keys"),
    ('keys = "ddjk"', "keys"),
    ('keys = "dfjp"', "keys"),
    ("keys = 4", "keys"),
    ("mute = 1", "mute"),
    ('palette = "rainbow"', "palette"),
    ('size = "10x10"', "size"),
    ('size = "wide"', "size"),
    ("size = [1280, 720]", "size"),
    ('colour = "red"', "colour"),
    ("mute = = true", "TOML"),
])
def test_a_malformed_file_is_refused_naming_the_key(tmp_path, text, named, capsys):
    path = tmp_path / "settings.toml"
    path.write_text(text + "\n")
    with pytest.raises(SettingsError, match=named):
        load(path)
    assert main(["settings", "--settings", str(path)]) == 2
    err = capsys.readouterr().err
    assert named in err and err.count("\n") == 1 and str(path) in err


def test_hostile_files_are_refused_without_reading_them(tmp_path):
    secret = tmp_path / "elsewhere.toml"
    secret.write_text('keys = "asdf"\n')
    link = tmp_path / "link.toml"
    link.symlink_to(secret)
    with pytest.raises(SettingsError, match="symbolic link"):
        load(link)
    with pytest.raises(SettingsError, match="symbolic link"):
        save(Settings(), link)  # and never written through
    assert secret.read_text() == 'keys = "asdf"\n'
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    reads = []  # counted, not timed: refused before a byte is read (a FIFO's read waits for a writer)
    real_fdopen = os.fdopen
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(os, "fdopen", lambda *a, **k: reads.append(a) or real_fdopen(*a, **k))
        with pytest.raises(SettingsError, match="not a regular file"):
            load(fifo)  # would block for ever if it were opened
    assert reads == []
    with pytest.raises(SettingsError, match="not a regular file"):
        load(tmp_path)
    huge = tmp_path / "huge.toml"
    huge.write_bytes(b"#" * (10 * 1024 * 1024))
    with pytest.raises(SettingsError, match="too large"):
        load(huge)
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(SettingsError, match="UTF-8"):
        load(binary)


def test_settings_command_prints_path_and_values(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    assert main(["settings"]) == 0
    out = capsys.readouterr().out
    assert str(tmp_path / "armgame" / "settings.toml") in out and "no file yet" in out and "keys = dfjk" in out
    save(Settings(keys="a,s,d,f", size=(1280, 720)), tmp_path / "armgame" / "settings.toml")
    assert main(["settings"]) == 0
    out = capsys.readouterr().out
    assert "keys = a,s,d,f" in out and "size = 1280x720" in out and "no file yet" not in out


def test_window_options_are_shared_and_checked(capsys):
    from armgame.cli import build_parser

    parser = build_parser()
    for command in (["play"], ["play", "--bot", "model"], ["replay", "x.json"], ["demo", "chaos"],
                    ["demo", "autopilot"]):
        args = parser.parse_args([*command, "--size", "1280x720", "--fullscreen", "--settings", "s.toml"])
        assert args.size == (1280, 720) and args.fullscreen and args.settings == "s.toml"
    with pytest.raises(SystemExit):
        parser.parse_args(["play", "--size", "12x12"])
    assert "--size" in capsys.readouterr().err


def test_headless_play_ignores_the_settings_keys(tmp_path, monkeypatch, capsys):
    """A script's keys and so its result must not depend on who runs it."""
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    save(Settings(keys="asdf"), tmp_path / "armgame" / "settings.toml")
    script = tmp_path / "s.txt"
    script.write_text("0.0 d down\n0.5 d up\n")
    assert main(["play", "--headless", "--script", str(script), "--duration", "2", "--json"]) == 0
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "none"))
    first = capsys.readouterr().out
    assert main(["play", "--headless", "--script", str(script), "--duration", "2", "--json"]) == 0
    assert capsys.readouterr().out == first


# ------------------------------------------------------------------------------------------ sounds
def test_sound_files_are_made_by_the_committed_script(tmp_path):
    sys.path.insert(0, str(REPO / "assets"))
    try:
        import make_sounds
    finally:
        sys.path.pop(0)
    for path in make_sounds.main(tmp_path):
        committed = REPO / "assets" / path.name
        assert path.read_bytes() == committed.read_bytes(), path.name  # deterministic, and up to date
        assert 1000 < len(committed.read_bytes()) < 64 * 1024


def test_headless_runs_never_start_the_mixer(tmp_path):
    # As Gymnasium's test_pygame_selective_init: nothing headless may initialise pygame's audio.
    code = (
        "import sys\n"
        "from armgame.cli import main\n"
        "assert main(['play', '--headless', '--duration', '1']) == 0\n"
        "assert main(['play', '--headless', '--bot', 'naive', '--duration', '1']) == 0\n"
        f"assert main(['demo', 'chaos', '--headless', '--out', {str(tmp_path)!r}, '--duration', '0.1',"
        " '--no-figures']) == 0\n"
        "mixer = sys.modules.get('pygame.mixer')\n"
        "assert mixer is None or not mixer.get_init(), 'mixer started'\n"
        "assert 'armgame.ui.sound' not in sys.modules\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                         env={**os.environ, "ARMGAME_SCORES": str(tmp_path / "scores")})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().endswith("ok")


def test_a_mixer_that_cannot_open_is_not_fatal():
    code = (
        "import os\n"
        "os.environ['SDL_AUDIODRIVER'] = 'no-such-driver'\n"
        "from armgame.ui.sound import Sounds\n"
        "s = Sounds()\n"
        "assert not s.available\n"
        "s.play('hit'); s.toggle(); s.play('hit'); s.close()\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_sounds_load_and_mute_under_the_dummy_driver(tmp_path):
    code = (
        "import os\n"
        "os.environ['SDL_AUDIODRIVER'] = 'dummy'\n"
        "from armgame.ui.sound import SOUND_NAMES, Sounds\n"
        "s = Sounds(muted=True)\n"
        "assert s.available and set(s.sounds) == set(SOUND_NAMES), s.sounds\n"
        "assert s.toggle() is False\n"
        "s.play('hit'); s.close()\n"
        "import pygame\n"
        "assert not pygame.mixer.get_init()\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_the_sounds_are_found_in_a_checkout_or_where_a_wheel_installs_them(tmp_path):
    from armgame.ui.sound import SOUND_NAMES, asset_folder

    checkout, installed = tmp_path / "checkout", tmp_path / "share" / "armgame" / "assets"
    installed.mkdir(parents=True)
    for name in SOUND_NAMES:
        (installed / f"{name}.wav").write_bytes(b"RIFF")
    assert asset_folder((checkout, installed)) == installed  # a wheel: no checkout beside the package
    checkout.mkdir()
    (checkout / "hit.wav").write_bytes(b"RIFF")
    assert asset_folder((checkout, installed)) == checkout
    assert asset_folder((tmp_path / "none", tmp_path / "neither")) == tmp_path / "none"  # silence
    assert (asset_folder() / "hit.wav").is_file()  # this checkout's own


def test_mute_in_the_window_is_written_to_the_settings(tmp_path):
    path = tmp_path / "settings.toml"
    code = (
        "import os\n"
        "os.environ['SDL_VIDEODRIVER'] = 'dummy'; os.environ['SDL_AUDIODRIVER'] = 'dummy'\n"
        "import pygame\n"
        "from armgame.game.rules import GameConfig\n"
        "from armgame.game.session import GameSession\n"
        "from armgame.ui.frontend import play_window\n"
        "from armgame.ui.settings import Settings\n"
        "from pathlib import Path\n"
        "pygame.display.init()\n"
        "real_open = pygame.display.set_mode\n"
        "def events(*a, **k):\n"
        "    s = real_open(*a, **k)\n"
        "    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_m))\n"
        "    pygame.event.post(pygame.event.Event(pygame.QUIT))\n"
        "    return s\n"
        "pygame.display.set_mode = events\n"
        f"w = play_window(GameSession(GameConfig()), Settings(size=(800, 600)), Path({str(path)!r}))\n"
        "print(w.sounds.muted)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "True"
    assert load(path)[0] == Settings(mute=True)  # the size came from the command line, not the file


# ---------------------------------------------------------------------------------- no display
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SDL's display probing is Linux's here")
@pytest.mark.parametrize("command", [["play"], ["play", "--bot", "model"], ["demo", "chaos"], ["demo", "autopilot"]])
def test_a_window_with_no_display_is_one_line_and_never_waits(command, tmp_path):
    # No stopwatch (a shared machine's load decides it): a window that waited on an invisible display
    # would run into the timeout, which is the failure this guards against.
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    env["XDG_CONFIG_HOME"] = str(tmp_path)
    out = subprocess.run([sys.executable, "-m", "armgame", *command], capture_output=True, text=True, env=env,
                         timeout=60)
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1 and "--headless" in out.stderr, out.stderr


def test_a_window_takes_its_keys_and_size_from_the_settings_unless_told(tmp_path):
    from armgame.cli import build_parser
    from armgame.commands.play import _window_settings, game_config

    path = tmp_path / "settings.toml"
    save(Settings(keys="asdf", size=(1024, 700), mute=True), path)
    args = build_parser().parse_args(["play", "--settings", str(path)])
    settings, _ = _window_settings(args)
    assert game_config(args).muscles[0].key == "a" and settings.size == (1024, 700) and settings.mute
    args = build_parser().parse_args(["play", "--settings", str(path), "--keys", "hjkl", "--size", "800x600"])
    settings, _ = _window_settings(args)
    assert game_config(args).muscles[0].key == "h" and settings.size == (800, 600)


def test_the_clock_reads_the_same_way_all_game():
    from armgame.ui.render import clock_text

    assert clock_text(60.0) == "60.0" and clock_text(9.3) == " 9.3" and clock_text(99.9) == "99.9"
    assert clock_text(120.0) == "2:00" and clock_text(100.01) == "1:41"


def test_the_end_screen_callback_keeps_the_game_once_and_ranks_it(tmp_path, capsys):
    """commands/play.py hands the window a callback; the window never touches the score files itself."""
    from armgame.cli import build_parser
    from armgame.commands.play import _keep, _standing, game_config
    from armgame.game.session import GameSession
    from armgame.records.scores import ScoreTable

    def finished_game(args, key="d"):
        session = GameSession(game_config(args))
        session.key_event(key, "down")
        session.advance(session.total_steps)
        return session

    parser = build_parser()
    scores = tmp_path / "scores"
    earlier = parser.parse_args(["play", "--duration", "1", "--scores", str(scores), "--name", "Bob"])
    _keep(finished_game(earlier), earlier)
    args = parser.parse_args(["play", "--duration", "1", "--scores", str(scores)])
    session = finished_game(args, "f")  # Ann's own game: Bob's again would be refused (a game enters once)
    standing = _standing(session, args)("Ann")
    assert args.kept and args.name == "Ann"
    assert standing.entries == 2 and standing.rank in (1, 2)
    assert sorted(name for _, name, _ in standing.top) == ["Ann", "Bob"]
    assert [e.name for e in ScoreTable(scores).all_entries()].count("Ann") == 1  # a 1 s game: custom
    assert "saved to the high-score table as Ann" in capsys.readouterr().out
    # No name (Esc on the prompt is another path): the table is shown, nothing is entered.
    args = parser.parse_args(["play", "--duration", "1", "--scores", str(scores)])
    standing = _standing(finished_game(args), args)(None)
    assert standing.rank is None and standing.entries == 2
    # A table that cannot be written is one line on stderr, and the end screen goes on without it.
    not_a_folder = tmp_path / "not-a-folder"
    not_a_folder.write_text("x")
    args = parser.parse_args(["play", "--duration", "1", "--scores", str(not_a_folder)])
    assert _standing(finished_game(args), args)("Cleo") is None
    assert capsys.readouterr().err.count("armgame play: error:") == 1


def test_a_window_game_quit_early_keeps_its_replay_to_watch(tmp_path, capsys):
    """Esc during the game: nothing is entered, nothing is lost, and the line says how to watch it."""
    from armgame.cli import build_parser, main
    from armgame.commands.play import _keep, game_config
    from armgame.game.session import GameSession
    from armgame.records.scores import ScoreTable

    args = build_parser().parse_args(["play", "--scores", str(tmp_path / "scores"), "--name", "Ann"])
    session = GameSession(game_config(args))
    session.key_event("d", "down")
    session.advance(round(1.0 / session.config.dt))
    assert _keep(session, args) is None
    out = capsys.readouterr().out
    table = ScoreTable(tmp_path / "scores")
    (kept,) = table.replays.iterdir()
    assert table.all_entries() == [] and f"armgame replay {kept} watches it" in out and "stopped at 1.0 s" in out
    assert main(["replay", str(kept), "--headless"]) == 0
    assert "stopped at 1.0 s" not in capsys.readouterr().err
