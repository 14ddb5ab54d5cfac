"""armgame derive: the equations of motion by Euler-Lagrange in SymPy, checked against the numeric core."""

from __future__ import annotations

import argparse

from ..errors import UserError
from ..valid import INT64_MAX


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "derive",
        help="derive the equations of motion with SymPy and check them against the simulator",
        description="Form the kinetic and potential energy from the arm's kinematics, run L = T - U through the "
        "Euler-Lagrange equations (as the tutorial's onejoint_lagrange.py and twojointarm_lagrange.py do), print "
        "tau = M(q) qdd + C(q, qd) + G(q), and compare M, C and G with armgame's numeric model at random states. "
        "Exits non-zero if they differ. Needs SymPy: pip install 'armgame[derive]'.",
    )
    p.add_argument("arm", choices=("one", "two"), help="one: the pendulum; two: the two-joint arm")
    p.add_argument("--latex", action="store_true", help="print the equations as LaTeX instead of plain text")
    p.add_argument("--states", type=int, default=5, help="random states to compare at (default: 5)")
    p.add_argument("--seed", type=int, default=0, help="seed for the random states (default: 0)")
    p.set_defaults(run=run)


#: Random states ``derive`` compares at: plenty for a check, and a few seconds at most.
MAX_STATES = 10_000


def run(args: argparse.Namespace) -> int:
    try:
        import sympy  # noqa: F401
    except ImportError:
        raise UserError("derive needs SymPy: pip install 'armgame[derive]'") from None
    if not 1 <= args.states <= MAX_STATES:  # each state is a few evaluations: bounded before SymPy starts
        raise UserError(f"--states must be from 1 to {MAX_STATES}, got {args.states}")
    if not 0 <= args.seed <= INT64_MAX:
        raise UserError(f"--seed must be a whole number from 0 to 2^63 - 1, got {args.seed}")
    from ..derive import MATCH_TOLERANCE, compare_with_core, derive, format_latex, format_text

    joints = 1 if args.arm == "one" else 2
    d = derive(joints)
    print(format_latex(d) if args.latex else format_text(d))
    worst = compare_with_core(d, args.states, args.seed)
    verdict = "matches" if worst <= MATCH_TOLERANCE else "DIFFERS"
    arm = "OneJointArm (pendulum)" if joints == 1 else "TwoJointArm (tutorial arm)"
    print(f"numeric core {arm} at {args.states} random states: max |difference| in M, C, G = {worst:.3g}: {verdict}")
    return 0 if verdict == "matches" else 1
