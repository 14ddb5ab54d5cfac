"""What the benchmarks that check docs/lab.md's numbers share: the page's text, and each phrase looked for in it.

``lab_claims.py``, ``curl_scaling.py`` and ``fit_coverage.py`` rebuild the page's numbers from their runs and
look for each sentence as printed; a benchmark run beside this file imports it (``python benchmarks/NAME.py``
puts ``benchmarks/`` first on the path).
"""

from __future__ import annotations

import re
from pathlib import Path

#: docs/lab.md with every run of white space one space: a phrase may wrap anywhere in the page.
LAB_DOC = re.sub(r"\s+", " ", (Path(__file__).resolve().parent.parent / "docs" / "lab.md").read_text(encoding="utf-8"))


class Claims:
    """The phrases a run looks for in ``text``: ``says`` prints each (ok or DIFFERS), ``failures`` keeps the missing."""

    def __init__(self, text: str = LAB_DOC) -> None:
        self.text = text
        self.failures: list[str] = []

    def says(self, phrase: str) -> None:
        ok = phrase in self.text
        print(f"  {'ok     ' if ok else 'DIFFERS'} {phrase}")
        if not ok:
            self.failures.append(phrase)
