"""Per-reach metrics on synthetic reaches whose values are known in closed form, and the trials table."""

import doctest
import math
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from armgame.errors import UserError
from armgame.lab import metrics
from armgame.lab.metrics import (
    TRIAL_COLUMNS,
    Reach,
    ReachMetrics,
    TrialsFileError,
    reach_metrics,
    read_trials_csv,
    write_trials_csv,
)
from armgame.lab.protocol import FEEDBACK

DT = 0.001
D = 0.10        # reach distance (m)
T = 0.5         # movement duration (s)
GO = 0.2        # go cue (s)
START = 0.35    # when the minimum-jerk movement starts (s)
HOME = np.array([0.05, 0.40])
# Onset and end come from sampled speeds (central differences, error dt^2/6 |x'''|) crossing the
# threshold between samples (linear interpolation, error up to dt^2/8 |v''/v'|): together under
# 1e-5 s at dt = 1 ms on these reaches, so 2e-5 s, one fiftieth of a sample, bounds them.
SAMPLED = 2e-5

# Where the minimum-jerk speed 30 s^2 (1 - s)^2 (D/T) crosses 5% of its peak 1.875 D/T:
# s (1 - s) = sqrt(0.05 * 1.875 / 30), the smaller root.
S5 = (1.0 - math.sqrt(1.0 - 4.0 * math.sqrt(0.05 * 1.875 / 30.0))) / 2.0


def progress(s):
    s = np.clip(s, 0.0, 1.0)
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def unit(deg):
    return np.array([math.cos(math.radians(deg)), math.sin(math.radians(deg))])


def left_of(deg):
    return unit(deg + 90.0)


def make_reach(path_of_progress, target_deg=30.0, start_at=START, duration=1.2):
    t = np.arange(0.0, duration + DT / 2, DT)
    hand = path_of_progress(progress((t - start_at) / T))
    return Reach(t=t, hand=hand, start=tuple(HOME), target=tuple(HOME + D * unit(target_deg)), go_time=GO, hit=True)


def straight(deg, distance=D):
    return lambda p: HOME + np.outer(p, distance * unit(deg))


def test_straight_minimum_jerk_reach():
    m = reach_metrics(make_reach(straight(30.0)))
    assert m.peak_speed_m_per_s == pytest.approx(1.875 * D / T, rel=2e-5)  # central differences: -dt^2/6 |x'''|
    assert m.reaction_time_s == pytest.approx(START - GO + S5 * T, abs=SAMPLED)
    assert m.movement_time_s == pytest.approx((1.0 - 2.0 * S5) * T, abs=SAMPLED)
    assert m.initial_direction_error_deg == pytest.approx(0.0, abs=1e-9)
    assert m.max_perpendicular_error_m == pytest.approx(0.0, abs=1e-15)
    assert m.path_length_ratio == pytest.approx(1.0, abs=1e-12)


def test_thresholds_move_onset_and_end_as_the_speed_profile_says():
    m = reach_metrics(make_reach(straight(0.0)), threshold=0.2)
    s = (1.0 - math.sqrt(1.0 - 4.0 * math.sqrt(0.2 * 1.875 / 30.0))) / 2.0
    assert m.reaction_time_s == pytest.approx(START - GO + s * T, abs=SAMPLED)
    assert m.movement_time_s == pytest.approx((1.0 - 2.0 * s) * T, abs=SAMPLED)


@pytest.mark.parametrize("angle", [25.0, -25.0, 90.0, -150.0])
@pytest.mark.parametrize("direction_at", ["delay", "peak_acceleration"])
def test_rotated_path_gives_the_rotation_with_its_sign(angle, direction_at):
    target_deg = 30.0
    m = reach_metrics(make_reach(straight(target_deg + angle), target_deg), direction_at=direction_at)
    assert m.initial_direction_error_deg == pytest.approx(angle, abs=1e-9)
    # The straight path ends (at the 5% threshold) a distance D p_end from home, rotated by angle.
    p_end = float(progress(1.0 - S5))
    assert m.max_perpendicular_error_m == pytest.approx(D * p_end * math.sin(math.radians(angle)), abs=1e-7)
    assert m.path_length_ratio == pytest.approx(1.0, abs=1e-12)
    assert m.peak_speed_m_per_s == pytest.approx(1.875 * D / T, rel=2e-5)  # central differences: -dt^2/6 |x'''|


def test_a_reach_the_wrong_way_reads_180_degrees():
    m = reach_metrics(make_reach(straight(30.0 + 180.0), 30.0))
    assert abs(m.initial_direction_error_deg) == pytest.approx(180.0, abs=1e-9)
    assert m.path_length_ratio == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("bump", [0.02, -0.015])
def test_sine_bump_path_has_its_known_deviation_length_and_initial_direction(bump):
    target_deg = 120.0
    u, n = unit(target_deg), left_of(target_deg)

    def curved(p):
        return HOME + np.outer(p, D * u) + np.outer(bump * np.sin(np.pi * p), n)

    reach = make_reach(curved, target_deg)
    m = reach_metrics(reach)
    assert m.max_perpendicular_error_m == pytest.approx(bump, abs=1e-9)

    # Onset and end: the speed is p'(t) |dhand/dp|, so its crossings are not those of the straight
    # reach; find them on a fine grid of the exact speed, then integrate the exact arc length.
    s = np.linspace(0.0, 1.0, 2_000_001)
    p = progress(s)
    dp = 30 * s**2 * (1 - s) ** 2
    speed = dp * np.hypot(D, bump * np.pi * np.cos(np.pi * p))
    above = np.flatnonzero(speed >= 0.05 * speed.max())
    p_on, p_end = p[above[0]], p[above[-1]]
    from scipy.integrate import quad  # here, not at collection: only the worker running it pays

    arc = quad(lambda q: math.hypot(D, bump * math.pi * math.cos(math.pi * q)), p_on, p_end, epsabs=1e-14)[0]
    chord = float(np.hypot(*(curved(np.array([p_end])) - curved(np.array([p_on])))[0]))
    assert m.path_length_ratio == pytest.approx(arc / chord, rel=1e-5)
    assert m.path_length_ratio > 1.0
    assert m.peak_speed_m_per_s == pytest.approx(speed.max() / T, rel=2e-5)

    # The hand 100 ms after onset, from where it was at onset, against the target direction.
    s_on = s[above[0]]
    p_dir = float(progress(s_on + 0.1 / T))
    moved = curved(np.array([p_dir]))[0] - curved(np.array([p_on]))[0]
    expected = math.degrees(math.atan2(moved @ n, moved @ u))
    assert m.initial_direction_error_deg == pytest.approx(expected, abs=0.02)
    assert math.copysign(1.0, m.initial_direction_error_deg) == math.copysign(1.0, bump)


def test_delayed_onset_shifts_only_the_reaction_time():
    early = reach_metrics(make_reach(straight(45.0), 45.0, start_at=0.30))
    late = reach_metrics(make_reach(straight(45.0), 45.0, start_at=0.55))
    assert late.reaction_time_s - early.reaction_time_s == pytest.approx(0.25, abs=1e-9)
    for name in ("movement_time_s", "peak_speed_m_per_s", "initial_direction_error_deg", "path_length_ratio"):
        assert getattr(late, name) == pytest.approx(getattr(early, name), abs=1e-9)


def test_movement_before_the_go_cue_is_a_negative_reaction_time():
    m = reach_metrics(make_reach(straight(0.0), 0.0, start_at=GO - 0.1))
    assert m.reaction_time_s == pytest.approx(-0.1 + S5 * T, abs=SAMPLED)


def test_resting_offset_does_not_bias_the_direction():
    offset = 0.004 * left_of(30.0)  # the hand rests 4 mm to the side of the home centre
    m = reach_metrics(make_reach(lambda p: straight(30.0)(p) + offset))
    assert m.initial_direction_error_deg == pytest.approx(0.0, abs=1e-9)
    assert m.max_perpendicular_error_m == pytest.approx(0.004, abs=1e-12)  # it is off the line, though


def test_a_corrective_submovement_after_the_primary_one_is_left_out():
    primary = straight(0.0, 0.8 * D)
    t = np.arange(0.0, 1.6 + DT / 2, DT)
    hand = primary(progress((t - START) / T)) + np.outer(progress((t - 1.0) / 0.3), 0.2 * D * left_of(0.0))
    m = reach_metrics(Reach(t, hand, tuple(HOME), tuple(HOME + D * unit(0.0)), GO, True))
    assert m.movement_time_s == pytest.approx((1.0 - 2.0 * S5) * T, abs=SAMPLED)
    assert m.max_perpendicular_error_m == pytest.approx(0.0, abs=1e-12)
    assert m.path_length_ratio == pytest.approx(1.0, abs=1e-12)


def test_a_reach_cut_off_mid_movement_ends_at_the_last_sample():
    m = reach_metrics(make_reach(straight(0.0), 0.0, duration=START + 0.7 * T))
    assert m.movement_time_s == pytest.approx(0.7 * T - S5 * T, abs=SAMPLED)
    assert math.isfinite(m.path_length_ratio)


def nan_or_value(m: ReachMetrics):
    return [v for v in m.as_dict().values() if not math.isnan(v)]


def test_no_movement_is_nan_except_the_peak_speed():
    t = np.arange(0.0, 1.0, DT)
    still = Reach(t, np.tile(HOME, (t.size, 1)), tuple(HOME), tuple(HOME + D * unit(0.0)), GO, False)
    m = reach_metrics(still)
    assert m.peak_speed_m_per_s == 0.0
    assert nan_or_value(m) == [0.0]
    jitter = Reach(t, HOME + 1e-6 * np.sin(50 * t)[:, None], tuple(HOME), tuple(HOME + D * unit(0.0)), GO, False)
    assert nan_or_value(reach_metrics(jitter)) == [pytest.approx(50e-6 * math.sqrt(2), rel=1e-2)]


@pytest.mark.parametrize("n", [0, 1])
def test_empty_and_single_sample_reaches_are_all_nan(n):
    m = reach_metrics(Reach(np.arange(n) * DT, np.zeros((n, 2)), (0.0, 0.0), (0.1, 0.0), 0.0, False))
    assert nan_or_value(m) == []


def test_records_ending_before_the_go_cue_or_holding_nan_are_all_nan():
    reach = make_reach(straight(0.0), 0.0)
    before = Reach(reach.t, reach.hand, reach.start, reach.target, go_time=10.0, hit=False)
    assert nan_or_value(reach_metrics(before)) == []
    hand = reach.hand.copy()
    hand[400] = np.nan
    assert nan_or_value(reach_metrics(Reach(reach.t, hand, reach.start, reach.target, GO, False))) == []


def test_target_on_home_leaves_the_directional_measures_undefined():
    reach = make_reach(straight(0.0), 0.0)
    m = reach_metrics(Reach(reach.t, reach.hand, reach.start, reach.start, GO, False))
    assert math.isnan(m.initial_direction_error_deg) and math.isnan(m.max_perpendicular_error_m)
    assert m.path_length_ratio == pytest.approx(1.0)


def test_malformed_reach_and_options_are_value_errors():
    reach = make_reach(straight(0.0))
    with pytest.raises(ValueError, match="shape"):
        reach_metrics(Reach(reach.t, reach.hand[:, 0], reach.start, reach.target, GO, True))
    for option in ({"threshold": 0.0}, {"threshold": 1.0}, {"direction_at": "peak"}, {"direction_delay": 0.0},
                   {"min_peak_speed": -1.0}):
        with pytest.raises(ValueError):
            reach_metrics(reach, **option)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=0, max_size=60), st.floats(-1.0, 2.0))
def test_any_finite_path_gives_metrics_and_never_raises(coords, go):
    n = len(coords) // 2
    hand = np.array(coords[: 2 * n]).reshape(n, 2)
    m = reach_metrics(Reach(np.arange(n) * 0.01, hand, (0.0, 0.0), (0.1, 0.0), go, False))
    assert all(math.isnan(v) or math.isfinite(v) for v in m.as_dict().values())
    if math.isfinite(m.path_length_ratio):
        assert m.path_length_ratio >= 1.0 - 1e-9
    if math.isfinite(m.movement_time_s):
        assert m.movement_time_s >= 0.0


# ----------------------------------------------------------------------------------- trials table

def row(number, **changes):
    base = {"block": "exposure", "trial": number, "target_deg": 45.0, "perturbation": "curl",
            "reaction_time_s": 0.3141592653589793, "movement_time_s": 0.45, "peak_speed_m_per_s": 0.375,
            "initial_direction_error_deg": -12.5, "max_perpendicular_error_m": 0.0123,
            "path_length_ratio": 1.1, "hit": True, "channel_force_peak_n": float("nan"),
            "channel_force_at_peak_speed_n": float("nan"), "adaptation_index": float("nan"),
            "hand_sent_home": False,
            "feedback": "full", "disturbance": 1.0, "adaptation_index_hand": float("nan"),
            "adaptation_index_joint": float("nan"), "home_shoulder_deg": 45.0, "home_elbow_deg": 90.0}
    base.update(changes)
    return base


def test_trials_round_trip_exactly_with_nan_as_empty(tmp_path):
    rows = [row(1, perturbation="channel", channel_force_peak_n=1.5, channel_force_at_peak_speed_n=-0.25,
                adaptation_index=0.75, adaptation_index_hand=0.75, adaptation_index_joint=-0.5),
            row(2, hit=False, reaction_time_s=float("nan"), path_length_ratio=np.float64(1 / 3)),
            row(3, block="washout", perturbation="none", trial=np.int64(3), hit=np.bool_(True), hand_sent_home=True)]
    path = tmp_path / "trials.csv"
    write_trials_csv(path, rows)
    text = path.read_text()
    assert text.splitlines()[0] == ",".join(TRIAL_COLUMNS)
    assert ",," in text.splitlines()[2]
    back = read_trials_csv(path)
    assert [list(r) for r in back] == [list(TRIAL_COLUMNS)] * 3
    assert back[1]["path_length_ratio"] == 1 / 3 and math.isnan(back[1]["reaction_time_s"])
    assert back[0] == rows[0] and back[2]["trial"] == 3 and back[2]["hit"] is True and back[1]["hit"] is False
    assert back[2]["hand_sent_home"] is True and back[1]["hand_sent_home"] is False


def test_write_refuses_bad_rows_and_non_regular_targets(tmp_path):
    path = tmp_path / "trials.csv"
    for bad in ({**row(1), "extra": 1}, {k: v for k, v in row(1).items() if k != "hit"}, row(1, trial=1.5),
                row(1, hit=1), row(1, block=""), row(1, peak_speed_m_per_s=float("inf")),
                row(1, target_deg=float("nan")),
                row(1, movement_time_s="0.4")):
        with pytest.raises(ValueError):
            write_trials_csv(path, [bad])
    assert not path.exists()
    (tmp_path / "folder.csv").mkdir()
    with pytest.raises(UserError, match="not a regular file"):
        write_trials_csv(tmp_path / "folder.csv", [row(1)])
    (tmp_path / "link.csv").symlink_to(tmp_path / "elsewhere.csv")
    with pytest.raises(UserError, match="not a regular file"):
        write_trials_csv(tmp_path / "link.csv", [row(1)])
    assert not (tmp_path / "elsewhere.csv").exists()
    with pytest.raises(UserError, match="no folder"):
        write_trials_csv(tmp_path / "nowhere" / "trials.csv", [row(1)])


def write_text(tmp_path, text, name="t.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


#: A table without the error-clamp columns (as written before they existed): it still reads.
BASE_COLUMNS = TRIAL_COLUMNS[:11]
HEADER = ",".join(BASE_COLUMNS)
GOOD = "exposure,1,45,curl,0.3,0.45,0.375,-12.5,0.0123,1.1,1"


@pytest.mark.parametrize(("text", "message"), [
    ("", "empty"),
    ("block,trial\nx,1\n", "lacks column"),
    (HEADER + ",extra\n", "unknown column"),
    (HEADER.replace("hit", "block") + "\n", "named twice"),
    (HEADER + "\n" + GOOD + ",9\n", "line 2: 12 fields"),
    (HEADER + "\n" + GOOD.replace(",1.1,", ",nan,") + "\n", "line 2, column path_length_ratio"),
    (HEADER + "\n" + GOOD + "\n" + GOOD.replace(",0.375,", ",1e999,") + "\n", "line 3, column peak_speed_m_per_s"),
    (HEADER + "\n" + GOOD.replace(",0.375,", ",-0.1,") + "\n", "must not be negative"),
    (HEADER + "\n" + GOOD.replace(",45,", ",,") + "\n", "column target_deg"),
    (HEADER + "\n" + GOOD.replace("exposure,1,", "exposure,-1,") + "\n", "column trial"),
    (HEADER + "\n" + GOOD.replace("exposure,1,", "exposure,1.0,") + "\n", "column trial"),
    (HEADER + "\n" + GOOD[:-1] + "yes\n", "column hit"),
    (HEADER + "\n" + GOOD.replace("exposure", "exp\tosure") + "\n", "column block"),
    (HEADER + "\n" + GOOD.replace("exposure", "x" * 65) + "\n", "column block"),
    (HEADER + '\n"exposure,1\n', "not CSV"),
])
def test_hostile_tables_get_one_line_naming_line_and_column(tmp_path, text, message):
    with pytest.raises(TrialsFileError, match=message) as info:
        read_trials_csv(write_text(tmp_path, text))
    assert "\n" not in str(info.value) and "t.csv" in str(info.value)


def test_reader_accepts_a_spreadsheets_table(tmp_path):
    columns = list(reversed(BASE_COLUMNS))
    values = dict(zip(BASE_COLUMNS, GOOD.split(","), strict=True)) | {"hit": "TRUE", "reaction_time_s": ""}
    text = "\ufeff" + ",".join(columns) + "\r\n" + ",".join(values[c] for c in columns) + "\r\n\r\n"
    (rows,) = read_trials_csv(write_text(tmp_path, text))
    assert rows["hit"] is True and math.isnan(rows["reaction_time_s"]) and rows["trial"] == 1
    assert list(rows) == list(TRIAL_COLUMNS) and math.isnan(rows["adaptation_index"])  # absent: read as NaN
    assert rows["hand_sent_home"] is False  # a table from before the column: no reach was sent home


def test_a_table_from_before_each_column_named_its_unit_still_reads(tmp_path):
    old = HEADER.replace("reaction_time_s", "reaction_time").replace("movement_time_s", "movement_time") \
        .replace("peak_speed_m_per_s", "peak_speed")
    assert old != HEADER
    (rows,) = read_trials_csv(write_text(tmp_path, old + "\n" + GOOD + "\n"))
    assert (rows["reaction_time_s"], rows["movement_time_s"], rows["peak_speed_m_per_s"]) == (0.3, 0.45, 0.375)
    with pytest.raises(TrialsFileError, match="named twice"):  # an old name beside its new one is the same column
        read_trials_csv(write_text(tmp_path, HEADER + ",peak_speed\n"))


def test_every_measure_names_its_unit():
    """SI in every table: a measure's column ends in its unit, or is a ratio or an index."""
    for name in TRIAL_COLUMNS:
        if name not in ("block", "trial", "perturbation", "hit", "path_length_ratio", "adaptation_index", "feedback",
                        "disturbance", "adaptation_index_hand", "adaptation_index_joint", "hand_sent_home"):
            assert name.endswith(("_s", "_m", "_m_per_s", "_deg", "_n")), name


def test_reader_refuses_non_regular_big_and_binary_files(tmp_path, monkeypatch):
    with pytest.raises(TrialsFileError, match="no such"):
        read_trials_csv(tmp_path / "missing.csv")
    with pytest.raises(TrialsFileError, match="not a regular file"):
        read_trials_csv(tmp_path)
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    with pytest.raises(TrialsFileError, match="not a regular file"):  # and does not block on it
        read_trials_csv(fifo)
    with pytest.raises(TrialsFileError, match="not UTF-8"):
        (tmp_path / "binary.csv").write_bytes(HEADER.encode() + b"\n\xff\xfe")
        read_trials_csv(tmp_path / "binary.csv")
    monkeypatch.setattr(metrics, "MAX_TRIALS_BYTES", 100)
    with pytest.raises(TrialsFileError, match="too large"):
        read_trials_csv(write_text(tmp_path, HEADER + "\n" + GOOD + "\n"))


def test_module_examples():
    assert doctest.testmod(metrics).failed == 0


def test_a_clockwise_curl_field_reads_as_clockwise_errors():
    # The README's sign claim: with F = b [[0, 1], [-1, 0]] v and b > 0 the force turns clockwise
    # of the velocity, so a point mass servoed along a straight minimum-jerk reach errs clockwise
    # (negative), whatever the reach direction; b < 0 errs counter-clockwise.
    def servoed_reach(b, deg):
        t = np.arange(0.0, 1.0, DT)
        goal = straight(deg)(progress((t - START) / T))
        x, v = goal[0].copy(), np.zeros(2)
        hand = np.empty_like(goal)
        for i in range(t.size):
            hand[i] = x
            force = 60.0 * (goal[i] - x) - 8.0 * v + b * np.array([v[1], -v[0]])
            v = v + DT * force  # 1 kg; semi-implicit Euler
            x = x + DT * v
        return reach_metrics(Reach(t, hand, tuple(HOME), tuple(HOME + D * unit(deg)), GO, True))

    for deg in (0.0, 135.0, -60.0):
        cw, ccw = servoed_reach(10.0, deg), servoed_reach(-10.0, deg)
        assert cw.initial_direction_error_deg < -1.0 and cw.max_perpendicular_error_m < -0.002
        assert ccw.initial_direction_error_deg > 1.0 and ccw.max_perpendicular_error_m > 0.002


measure = st.one_of(st.just(float("nan")), st.floats(allow_nan=False, allow_infinity=False))
text = st.text(st.characters(codec="utf-8", categories=("L", "N", "P", "S", "Zs")), min_size=1, max_size=64).filter(
    lambda s: s.strip() == s and s.isprintable())


@settings(max_examples=30, deadline=None)
@given(st.lists(st.fixed_dictionaries({
    "block": text, "trial": st.integers(0, 1_000_000), "target_deg": st.floats(-1e6, 1e6),
    "perturbation": text, "reaction_time_s": measure, "movement_time_s": measure.map(abs),
    "peak_speed_m_per_s": measure.map(abs), "initial_direction_error_deg": measure,
    "max_perpendicular_error_m": measure,
    "path_length_ratio": measure.map(abs), "hit": st.booleans(), "channel_force_peak_n": measure,
    "channel_force_at_peak_speed_n": measure, "adaptation_index": measure, "hand_sent_home": st.booleans(),
    "feedback": st.sampled_from(FEEDBACK), "disturbance": measure, "adaptation_index_hand": measure,
    "adaptation_index_joint": measure, "home_shoulder_deg": measure, "home_elbow_deg": measure}), max_size=5))
def test_any_table_round_trips_exactly(tmp_path_factory, rows):
    path = tmp_path_factory.mktemp("round") / "trials.csv"
    write_trials_csv(path, rows)
    back = read_trials_csv(path)
    assert len(back) == len(rows)
    for a, b in zip(rows, back, strict=True):
        for name in TRIAL_COLUMNS:
            same = (math.isnan(a[name]) and math.isnan(b[name])) if isinstance(a[name], float) else False
            assert same or a[name] == b[name], name


def under_header(cells):
    return (HEADER + "\n" + ",".join(cells)).encode()


@settings(max_examples=60, deadline=None)
@given(st.one_of(st.binary(max_size=300),
                 st.lists(st.text(max_size=30), max_size=12).map(under_header),
                 st.lists(st.sampled_from(["1", "-1", "", "x", "1e999", "nan", '"', "\x00", "true", "é"]),
                          min_size=11, max_size=11).map(under_header)))
def test_any_bytes_read_as_a_table_or_one_line_error(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("fuzz") / "t.csv"
    path.write_bytes(data)
    try:
        rows = read_trials_csv(path)
    except TrialsFileError as exc:
        assert "\n" not in str(exc) and str(path) in str(exc)
    else:
        assert all(list(r) == list(TRIAL_COLUMNS) for r in rows)
