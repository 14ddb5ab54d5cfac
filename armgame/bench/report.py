"""Text, CSV and JSON output of a benchmark run."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Any

from ..words import plural
from .measure import Row
from .run import Result

COLUMNS = ("case", "method", "setting", "ms_per_sim_s", "rhs_per_sim_s", "hand_error_m", "energy_drift", "blew_up",
           "note")


def _g(x: float, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if math.isinf(x):
        return "inf"
    return f"{x:.{digits}g}" if abs(x) >= 1e-3 or x == 0 else f"{x:.{digits}e}".replace("e-0", "e-")


def row_cells(r: Row) -> list[str]:
    return [r.case, r.method, r.setting, _g(r.time_per_sim_s * 1e3, 3), _g(r.rhs_per_sim_s, 3),
            _g(r.hand_error), _g(r.energy_drift), "BLOW-UP" if r.blew_up else "", r.note]


def table(rows: list[Row], markdown: bool = False) -> str:
    header = ["case", "method", "setting", "ms/sim s", "RHS/sim s", "hand err (m)", "energy drift", "blew up",
              "note"]
    body = [row_cells(r) for r in rows]
    if markdown:
        lines = ["| " + " | ".join(header[:-1]) + " |", "|" + "---|" * (len(header) - 1)]
        lines += ["| " + " | ".join(cells[:-1]) + " |" for cells in body]
        return "\n".join(lines)
    widths = [max(len(h), *(len(c[i]) for c in body)) if body else len(h) for i, h in enumerate(header)]
    fmt = "  ".join(f"{{:{'<' if i < 3 or i == len(header) - 1 else '>'}{w}}}" for i, w in enumerate(widths))
    lines = [fmt.format(*header).rstrip(), fmt.format(*("-" * w for w in widths)).rstrip()]
    last_case = None
    for r, cells in zip(rows, body, strict=True):
        if last_case is not None and r.case != last_case:
            lines.append("")
        last_case = r.case
        lines.append(fmt.format(*cells).rstrip())
    return "\n".join(lines)


def bars_text(bars: dict[str, Any]) -> list[str]:

    out = []
    # The goals: the game's default as the game runs it (compiled) at 300x the tutorial's odeint and 40x
    # MuJoCo's C loop (issue 30); the Python step, what an install without a C compiler runs, at 20x and 2.5x.
    compiled = bool(bars.get("odeint_compiled", "game_step_us" in bars))
    if "odeint_ratio" in bars:
        goal = 300 if compiled else 20
        ok = "meets" if bars["odeint_ratio"] >= goal else "MISSES"
        line = (f"game default vs tutorial odeint, passive, equal or better error: "
                f"{bars['odeint_ratio']:.0f}x faster ({ok} the {goal}x bar)")
        if compiled and "odeint_ratio_python" in bars:
            line += f"; the Python step {bars['odeint_ratio_python']:.0f}x"
        out.append(f"{line} [{bars['odeint_detail']}]")
    if "rk4_step_us" in bars:
        line = "one arm, RK4 step: "
        if "game_step_us" in bars:
            line += (f"the game's compiled loop {bars['game_step_us']:.3f} us (muscles and hit test included), "
                     f"RK4 alone in C {bars['rk4_c_step_us']:.3f} us; ")
        out.append(f"{line}the Python step {bars['rk4_step_us']:.2f} us (floats); "
                   f"numpy backend on one arm {bars['rk4_numpy_single_step_us']:.2f} us")
    if "mujoco_ratio" in bars:
        # Compiled, the game's loop against MuJoCo's own C loop (C against C); the Python step against
        # MuJoCo stepped from Python (a call a step either way).
        key, goal = ("mujoco_c_loop_ratio", 40) if "game_step_us" in bars else ("mujoco_ratio", 2.5)
        ok = f"{'meets' if bars[key] >= goal else 'MISSES'} the {goal:g}x bar"
        ours = "the game's loop" if "game_step_us" in bars else "the Python step"
        line = (f"MuJoCo RK4 step of the same arm: {bars['mujoco_rk4_c_loop_step_us']:.2f} us in its own C loop "
                f"(mj_step nstep, constant torque) -> {ours} {bars['mujoco_c_loop_ratio']:.1f}x faster"
                f"{f' ({ok})' if key == 'mujoco_c_loop_ratio' else ''}; {bars['mujoco_rk4_step_us']:.2f} us "
                f"stepped from Python -> {bars['mujoco_ratio']:.1f}x{f' ({ok})' if key == 'mujoco_ratio' else ''}")
        if "game_step_us" in bars:
            line += (f"; the Python step {bars['mujoco_c_loop_ratio_python']:.2f}x and "
                     f"{bars['mujoco_ratio_python']:.2f}x")
        out.append(line)
    if "batch_rate" in bars:
        ok = "meets" if bars["batch_rate"] >= 10e6 else "MISSES"
        per = ", ".join(f"{plural(int(k.split('_')[2]), 'thread')} {v / 1e6:.1f} M" for k, v in bars.items()
                        if k.startswith("batch_rate_") and k.endswith("thread"))
        out.append(f"batch of 10,000 arms, RK4, dt 1 ms (BatchRK4): {bars['batch_rate'] / 1e6:.1f} M arm-steps/s "
                   f"with {plural(bars['batch_threads'], 'thread')} ({ok} the 10 M bar) [{per}; "
                   f"Integrator numpy backend {bars['batch_rate_integrator_numpy'] / 1e6:.1f} M]")
    return out


def text_report(result: Result) -> str:
    from ..physics import defaults

    lines = [table(result.rows), ""]
    lines.append("speed bars (each measured in this run):")
    lines += [f"  {line}" for line in bars_text(result.bars)] or ["  (not measured)"]
    lines.append("defaults the data choose:")
    if not result.choices:
        lines.append("  (not judged: see the note below)")
    roles = (("game", (defaults.GAME_INTEGRATOR, defaults.GAME_DT)),
             ("simulate", (defaults.SIMULATE_INTEGRATOR, defaults.SIMULATE_DT)))
    for role, current in roles if result.choices else ():
        c = result.choices.get(role)
        if c is None:
            lines.append(f"  {role}: no measured setting meets the criteria (measure more cases or steps)")
            continue
        same = "matches" if (c.integrator, round(1 / c.dt)) == (current[0], round(1 / current[1])) else "DIFFERS from"
        lines.append(f"  {role}: {c.integrator} at dt=1/{round(1 / c.dt)} ({c.reason}); {same} "
                     f"armgame/physics/defaults.py ({current[0]}, dt=1/{round(1 / current[1])})")
    for note in result.notes:
        lines.append(f"note: {note}")
    m = result.machine
    cores = plural(int(m["cores"]), "core") if m["cores"].isdigit() else f"{m['cores']} cores"
    lines.append(f"machine: {m['cpu']}, {cores}, {m['system']}; load average "
                 f"{m.get('load', 'unknown')} (1, 5, 15 min) as the run started")
    lines.append("versions: " + ", ".join(f"{k} {m[k]}" for k in ("python", "numpy", "scipy", "mujoco", "matplotlib")))
    lines.append(f"benchmark took {result.seconds:.0f} s")
    return "\n".join(lines)


def json_report(result: Result) -> str:
    def clean(x: Any) -> Any:
        if isinstance(x, float) and not math.isfinite(x):
            return None if math.isnan(x) else ("inf" if x > 0 else "-inf")
        return x

    payload = {
        "rows": [{k: clean(v) for k, v in r.as_dict().items()} for r in result.rows],
        "bars": {k: clean(v) for k, v in result.bars.items()},
        "defaults": {role: (None if c is None else {"integrator": c.integrator, "dt": c.dt, "reason": c.reason})
                     for role, c in result.choices.items()},
        "machine": result.machine,
        "notes": result.notes,
        "seconds": result.seconds,
    }
    return json.dumps(payload, indent=1)


def write_csv(rows: list[Row], path: Path) -> None:
    from ..records.storage import atomic_write_bytes

    f = io.StringIO(newline="")
    w = csv.writer(f)
    w.writerow(["case", "method", "family", "setting", "dt", "tol", "time_per_sim_s", "rhs_per_sim_s",
                "hand_error_m", "energy_drift", "blew_up", "note"])
    for r in rows:
        w.writerow([r.case, r.method, r.family, r.setting, "" if r.dt is None else repr(r.dt),
                    "" if r.tol is None else repr(r.tol), repr(r.time_per_sim_s), repr(r.rhs_per_sim_s),
                    repr(r.hand_error), repr(r.energy_drift), int(r.blew_up), r.note])
    atomic_write_bytes(Path(path), f.getvalue().encode("utf-8"), "CSV")  # only a regular file, whole
