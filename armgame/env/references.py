"""Reference scores of the suite: filled from benchmarks/reference_scores.py."""

REFERENCE_HITS: dict[str, dict[str, float]] = {}
