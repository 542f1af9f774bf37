"""The cost of joint stops and actuator rotors in `simulate` (issue 22), on the UR5.

    python -m benchmarks.stops_and_rotors

1. Stops untouched: the UR5 (example-robot-data ``ur5_robot.urdf``, limits +-2 pi, elbow +-pi)
   released from ``common.UR5_Q0`` for 0.8 s (no limit reached) at rtol 1e-8, with
   ``limits="ignore"`` and ``"enforce"``: the median CPU time of 7 runs and the steps, both
   formulations (the enforced run evaluates the stops' event functions every step).
2. Rotors: the same arm falling for 1 s (limits ignored) bare and with a gear-reduced actuator
   on every joint (N = 100, 100, 80, 50, 50, 50): DOPRI5 steps and CPU time per formulation.
"""

from __future__ import annotations

import time

import armdyn as ad
import numpy as np

from benchmarks import common

GEARS = [(100.0, 6e-5), (100.0, 6e-5), (80.0, 4e-5), (50.0, 1.5e-5), (50.0, 1.5e-5), (50.0, 1.5e-5)]


def _median_cpu(fn, repeats=7):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return float(np.median(times)), out


def main() -> None:
    path = common.robot_urdf("ur5")
    if path is None:
        raise SystemExit("example-robot-data is not installed (pip install '.[test]')")
    bare = ad.load_urdf(str(path))
    start = dict(q0=common.UR5_Q0, qd0=np.zeros(6))
    print("1. stops untouched (0.8 s, rtol 1e-8)")
    for coords in ("cartesian", "joint"):
        for limits in ("ignore", "enforce"):
            cpu, r = _median_cpu(
                lambda c=coords, lim=limits: ad.simulate(
                    bare,
                    0.8,
                    output_dt=0.01,
                    rtol=1e-8,
                    atol=1e-10,
                    coordinates=c,
                    limits=lim,
                    **start,
                )
            )
            print(
                f"   {coords:9s} limits={limits:7s} steps {r.stats['steps']:4d}  "
                f"stop events {len(r.events['limits']['t'])}  {cpu * 1e3:.2f} ms"
            )
    b = ad.urdf_builder(str(path))
    for name, (n, j) in zip(bare.coord_names, GEARS, strict=True):
        b.add_actuator(name, n, j)
    geared = b.finalize()
    print("2. rotors (1 s fall, rtol 1e-6, limits ignored)")
    for label, model in (("bare", bare), ("actuated", geared)):
        for coords in ("cartesian", "joint"):
            cpu, r = _median_cpu(
                lambda m=model, c=coords: ad.simulate(
                    m, 1.0, output_dt=0.1, coordinates=c, limits="ignore", **start
                )
            )
            print(f"   {label:8s} {coords:9s} steps {r.stats['steps']:4d}  {cpu * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
