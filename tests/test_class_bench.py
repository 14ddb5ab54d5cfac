"""benchmarks/class_server.py cannot rot: a class of two through all its phases, in about 2 s."""

from __future__ import annotations

import importlib.util
from pathlib import Path


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
