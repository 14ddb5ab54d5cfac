"""How long the browser's engine (armgame/classroom/static/engine.js) takes to play a 60 s game, in Node.

    python benchmarks/browser_engine_speed.py            # 7 games, a few seconds
    python benchmarks/browser_engine_speed.py --games 15 --json

Each game is ``standardConfig(seed)`` (the standard 60 s game, 15,000 steps of 4 ms) played by ``Game`` with a key
pressed or released every 25 steps in turn (d, f, j, k: the arm moving, the muscles changing), timed with
``performance.now()`` from the game's making to its last step. Five games first, untimed, so that V8 has compiled
the engine to its top tier (after one, the timed games spread from 4 to 13 ms; after five, 3.2 to 3.5). The report
gives the best and the median over the games and a step's share of the best; Node's version and the machine beside
them. The figure docs/development.md gives for "a 60 s game" is this benchmark's
(``benchmarks/results/browser_engine_speed.json``).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ENGINE = ROOT / "armgame" / "classroom" / "static" / "engine.js"

#: The Node side: plays ``games + 5`` games, the first five to warm V8, and prints each timed game's milliseconds.
SCRIPT = """
import { Game, standardConfig } from %(engine)s;
const keys = ["d", "f", "j", "k"];
function play(seed) {
  const start = performance.now();
  const game = new Game(standardConfig(seed));
  let k = 0;
  while (!game.over && game.steps < game.totalSteps) {
    if (game.advance(25) === 0) break;
    const key = keys[k %% 4];
    game.keyEvent(key, Math.floor(k / 4) %% 2 === 0 ? "down" : "up");
    k += 1;
  }
  return [performance.now() - start, game.steps];
}
for (let seed = 1001; seed <= 1005; seed++) play(seed);
const out = [];
for (let seed = 1; seed <= %(games)d; seed++) out.push(play(seed));
console.log(JSON.stringify({ node: process.version, games: out }));
"""


def measure(games: int) -> dict[str, object]:
    node = shutil.which("node")
    if node is None:
        raise SystemExit("node (Node.js) is not installed: the engine runs in it")
    script = SCRIPT % {"engine": json.dumps(ENGINE.as_uri()), "games": games}
    load = os.getloadavg()[0]
    done = subprocess.run([node, "--input-type=module", "-e", script], capture_output=True, text=True, timeout=300,
                          check=False)
    if done.returncode != 0:
        last = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"exit {done.returncode}"
        raise SystemExit(f"node failed: {last}")
    answer = json.loads(done.stdout)
    ms = sorted(float(t) for t, _ in answer["games"])
    steps = {int(s) for _, s in answer["games"]}
    if len(steps) != 1:
        raise SystemExit(f"the games ran different numbers of steps: {sorted(steps)}")
    step_count = steps.pop()
    return {"node": answer["node"], "games": games, "steps_a_game": step_count, "ms": [round(t, 3) for t in ms],
            "best_ms": round(ms[0], 3), "median_ms": round(ms[len(ms) // 2], 3),
            "us_a_step_best": round(ms[0] * 1e3 / step_count, 4),
            "machine": f"{platform.machine()}, {os.cpu_count()} cores", "python": platform.python_version(),
            "load_average": [round(load, 2), round(os.getloadavg()[0], 2)]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--games", type=int, default=7, help="games timed (after one to warm up)")
    parser.add_argument("--json", action="store_true", help="one JSON object instead of the report")
    args = parser.parse_args()
    if not 1 <= args.games <= 1000:
        parser.error("--games must be from 1 to 1000")
    result = measure(args.games)
    if args.json:
        print(json.dumps(result, indent=1))
        return
    print(f"engine.js in Node {result['node']}: a 60 s game ({result['steps_a_game']:,} steps) in "
          f"{result['best_ms']:.1f} ms at best of {result['games']}, {result['median_ms']:.1f} ms the median "
          f"({result['us_a_step_best']:.2f} us a step at best); {result['machine']}, load average "
          f"{result['load_average'][0]} before, {result['load_average'][1]} after", file=sys.stdout)


if __name__ == "__main__":
    main()
