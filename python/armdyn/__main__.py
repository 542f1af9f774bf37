"""Command line.

* ``armdyn reproduce [--out DIR]`` regenerates the five-DOF validation paper's Tables 1–4 and
  Figures 5–8 beside the paper's own figures, and the six-DOF paper's geared-arm study (Fig. 3
  style), as a Markdown + PNG report.
* ``armdyn bench [--out DIR]`` times armdyn against Pinocchio and SciPy in one process (UR5,
  Panda, a 5 s run, the 44-body geared arm, chains of 2–1000 bodies) and writes JSON + a plot.
* ``armdyn workprecision [PROBLEM ...] [--quick] [--out DIR]`` sweeps tolerances on the standard
  problems (IFToMM A01, A02, Andrews' squeezer), the five-DOF paper arm, the UR5 and the geared
  arm, and records error against CPU time for armdyn's
  integrators and the peers (SciPy, MuJoCo, Exudyn), as JSON + a log-log plot per problem.
* ``armdyn verify`` prints the solver's accuracy figures: pendulum period, energy and momentum
  conservation, constraint drift, and the cross-check against recursive Newton–Euler.
"""

from __future__ import annotations

import argparse
import sys


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="armdyn", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("verify", help="print accuracy figures against closed forms and RNEA")
    rep = sub.add_parser("reproduce", help="regenerate the papers' tables and figures")
    rep.add_argument("--out", default="armdyn-report", help="report folder (Markdown + PNG)")
    rep.add_argument("--no-plots", action="store_true", help="skip the figures")
    rep.add_argument(
        "--no-geared", action="store_true", help="skip the geared-arm study (a few minutes)"
    )
    bench = sub.add_parser("bench", help="speed against Pinocchio and SciPy, scaling (JSON + plot)")
    bench.add_argument("--out", default="docs/results", help="folder for bench.json, bench.png")
    bench.add_argument("--quick", action="store_true", help="chains up to 100 bodies only")
    wp = sub.add_parser("workprecision", help="error against CPU time on the standard problems")
    wp.add_argument(
        "problems",
        nargs="*",
        default=["all"],
        help="squeezer, a01, a02, five_dof, ur5, geared_arm, or all (every one; a02 and "
        "geared_arm take minutes)",
    )
    wp.add_argument("--out", default="docs/results/workprecision", help="folder for JSON + PNG")
    wp.add_argument("--quick", action="store_true", help="two points per curve")
    wp.add_argument("--no-peers", action="store_true", help="armdyn's curves only")
    args = parser.parse_args(argv)
    if args.command == "workprecision":
        from armdyn.workprecision import run as wp_run

        wp_run(args.problems, out=args.out, quick=args.quick, peers=not args.no_peers)
        return 0
    if args.command == "bench":
        from armdyn.bench import run as bench_run

        bench_run(args.out, quick=args.quick)
        return 0
    if args.command == "verify":
        from armdyn.verify import main as verify_main

        return verify_main()
    if args.command == "reproduce":
        from armdyn.reproduce import run

        run(args.out, plots=not args.no_plots, geared=not args.no_geared)
        return 0
    return 1


if __name__ == "__main__":
    sys.exit(main())
