"""The work-precision benchmark as a script: the same code and options as ``armgame bench``.

    python benchmarks/bench.py --quick
    python benchmarks/bench.py --out bench-out
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from armgame.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
