"""The excitation design on the UR5 (armdyn.identification.fourier_excitation): the condition
number of the designed motion against random Fourier motions within the same limits (per-joint
and common scaling, several seeds), the design's iterations, objective evaluations and time,
and base_parameters' time.

    python -m benchmarks.identification_excitation [--quick] [--seeds 5] \
        [--out benchmarks/results/identification_excitation.json]

``--quick``: 3 harmonics, 40 samples, 1 start of 40 iterations (the tests' configuration);
otherwise the defaults (5 harmonics, 100 samples, 3 starts of 100 iterations). The UR5's own
limits (velocity and effort from the URDF, acceleration 5 x velocity per second, 0.05 rad
position margin), period 10 s. Times: wall clock and this process's CPU time (the machine may
be shared: the CPU time is the figure to compare; the functions run OpenBLAS on one thread
themselves, armdyn.identification.base.one_blas_thread).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import armdyn as ad
import numpy as np
from armdyn.identification import base_parameters, fourier_excitation, random_fourier

from benchmarks import common


def _timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    robots = common.robots_dir()
    if robots is None:
        print("example-robot-data not installed")
        return 1
    model = ad.load_urdf(str(robots / "ur_description/urdf/ur5_robot.urdf"))
    base, bw, bc = _timed(lambda: base_parameters(model))
    print(f"base_parameters (UR5, 200 samples): rank {base.rank}, {bw:.3f} s wall, {bc:.3f} s CPU")
    opts = {"harmonics": 3, "samples": 40} if args.quick else {"harmonics": 5, "samples": 100}
    design_opts = {"maxiter": 40, "starts": 1} if args.quick else {}
    design, dw, dc = _timed(lambda: fourier_excitation(model, base=base, **opts, **design_opts))
    info = design.info
    starts = np.round(info["start_conds"], 3)
    print(
        f"design {opts | design_opts}: cond {design.cond:.4g} (starts {starts}), "
        f"{info['iterations']} iterations, {info['evaluations']} cond evaluations, "
        f"{dw:.1f} s wall, {dc:.1f} s CPU"
    )
    rows = {}
    for scaling in ("joint", "common"):
        conds = [
            random_fourier(model, base=base, seed=100 + s, scaling=scaling, **opts).cond
            for s in range(args.seeds)
        ]
        rows[scaling] = conds
        ratio = np.array(conds) / design.cond
        print(
            f"random ({scaling} scaling), {args.seeds} seeds: cond {np.round(conds, 3)}; "
            f"ratio to the design min {ratio.min():.2f}, median {np.median(ratio):.2f}, "
            f"max {ratio.max():.2f}"
        )
    if args.out:
        result = {
            "command": "python -m benchmarks.identification_excitation"
            + (" --quick" if args.quick else "")
            + f" --seeds {args.seeds}",
            "base_rank": base.rank,
            "base_seconds_cpu": bc,
            "design": {
                "options": opts | design_opts,
                "cond": design.cond,
                "start_conds": info["start_conds"],
                "iterations": info["iterations"],
                "evaluations": info["evaluations"],
                "seconds_wall": dw,
                "seconds_cpu": dc,
            },
            "random_cond": rows,
        }
        with open(args.out, "w") as f:
            json.dump(result, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
