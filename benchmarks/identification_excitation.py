"""The excitation design (armdyn.identification.fourier_excitation) on the UR5 and the Panda: the
condition number of the designed motion against random Fourier motions within the same limits
(per-joint and common scaling, many seeds), by three condition numbers, with the design's
iterations, objective evaluations and time.

    python -m benchmarks.identification_excitation [--quick] [--seeds 20] \
        [--robots ur5,panda] [--criterion scaled|raw] [--harmonics H] [--period T] \
        [--samples S] [--starts K] [--maxiter N] \
        [--out benchmarks/results/identification_excitation.json]

The three condition numbers of the stacked base regressor over one period (``samples`` equally
spaced times):

- ``scaled``: each column divided by its RMS over 200 random states within the limits
  (fourier_excitation's default criterion: fixed per model and limits, independent of each
  joint's units);
- ``raw``: the base regressor as it is, in SI units (what the literature reports: Swevers et al.
  1997, Gautier and Khalil, Presse and Gautier; it changes with the units);
- ``equilibrated``: each column divided by its own norm over this motion (unit-free and within
  sqrt(rank) of the best diagonal column scaling, van der Sluis 1969: only the collinearity of
  the columns, not how strongly each is excited).

The random baseline: ``random_fourier`` (standard normal coefficients scaled to 90 % of what the
position, speed and acceleration bounds allow, per joint or by one common factor, shrunk until
the torques hold), the same period, harmonics, samples and limits as the design; seeds 100,
101, .... Ratios: random / design per draw, reported as the worst (min) and the median.

Defaults: fourier_excitation's (period 10 s, 5 harmonics, 100 samples, 3 starts of 100 SLSQP
iterations); ``--quick``: 3 harmonics, 40 samples, 1 start of 40 iterations (the tests' size).
The robots' own limits (velocity and effort from the URDF, acceleration 5 x velocity per second,
0.05 rad position margin; the Panda's finger 0.002 m). Times: wall clock and this process's CPU
time (the machine may be shared: the CPU time is the figure to compare; the functions run
OpenBLAS on one thread themselves, armdyn.identification.base.one_blas_thread).
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

ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", {}),
    "panda": ("panda_description/urdf/panda.urdf", {"position_margin": [0.05] * 7 + [0.002]}),
}


def _timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def limit_scale(model, base, limits) -> np.ndarray:
    """The "scaled" criterion's column scale, recomputed: each base regressor column's RMS over
    200 random states within the limits (seed 0; q, qd, qdd uniform within the position limits
    minus the margin, +-velocity, +-acceleration; every joint of these robots has finite
    position limits)."""
    rng = np.random.default_rng(0)
    q = rng.uniform(limits["lower"], limits["upper"], size=(200, model.n_dofs))
    qd = rng.uniform(-1.0, 1.0, size=(200, model.n_dofs)) * limits["velocity"]
    qdd = rng.uniform(-1.0, 1.0, size=(200, model.n_dofs)) * limits["acceleration"]
    yr = base.regressor(ad.joint_torque_regressor(model, q, qd, qdd)).reshape(-1, base.rank)
    return np.sqrt(np.mean(yr**2, axis=0))


def conds(model, base, motion, samples: int) -> dict[str, float]:
    """The three condition numbers of ``motion``'s stacked base regressor (see the module)."""
    t = motion.period * np.arange(samples) / samples
    y = base.regressor(ad.joint_torque_regressor(model, *motion.evaluate(t)))
    y = y.reshape(-1, base.rank)
    scale = limit_scale(model, base, motion.info["limits"])
    return {
        "scaled": float(np.linalg.cond(y / scale)),
        "raw": float(np.linalg.cond(y)),
        "equilibrated": float(np.linalg.cond(y / np.linalg.norm(y, axis=0))),
    }


def _robot(name, args, opts, design_opts, seeds):
    path, extra = ROBOTS[name]
    model = ad.load_urdf(str(common.robots_dir() / path))
    base = base_parameters(model)
    kw = opts | extra
    design, dw, dc = _timed(lambda: fourier_excitation(model, base=base, **kw, **design_opts))
    info = design.info
    dconds = conds(model, base, design, kw["samples"])
    print(
        f"{name}: rank {base.rank}; design {kw | design_opts}: cond {design.cond:.4g} "
        f"(criterion {info['criterion']}; starts {np.round(info['start_conds'], 2)}), "
        f"{info['iterations']} iterations, {info['evaluations']} evaluations, "
        f"{dw:.1f} s wall, {dc:.1f} s CPU; {', '.join(f'{k} {v:.4g}' for k, v in dconds.items())}"
    )
    rows = {}
    for scaling in ("joint", "common"):
        draws = [
            conds(
                model,
                base,
                random_fourier(model, base=base, seed=100 + s, scaling=scaling, **kw),
                kw["samples"],
            )
            for s in range(seeds)
        ]
        rows[scaling] = {}
        for metric in dconds:
            values = np.array([d[metric] for d in draws])
            ratio = values / dconds[metric]
            rows[scaling][metric] = {
                "random": values.tolist(),
                "ratio_min": float(ratio.min()),
                "ratio_median": float(np.median(ratio)),
                "ratio_max": float(ratio.max()),
            }
            print(
                f"  random ({scaling}), {seeds} seeds, {metric}: median {np.median(values):.4g} "
                f"[{values.min():.4g}, {values.max():.4g}]; random / design: worst "
                f"{ratio.min():.2f}, median {np.median(ratio):.2f}"
            )
    return {
        "base_rank": base.rank,
        "design": {
            "options": kw | design_opts,
            "cond": design.cond,
            "conds": dconds,
            "start_conds": info["start_conds"],
            "iterations": info["iterations"],
            "evaluations": info["evaluations"],
            "seconds_wall": dw,
            "seconds_cpu": dc,
        },
        "random": rows,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--robots", default="ur5,panda")
    ap.add_argument("--criterion", default="scaled", choices=("scaled", "raw"))
    ap.add_argument("--harmonics", type=int, default=None)
    ap.add_argument("--period", type=float, default=10.0)
    ap.add_argument("--samples", type=int, default=None)
    ap.add_argument("--starts", type=int, default=None)
    ap.add_argument("--maxiter", type=int, default=None)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    if common.robots_dir() is None:
        print("example-robot-data not installed")
        return 1
    opts = {"harmonics": 3, "samples": 40} if args.quick else {"harmonics": 5, "samples": 100}
    design_opts = {"maxiter": 40, "starts": 1} if args.quick else {"maxiter": 100, "starts": 3}
    for key in ("harmonics", "samples"):
        if getattr(args, key) is not None:
            opts[key] = getattr(args, key)
    for key in ("starts", "maxiter"):
        if getattr(args, key) is not None:
            design_opts[key] = getattr(args, key)
    opts |= {"period": args.period, "criterion": args.criterion}
    result = {
        "command": "python -m benchmarks.identification_excitation "
        + " ".join(argv or sys.argv[1:])
    }
    for name in args.robots.split(","):
        result[name] = _robot(name, args, opts, design_opts, args.seeds)
    if args.out:
        with open(args.out, "w") as f:
            json.dump(result, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
