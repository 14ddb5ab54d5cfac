"""The words armgame prints: plurals from one helper, and command-line errors that name the command."""

import doctest
import subprocess
import sys

import pytest

from armgame import words
from armgame.cli import build_parser, main
from armgame.words import plural


def test_words_doctests():
    result = doctest.testmod(words)
    assert result.attempted >= 3 and result.failed == 0


@pytest.mark.parametrize(
    ("count", "noun", "expected"),
    [(1, "hit", "1 hit"), (0, "hit", "0 hits"), (2, "hit", "2 hits"), (1, "entry", "1 entry"),
     (5, "entry", "5 entries"), (1, "reset", "1 reset"), (-1, "reset", "-1 resets"), (2, "key", "2 keys"),
     (2, "valid entry", "2 valid entries"), (3, "match", "3 matches"), (4, "child", "4 children")],
)
def test_plural(count, noun, expected):
    assert plural(count, noun, "children" if noun == "child" else None) == expected


def test_the_autopilot_summary_says_min_ratio():
    from armgame.demos.autopilot import Row, format_table

    text = format_table([Row(0, {"model": 50, "naive": 1}), Row(1, {"model": 1, "naive": 20})], 60.0)
    last = text.splitlines()[-1].split()
    assert last[:3] == ["all", "51", "21"] and last[-2:] == ["(min", "ratio)"]
    assert float(last[3]) == pytest.approx(0.05)


def test_simulate_one_row_is_singular(tmp_path, capsys):
    out = tmp_path / "x.csv"
    assert main(["simulate", "--scene", "pendulum", "--duration", "0.001", "--sample-rate", "1",
                 "--out", str(out)]) == 0
    assert "pendulum: 1 row to" in capsys.readouterr().out


def test_a_negative_option_value_gets_a_hint(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["simulate", "--scene", "passive", "--out", "x.csv", "--initial", "-60,0"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("armgame simulate: error: argument --initial: expected one argument")
    assert "--initial=-60,0" in err and err.count("\n") == 1


def test_the_hinted_form_works(tmp_path, capsys):
    out = tmp_path / "x.csv"
    assert main(["simulate", "--scene", "passive", "--duration", "0.01", f"--out={out}", "--initial=-60,0"]) == 0
    assert out.read_text().splitlines()[1].split(",")[1] == repr(-1.0471975511965976)  # -60 deg in rad


def test_a_missing_value_at_the_end_gets_no_hint(capsys):
    with pytest.raises(SystemExit):
        main(["simulate", "--scene", "passive", "--out"])
    err = capsys.readouterr().err
    assert err == "armgame simulate: error: argument --out: expected one argument\n"


@pytest.mark.parametrize("command", list(build_parser().get_default("_commands")))
def test_every_commands_parse_errors_name_it(command, capsys):
    # An unknown option is left over by the command's own parser; argparse would blame "armgame".
    with pytest.raises(SystemExit) as stop:
        main([command, "--no-such-option"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"armgame {command}: error: ") and err.count("\n") == 1


@pytest.mark.parametrize(
    ("args", "message"),
    [(["demo", "nosuch"], "argument NAME: invalid choice"),
     (["demo", "chaos", "--dt", "x"], "argument --dt: invalid float value"),
     (["bench", "--cases", "nope"], "unknown case 'nope'"),
     (["demo", "pendulum", "--bogus", "1"], "unrecognized arguments: --bogus 1")],
)
def test_subcommand_argparse_errors_name_the_subcommand(args, message, capsys):
    with pytest.raises(SystemExit):
        main(args)
    err = capsys.readouterr().err
    assert err.startswith(f"armgame {args[0]}: error: ") and message in err


def test_errors_outside_any_command_name_armgame(capsys):
    with pytest.raises(SystemExit):
        main(["--bogus"])
    assert capsys.readouterr().err == "armgame: error: unrecognized arguments: --bogus\n"


def test_user_errors_name_the_command_in_a_subprocess(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "armgame", "demo", "chaos", "--headless"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.startswith("armgame demo: error: --headless needs --out DIR")
