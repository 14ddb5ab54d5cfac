"""benchmarks/class_server.py cannot rot: a class of two through all its phases, in about 2 s."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest


@pytest.mark.slow  # the benchmark's smoke run (about 2 s of a server): CI runs it after the suite, as the flood's
def test_the_class_server_benchmark_runs():
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "class_server.py"
    spec = importlib.util.spec_from_file_location("class_server_benchmark", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    report = bench.measure([2], repeats=1, sustained=2, clients=1, bot_share=0.0)
    figures = report["classes"]["2"]
    run = figures["runs"][0]
    assert run["joins"]["acknowledged"] == 2 and run["burst"]["acknowledged"] == 2
    assert run["sustained"]["acknowledged"] == 4 and figures["not_acknowledged"] == 0
    assert run["folder"] == {"entries": 6, "acknowledged_kept": 6, "not_acknowledged_but_kept": 0}
    assert figures["whole_class_s"]["median"] > 0 and figures["sustained_per_s"]["median"] > 0
    assert run["server_exit"] == 0 and run["server_notices"] == {}


@pytest.mark.slow
def test_the_flood_the_clerk_and_the_table_costs_run():
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "class_server.py"
    spec = importlib.util.spec_from_file_location("class_server_benchmark", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    report = bench.measure([1], repeats=1, sustained=1, clients=1, bot_share=0.0, flooders=2, flood_honest=1,
                           flood_seconds=1.0, clerk=4, table_sizes=[3])
    run = report["flood"]["runs"][0]
    assert run["honest_handins"]["acknowledged"] >= 1 and run["honest_handins"]["not_acknowledged"] == {}
    assert set(run["flood_answers"]) <= {"400", "422", "503"} and run["flood_answers"]
    clerk = report["clerk"][0]
    assert clerk["honest"]["answers"] == {"ok": 4} and clerk["forged"]["answers"] == {"422": 4}
    assert set(report["table"][0]["sizes"]["3"]) == {"journal", "rewrite"}


@pytest.mark.slow  # plays the model bot's game once (about 2 s)
def test_the_timeline_passes_benchmark_runs_and_checks_its_twins():
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "timeline_passes.py"
    spec = importlib.util.spec_from_file_location("timeline_passes_benchmark", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    from armgame.records import identity

    if identity._CTIMELINE is None:
        pytest.skip("built without a C compiler: nothing to compare")
    report = bench.measure(1)
    for figures in report["games"].values():
        assert set(figures["passes"]) == {"reading", "its identities", "the batch's columns", "writing it again"}
        assert all(row["with_c_ms"][0] > 0 and row["python_ms"][0] > 0 for row in figures["passes"].values())


@pytest.mark.slow  # a server and two browser lab runs (about 4 s)
def test_the_lab_handin_benchmark_runs():
    """benchmarks/lab_handin.py (docs/performance.md's 30 lab runs at once) on two students: every run taken into the
    class curve (the benchmark fails otherwise), each figure there."""
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "lab_handin.py"
    spec = importlib.util.spec_from_file_location("lab_handin_benchmark", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    report = bench.measure(students=2, repeats=1)
    s = report["summary"]
    assert 0 < s["after_last_sent_s"]["median"] <= s["after_first_sent_s"]["median"]
    assert s["verify_ms"]["median"] > 0 and s["batch_ms"]["median"] > 0
    assert report["classes"][0]["server_cpu_s"] is None or report["classes"][0]["server_cpu_s"] > 0
