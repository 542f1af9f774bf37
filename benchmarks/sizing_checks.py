"""The cost of the vectorised gearbox, bearing, emergency-stop, brake, drive and bus checks
(issue 33, :mod:`armdyn.sizing.gearbox`, :mod:`armdyn.sizing.drive`) for k candidates on a
cycle of n samples: the median wall time per call and per candidate, for the selection's
budget (6 joints x 10,000 combinations <= 10 s with every check).

The cycle is synthetic (a seeded smooth motion with a dwell and random reaction wrenches; the
checks' cost does not depend on the values); the candidates' columns are random, 20 distinct
bearing offsets (a catalog has few gearbox sizes). ``bus_values`` is timed for one set of 6
axes against k drives (the bus of a chosen set), and for k sets.

    python -m benchmarks.sizing_checks [--n N] [--k K] [--out FILE]

writes ``benchmarks/results/sizing_checks.json``.
"""

from __future__ import annotations

import argparse
import sys
from types import SimpleNamespace

import numpy as np
from armdyn.sizing import drive as dv
from armdyn.sizing import gearbox as gb

from benchmarks.common import RESULTS, machine, median_time, write_json


def cycle(n: int, rng) -> SimpleNamespace:
    t = np.linspace(0.0, 4.0, n)
    speed = np.where(t < 3.0, np.sin(np.pi * t / 3.0) ** 2, 0.0)
    return SimpleNamespace(
        t=t,
        speed=speed,
        torque=20.0 * np.cos(t),
        gravity_torque=10.0 * np.cos(t),
        inertia=0.5 + 0.1 * np.sin(t),
        force=rng.normal(0.0, 100.0, (n, 3)),
        moment=rng.normal(0.0, 10.0, (n, 3)),
        axis=np.array([0.0, 0.0, 1.0]),
    )


def calls(n: int, k: int) -> dict:
    rng = np.random.default_rng(0)
    load = cycle(n, rng)
    ratio = rng.uniform(30.0, 160.0, k)
    gears = {c: rng.uniform(1.0, 100.0, k) for c in [*gb.GEAR_COLUMNS, "momentary_peak_torque"]}
    gears["life_exponent"] = np.full(k, 3.0)
    bearings = {c: rng.uniform(0.01, 100.0, k) for c in gb.BEARING_COLUMNS}
    bearings["bearing_offset"] = rng.choice(np.linspace(0.0, 0.05, 20), k)
    eta, j_rot, t_s = np.full(k, 0.8), rng.uniform(1e-6, 1e-4, k), rng.uniform(0.5, 5.0, k)
    motor = {x: rng.uniform(1.0, 10.0, k) for x in ("peak_current", "rms_current")}
    motor["peak_terminal_voltage"] = rng.uniform(10.0, 60.0, k)
    drives = {"peak_current": rng.uniform(1, 20, k), "continuous_current": rng.uniform(1, 10, k)}
    drives["bus_voltage"] = np.full(k, 48.0)
    bus = {"bus_voltage": 48.0, "max_bus_voltage": 60.0, "bus_capacitance": rng.uniform(0, 1e-3, k)}
    powers = rng.normal(0.0, 100.0, (6, n))
    return {
        "gearbox_cycle_values": lambda: gb.gearbox_cycle_values(load, ratio, gears),
        "bearing_cycle_values": lambda: gb.bearing_cycle_values(load, bearings),
        "emergency_stop_values": lambda: gb.emergency_stop_values(
            load, ratio, eta, j_rot, t_s, gears
        ),
        "brake_values": lambda: dv.brake_values(load, ratio, t_s),
        "drive_values": lambda: dv.drive_values(motor, drives),
        "bus_values (1 set x k drives)": lambda: dv.bus_values(load.t, powers, drives=bus),
        "bus_values (1 set, 1 drive)": lambda: dv.bus_values(
            load.t, powers, drives={**bus, "bus_capacitance": 1e-3}
        ),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2000, help="samples per cycle")
    parser.add_argument("--k", type=int, default=10000, help="candidates")
    parser.add_argument("--out", default=str(RESULTS / "sizing_checks.json"))
    args = parser.parse_args(argv)
    rows = {}
    for name, fn in calls(args.n, args.k).items():
        seconds = median_time(fn, number=1, repeat=5)
        rows[name] = {"seconds": seconds, "microseconds_per_candidate": 1e6 * seconds / args.k}
        print(f"{name:32s} {seconds:8.4f} s  {1e6 * seconds / args.k:8.2f} us/candidate")
    total = sum(r["seconds"] for n, r in rows.items() if not n.startswith("bus"))
    print(f"per joint, every per-candidate check: {total:.3f} s (x 6 joints: {6 * total:.2f} s)")
    write_json(
        args.out,
        {
            "command": " ".join(["python -m benchmarks.sizing_checks", *(argv or sys.argv[1:])]),
            "machine": machine(),
            "n": args.n,
            "k": args.k,
            "calls": rows,
            "per_joint_seconds": total,
        },
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
