"""armgame simulate: run a named physics scene offline and write a CSV."""

from __future__ import annotations

import argparse
import math

from ..errors import UserError
from ..words import plural


def _initial_state(text: str) -> tuple[float, float, float, float]:
    parts = [p.strip() for p in text.split(",")]
    if len(parts) not in (2, 4):
        raise argparse.ArgumentTypeError(
            f"expected 'Q1,Q2' or 'Q1,Q2,QD1,QD2' in degrees and deg/s, got {text!r}"
        )
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a list of numbers: {text!r}") from None
    if not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"initial state must be finite, got {text!r}")
    values += [0.0] * (4 - len(values))
    q1, q2, w1, w2 = (math.radians(v) for v in values)
    return q1, q2, w1, w2


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "simulate",
        help="simulate a named scene and write a CSV",
        description="Simulate a named physics scene with a chosen integrator and write the trajectory as CSV "
        "(t, q1, q2, qd1, qd2 in rad and rad/s, hand_x, hand_y in m, tau1, tau2 in N m, energy in J). Rows are "
        "written as they come; a run over the budget (20,000,000 steps or 5,000,000 rows; dop853: 20,000 "
        "evaluations per simulated second, 2,000,000 in all) is refused before it starts, and a run that blows "
        "up stops with one line.",
    )
    p.add_argument("--scene", required=True, help="passive, pendulum, propeller, upright, stiff or game")
    # Defaults resolve in run(): they live in armgame.physics.defaults, which parsing must not import.
    p.add_argument("--integrator", default=None,
                   help="euler, symplectic-euler, rk4, midpoint, gauss4 or dop853 "
                   "(default: SIMULATE_INTEGRATOR in armgame/physics/defaults.py, chosen by armgame bench)")
    p.add_argument("--dt", type=float, default=None,
                   help="fixed step in seconds (default: SIMULATE_DT in armgame/physics/defaults.py)")
    p.add_argument("--duration", type=float, default=None, help="seconds to simulate (default: the scene's)")
    p.add_argument("--initial", type=_initial_state, default=None, metavar="Q1,Q2[,QD1,QD2]",
                   help="initial joint angles in degrees and velocities in deg/s, in armgame's convention "
                   "(q1 from +x, q2 relative to the upper arm); default: the scene's")
    p.add_argument("--sample-rate", type=float, default=200.0, help="rows per simulated second (default: 200)")
    p.add_argument("--out", required=True, help="CSV file to write (a file there already: refused unless --force)")
    from .outputs import add_force_option

    add_force_option(p, "the --out file")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..physics.defaults import SIMULATE_DT, SIMULATE_INTEGRATOR
    from ..records.storage import user_path
    from ..scenes import get_scene
    from ..simulation import simulate_to_csv

    args.integrator = SIMULATE_INTEGRATOR if args.integrator is None else args.integrator
    args.dt = SIMULATE_DT if args.dt is None else args.dt
    out = user_path(args.out, "--out")
    scene = get_scene(args.scene)
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise UserError(f"--duration must be a positive, finite number of seconds, got {args.duration!r}")
    from .outputs import fresh_outputs

    with fresh_outputs([out], args.force, "CSV"):
        run_ = simulate_to_csv(scene, args.integrator, args.dt, out, args.duration, args.initial, args.sample_rate)
    summary = f"{scene.name}: {plural(run_.rows, 'row')} to {args.out} ({args.integrator}, dt={args.dt:g} s, " \
        f"{run_.t_end:g} s)"
    if run_.energy_start is not None and run_.rows > 1 and run_.energy_start != 0.0:
        drift = abs(run_.energy_end - run_.energy_start) / abs(run_.energy_start)
        summary += f"; energy change while torque-free {drift:.2e} relative"
    print(summary)
    return 0
