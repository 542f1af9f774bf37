"""Command line.

* ``armdyn reproduce [--out DIR]`` regenerates the five-DOF validation paper's Tables 1–4 and
  Figures 5–8 beside the paper's own figures, and the six-DOF paper's geared-arm study (Fig. 3
  style), as a Markdown + PNG report (exit code 2 when DIR cannot be written).
* ``armdyn size ROBOT.urdf --trajectory FILE.csv [--actuators FILE.toml] [--out DIR]`` prints
  the sizing report of a planned motion (joint side, and motor side for the actuators of the
  TOML file) and writes it to DIR; exit code 0 when every joint is ok, 1 when some joint is
  not, 2 for bad input. File formats: ``armdyn.size``.
  ``--payload MASS[,X,Y,Z]`` welds a point mass (kg; its centre of mass in m, in the axes of
  ``--payload-frame``, default the model's last frame, ``model.frame_names[-1]``: a UR5's
  ``tool0``) to the robot; ``--dwell SECONDS`` and ``--cycle N|forever`` make the motion a
  duty cycle (the report is of one period, plus the winding temperature of the repeated
  cycle); of the check options (:class:`armdyn.sizing.SizingOptions`') it takes the thermal
  ones (``--ambient``...) and refuses the others (``--life``...: ``armdyn select``'s checks).
* ``armdyn select ROBOT.urdf --trajectory FILE.csv --catalog PATH [--objective
  mass|cost|bus_power|margin] [--payload ...] [--cycle ...] [--dwell ...] [--out DIR]`` chooses
  each joint's motor, gearbox and drive from the catalog (``armdyn.select_drivetrain``), prints
  the choice and writes its report to DIR; exit code 0 when every joint has a drivetrain that
  passes, 1 when some has none, 2 for bad input.
* ``armdyn identify ROBOT.urdf --log FILE.csv --out DIR [--validate FILE.csv] [--cutoff HZ]
  [--trim SECONDS] [--filter-tau] [--no-physical] [--method ols|wls] [--torque-constants K]
  [--gear-ratios N] [--efficiency E]`` identifies the robot's inertial, friction, offset and
  rotor parameters from a measured log (``armdyn.identification``), validates them on data the
  fit did not use, and writes DIR/identified.urdf, DIR/report.html and DIR/parameters.csv; exit
  code 0 when it ran, 1 when the unconstrained (``--no-physical``) estimate cannot be written as
  a URDF, 2 for bad input. Details: ``armdyn.identification.cli``.
* ``armdyn verify`` prints the solver's accuracy figures: pendulum period, energy and momentum
  conservation, constraint drift, and forward dynamics against the Euler–Lagrange equations.

The speed and work–precision benchmarks against peers are not part of the package: see
``benchmarks/README.md`` in the repository (``python -m benchmarks.bench``,
``python -m benchmarks.workprecision``).
"""

from __future__ import annotations

import argparse
import sys


def main(argv: list[str] | None = None) -> int:
    from armdyn import __version__

    parser = argparse.ArgumentParser(
        prog="armdyn", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--version", action="version", version=f"armdyn {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("verify", help="print accuracy figures against closed forms and Lagrange")
    rep_help = (
        "regenerate the papers' tables and figures (measured: 8.1 s on 2 cores, "
        "2.3 s with --no-geared)"
    )
    rep = sub.add_parser("reproduce", help=rep_help, description=rep_help)
    rep.add_argument("--out", default="armdyn-report", help="report folder (Markdown + PNG)")
    rep.add_argument("--no-plots", action="store_true", help="skip the figures")
    rep.add_argument(
        "--no-geared",
        action="store_true",
        help="skip the geared-arm study (8.1 s becomes 2.3 s)",
    )
    size = sub.add_parser(
        "size", help="sizing report of a planned motion (exit 0: every joint ok, 1: not)"
    )
    _motion_arguments(size)
    size.add_argument("--actuators", help="TOML: per joint gear_ratio, rotor_inertia, [motor]")
    size.add_argument("--out", help="write the report (HTML, CSV, figures) into this folder")
    size.add_argument(
        "--sweep",
        metavar="MIN:MAX:N",
        help="with --out: the report adds the gear-ratio sweep of the --actuators joints over N "
        "ratios spaced geometrically from MIN to MAX",
    )
    select = sub.add_parser(
        "select",
        help="choose each joint's motor, gearbox and drive from a catalog (exit 0: every joint "
        "has one that passes, 1: not)",
    )
    _motion_arguments(select)
    select.add_argument(
        "--catalog",
        required=True,
        action="append",
        metavar="PATH",
        help="a catalog folder (motors.csv, gearboxes.csv, drives.csv) or CSV file; repeat to "
        "merge several",
    )
    select.add_argument(
        "--objective",
        default="mass",
        metavar="mass|cost|bus_power|margin",
        help="what the choice minimises (margin: maximises the least margin); default mass",
    )
    select.add_argument("--out", help="write the selection's report into this folder")
    _identify_arguments(sub)
    args = parser.parse_args(argv)
    try:
        return _run(args)
    except ModuleNotFoundError as e:  # a dependency missing (e.g. pip install --no-deps)
        fix = "reinstall armdyn" if (e.name or "").startswith("armdyn") else f"pip install {e.name}"
        print(f"armdyn {args.command}: needs the Python module {e.name!r}: {fix}", file=sys.stderr)
        return 2


def _motion_arguments(p: argparse.ArgumentParser) -> None:
    """The arguments ``size`` and ``select`` share: the robot, its motion, the payload, the
    duty cycle and the check options (one per armdyn.sizing.SizingOptions field)."""
    from armdyn.sizing.cli import add_option_arguments

    p.add_argument("urdf", help="the robot's URDF file")
    p.add_argument(
        "--trajectory", required=True, help="CSV: t, one column per joint, optional .qd/.qdd"
    )
    p.add_argument(
        "--payload",
        metavar="MASS[,X,Y,Z]",
        help="a point mass [kg] welded to the robot, its centre of mass [m] in the axes of "
        "--payload-frame from its origin (default the origin)",
    )
    p.add_argument(
        "--payload-frame",
        metavar="NAME",
        help="the frame carrying the payload; default the model's last frame (a UR5: tool0)",
    )
    p.add_argument(
        "--cycle",
        metavar="N|forever",
        help="repeat the motion (and its dwell) N times from the ambient temperature, or "
        "forever (the periodic steady state; the default with --dwell)",
    )
    p.add_argument(
        "--dwell",
        metavar="SECONDS",
        help="hold the motion's last pose this long at the end of each cycle",
    )
    add_option_arguments(p)


def _identify_arguments(sub) -> None:
    """The ``identify`` subcommand's arguments (armdyn.identification.cli)."""
    p = sub.add_parser(
        "identify",
        help="identify the robot's parameters from a measured log, validate them and write the "
        "identified URDF and a report (exit 0: done, 2: bad input)",
    )
    p.add_argument("urdf", help="the robot's URDF file (fixed base)")
    p.add_argument(
        "--log",
        required=True,
        help="CSV: t, one position column per joint, <joint>.tau (or <joint>.current), optional "
        "<joint>.qd/.qdd",
    )
    p.add_argument("--out", required=True, help="folder for identified.urdf and the report")
    p.add_argument(
        "--validate",
        metavar="FILE.csv",
        help="a second log to validate on (default: the last 30%% of --log; the fit uses the rest)",
    )
    p.add_argument(
        "--cutoff",
        metavar="HZ",
        help="low-pass q (zero-phase Butterworth) before differentiating",
    )
    p.add_argument("--trim", metavar="SECONDS", help="drop this much of each log at each end")
    p.add_argument(
        "--filter-tau",
        action="store_true",
        help="with --cutoff, filter the torques too (default: q only; a filtered Coulomb "
        "friction step biases the fit)",
    )
    p.add_argument(
        "--no-physical",
        action="store_true",
        help="keep the least-squares estimate (no physical consistency constraint)",
    )
    p.add_argument(
        "--method", default="wls", metavar="ols|wls", help="least squares: ordinary or weighted"
    )
    for flag, what in (
        ("--torque-constants", "torque constants [N m/A]"),
        ("--gear-ratios", "gear ratios"),
        ("--efficiency", "gear efficiencies (0, 1]"),
    ):
        p.add_argument(
            flag,
            metavar="V|V1,V2,..|JOINT=V,..",
            help=f"for <joint>.current logs: the {what}, one for all joints, one per joint or "
            "by joint name",
        )


def _run(args: argparse.Namespace) -> int:
    if args.command == "size":
        from armdyn.size import main as size_main

        return size_main(args)
    if args.command == "select":
        from armdyn.sizing.cli import select_main

        return select_main(args)
    if args.command == "identify":
        from armdyn.identification.cli import main as identify_main

        return identify_main(args)
    if args.command == "verify":
        from armdyn.verify import main as verify_main

        return verify_main()
    if args.command == "reproduce":
        from armdyn.papers.reproduce import run

        try:
            run(args.out, plots=not args.no_plots, geared=not args.no_geared)
        except OSError as exc:  # --out not writable: bad input, one line
            print(
                f"armdyn reproduce: cannot write the report to {args.out!r}: {exc}", file=sys.stderr
            )
            return 2
        return 0
    return 1


if __name__ == "__main__":
    sys.exit(main())
