"""The cost of the joint trajectories of :mod:`armdyn.motion.profiles` on a UR5-sized move (6
joints, 3 waypoints, jerk-limited): planning (the ruckig solves and a 1 ms grid) with and
without stopping at the waypoint, and evaluating the result: the closed-form integration of
ruckig's phase data the module uses against a Python loop of ruckig's own
``Trajectory.at_time`` (the two agree to 1e-12: tests/motion/test_profiles.py), as the median
wall time per sample and their ratio in one run. The durations of the two moves are recorded
beside (what passing through the waypoint saves).

    python -m benchmarks.profiles [--samples N] [--out FILE]

writes ``benchmarks/results/profiles.json``.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from armdyn.motion import profiles, through_waypoints

from benchmarks.common import RESULTS, machine, median_time, write_json

WAYPOINTS = np.array(
    [
        [0.0, -1.2, 1.0, -1.4, -1.57, 0.0],
        [0.8, -1.0, 1.3, -1.8, -1.57, 0.4],
        [1.6, -1.4, 0.9, -1.2, -1.57, 0.0],
    ]
)
LIMITS = {"max_velocity": 3.15, "max_acceleration": 4.0, "max_jerk": 40.0}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=100_000, help="samples evaluated")
    parser.add_argument("--out", default=str(RESULTS / "profiles.json"))
    args = parser.parse_args(argv)
    plans = {}
    for stop in (False, True):
        seconds = median_time(
            lambda s=stop: through_waypoints(WAYPOINTS, stop_at_waypoints=s, **LIMITS), 1, 5
        )
        duration = through_waypoints(WAYPOINTS, stop_at_waypoints=stop, **LIMITS).duration
        key = "stop_at_waypoints" if stop else "through"
        plans[key] = {"plan_seconds": seconds, "duration": duration}
        print(f"{key:18s} plan + 1 ms grid {1e3 * seconds:7.2f} ms, motion {duration:.4f} s")
    lim = tuple(np.full(6, LIMITS[k]) for k in ("max_velocity", "max_acceleration", "max_jerk"))
    fast, _ = profiles._chain("benchmark", WAYPOINTS, list(range(6)), lim, False)
    slow, _ = profiles._chain("benchmark", WAYPOINTS, list(range(6)), lim, False, phases=False)
    x = np.linspace(0.0, fast.duration, args.samples)
    gap = float(np.max(np.abs(fast.at(x) - slow.at(x))))
    per = {}
    for name, chain in (("closed_form_phases", fast), ("ruckig_at_time_loop", slow)):
        per[name] = median_time(lambda c=chain: c.at(x), 1, 3) / args.samples
        print(f"{name:20s} {1e6 * per[name]:6.2f} us per sample of 6 joints")
    ratio = per["closed_form_phases"] / per["ruckig_at_time_loop"]
    print(f"ratio closed form / at_time loop: {ratio:.3f}; largest difference {gap:.1e}")
    write_json(
        args.out,
        {
            "command": " ".join(["python -m benchmarks.profiles", *(argv or sys.argv[1:])]),
            "machine": machine(),
            "samples": args.samples,
            "plans": plans,
            "seconds_per_sample": per,
            "ratio_closed_form_to_at_time": ratio,
            "largest_difference": gap,
        },
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
