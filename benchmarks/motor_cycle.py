"""The vectorised motor side of a duty cycle (armdyn.sizing.motor.motor_cycle_values): 10,000
candidate drivetrains (random ratios, efficiencies, rotor inertias and two-node motors) on one
joint's cycle of about 1,000 samples (a shoulder's 998-sample motion and a dwell), the
periodic steady state with the copper's R(T). Reports the median wall and CPU time of a call
and its peak traced memory (tracemalloc), per chunk size.

    python -m benchmarks.motor_cycle [--candidates K] [--samples N] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import tracemalloc
from pathlib import Path

import armdyn as ad
import numpy as np

from benchmarks.common import cpu_time, machine, write_json


def shoulder_load(samples: int):
    """A 2 kg link at 0.5 m lifted by a quintic over 1 s, then a 2 s dwell: its JointLoad."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("link", 2.0, [0.01, 0.05, 0.05], position=(0.5, 0.0, 0.0))
    b.add_revolute("shoulder", "ground", "link", point=(0, 0, 0), axis=(0, 1, 0))
    model = b.finalize()
    t = np.linspace(0.0, 1.0, samples - 2)
    s = t
    q = 10 * s**3 - 15 * s**4 + 6 * s**5
    qd = 30 * s**2 - 60 * s**3 + 30 * s**4
    qdd = 60 * s - 180 * s**2 + 120 * s**3
    cycle = ad.duty_cycle(model, (t, q[:, None], qd[:, None], qdd[:, None]), dwell=2.0)
    return cycle.joint_load("shoulder")


def candidates(k: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    motors = {
        "torque_constant": rng.uniform(0.05, 0.2, k),
        "resistance": rng.uniform(0.2, 2.0, k),
        "voltage": np.full(k, 48.0),
        "continuous_torque": rng.uniform(0.2, 2.0, k),
        "peak_torque": rng.uniform(1.0, 6.0, k),
        "max_speed": np.full(k, 600.0),
        "thermal_resistance_winding": rng.uniform(0.5, 2.0, k),
        "thermal_resistance_housing": rng.uniform(0.5, 2.0, k),
        "thermal_time_constant_winding": rng.uniform(10.0, 60.0, k),
        "thermal_time_constant_housing": rng.uniform(300.0, 2000.0, k),
        "max_winding_temperature": np.full(k, 155.0),
    }
    return rng.uniform(30, 160, k), rng.uniform(0.6, 0.95, k), rng.uniform(1e-5, 1e-4, k), motors


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--candidates", type=int, default=10000)
    p.add_argument("--samples", type=int, default=1000)
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    from armdyn.sizing.motor import CHUNK, motor_cycle_values

    load = shoulder_load(args.samples)
    ratio, eta, j, motors = candidates(args.candidates)
    rows = []
    for chunk in sorted({CHUNK, 2 * CHUNK}):

        def call(chunk=chunk):
            return motor_cycle_values(load, ratio, eta, j, motors, chunk=chunk)

        walls = []
        for _ in range(5):
            t0 = time.perf_counter()
            call()
            walls.append(time.perf_counter() - t0)
        cpu, _, out = cpu_time(call, 5)
        tracemalloc.start()
        call()
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        rows.append(
            {
                "chunk": chunk,
                "wall_median_s": float(np.median(walls)),
                "wall_min_s": float(np.min(walls)),
                "cpu_median_s": cpu,
                "peak_traced_MiB": peak / 2**20,
                "checked_finite": bool(np.all(np.isfinite(out["winding_temperature_peak"]))),
            }
        )
        print(
            f"k={args.candidates} n={len(load.t)} chunk={chunk}: wall median "
            f"{rows[-1]['wall_median_s']:.3f} s (min {rows[-1]['wall_min_s']:.3f}), CPU median "
            f"{cpu:.3f} s, peak traced memory {rows[-1]['peak_traced_MiB']:.0f} MiB"
        )
    result = {
        "command": "python -m benchmarks.motor_cycle " + " ".join(sys.argv[1:]),
        "candidates": args.candidates,
        "samples": len(load.t),
        "rows": rows,
        "machine": machine(),
        # a shared machine: the 1-minute load average when the run ended (2 cores)
        "load_average_1min": os.getloadavg()[0],
    }
    print("written", write_json(Path(args.out) / "motor_cycle.json", result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
