"""``armdyn.sweep`` on a LocalCluster of 2 workers against the same points run serially (issue 23's
target: >= 1.6x the serial throughput on a grid of >= 16 points).

Each point is a real armdyn computation of 0.2-0.5 s CPU: the first paper's geared arm
(:func:`armdyn.papers.geared_arm.geared_arm_6dof`, 0.1 mm backlash) with 1-4 motors on its waist and
a move ending at 1.5-3 s, simulated in joint coordinates, and the waist motors' peak and RMS torques
from ``armdyn.sizing_report``. The function builds its model itself, so nothing but the grid values
travels to the workers.

A control runs the same points on a ``multiprocessing`` pool of 2 processes: on a machine
shared with other sessions, it shows how much parallelism the machine gave at that moment.
Serial and parallel runs are interleaved (``--rounds`` rounds, default 2) and the ratio is the
median of the per-round ratios. The cluster is started and warmed up (every worker imports
armdyn and runs one point) before the timing: its start-up, also recorded, is a one-off cost of a
session, not of a sweep. Results are checked equal to the serial ones.

    python -m benchmarks.sweep [--rounds N] [--out FILE]

writes ``benchmarks/results/sweep.json``.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import sys
import time

import armdyn as ad
import cloudpickle
import numpy as np

from benchmarks.common import RESULTS, machine, write_json

GRID = {"n_motors": [1, 2, 3, 4], "move_end": [1.5, 2.0, 2.5, 3.0]}
BACKLASH = 1e-4  # the paper's 0.1 mm stage-2 clearance: tooth impacts located as events


def geared_point(n_motors, move_end):
    """The geared arm with ``n_motors`` on the waist (0.1 mm backlash), a move from 0.1 s to
    ``move_end``, run to ``move_end + 0.5`` s: the waist motors' largest peak and RMS torque
    [N m], the steps, and the CPU time of the point (not compared)."""
    from armdyn.papers.geared_arm import geared_arm_6dof

    c0 = time.process_time()
    arm = geared_arm_6dof(n_motors=n_motors, backlash=BACKLASH, t_start=0.1, t_end=move_end)
    res = ad.simulate(arm, move_end + 0.5, output_dt=0.005, coordinates="joint")
    tab = ad.sizing_report(res, arm).table
    waist = [k for k in tab.index if k.startswith("waist_") and k.endswith("_motor")]
    return {
        "peak_torque": float(tab.loc[waist, "peak_torque"].max()),
        "rms_torque": float(tab.loc[waist, "rms_torque"].max()),
        "steps": int(res.stats["steps"]),
        "cpu_s": time.process_time() - c0,
    }


def serial(grid):
    """The same points in this process, C order of the product (as sweep spawns them)."""
    out = {}
    for n in grid["n_motors"]:
        for e in grid["move_end"]:
            out[(n, e)] = geared_point(n, e)
    return out


def _point(p):
    return geared_point(*p)


def pool_time(pool, grid) -> float:
    """The same points on a ``multiprocessing`` pool of 2 spawned processes (the control: what
    two processes get from this machine right now, without Dask)."""
    pts = [(n, e) for n in grid["n_motors"] for e in grid["move_end"]]
    t0 = time.perf_counter()
    pool.map(_point, pts, chunksize=1)
    return time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--out", default=str(RESULTS / "sweep.json"))
    args = ap.parse_args(argv)

    import distributed

    # the workers need not import this module: geared_point travels by value
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    points = len(GRID["n_motors"]) * len(GRID["move_end"])
    geared_point(1, 1.5)  # warm: imports, first-call costs
    t0 = time.perf_counter()
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    )
    client = distributed.Client(cluster)
    pool = multiprocessing.get_context("spawn").Pool(2)
    pool.map(_point, [(1, 1.5), (2, 1.5)])  # warm both processes
    ad.sweep(geared_point, client, n_motors=[1, 2], move_end=[1.5])  # warm both workers
    startup = time.perf_counter() - t0
    load = [os.getloadavg()[0]]
    rounds = []
    try:
        for r in range(args.rounds):
            t0 = time.perf_counter()
            ref = serial(GRID)
            t_serial = time.perf_counter() - t0
            t0 = time.perf_counter()
            ds = ad.sweep(geared_point, client, **GRID)
            t_sweep = time.perf_counter() - t0
            t_pool = pool_time(pool, GRID)
            assert (ds["status"].values == "ok").all(), ds["status"].values
            for (n, e), row in ref.items():
                for k in ("peak_torque", "rms_torque", "steps"):
                    assert ds[k].sel(n_motors=n, move_end=e).item() == row[k], (n, e, k)
            cpu_serial = sum(row["cpu_s"] for row in ref.values())
            cpu_workers = float(ds["cpu_s"].sum())
            rounds.append(
                {
                    "serial_s": t_serial,
                    "sweep_s": t_sweep,
                    "ratio": t_serial / t_sweep,
                    "pool_s": t_pool,
                    "pool_ratio": t_serial / t_pool,
                    "serial_cpu_s": cpu_serial,
                    "workers_cpu_s": cpu_workers,
                    "load_average_1min": os.getloadavg()[0],
                }
            )
            print(
                f"round {r + 1}: serial {t_serial:.2f} s (CPU {cpu_serial:.2f} s), sweep on 2 "
                f"workers {t_sweep:.2f} s (workers' CPU {cpu_workers:.2f} s), throughput ratio "
                f"{t_serial / t_sweep:.2f}; multiprocessing pool of 2: {t_pool:.2f} s, ratio "
                f"{t_serial / t_pool:.2f}; load average {os.getloadavg()[0]:.1f}"
            )
    finally:
        pool.close()
        client.close()
        cluster.close()
    ratio = float(np.median([x["ratio"] for x in rounds]))
    best = min(rounds, key=lambda x: x["serial_s"])
    record = {
        "command": "python -m benchmarks.sweep" + (" " + " ".join(argv) if argv else ""),
        "target": "sweep on a LocalCluster of 2 workers >= 1.6x the serial throughput",
        "grid": GRID,
        "points": points,
        "point": "geared_arm_6dof(n_motors, backlash=1e-4, t_start=0.1, t_end=move_end), "
        "simulate(move_end + 0.5, output_dt=0.005, coordinates='joint'), sizing_report",
        "mean_point_s": best["serial_s"] / points,
        "rounds": rounds,
        "throughput_ratio": ratio,
        "control_pool_ratio": float(np.median([x["pool_ratio"] for x in rounds])),
        "target_met": ratio >= 1.6,
        "cluster_startup_and_warmup_s": startup,
        "results_equal_serial": True,
        "load_average_1min_start": load[0],
        "note": "2 cores shared with other sessions under the kernel's autogroup scheduling "
        "(/proc/sys/kernel/sched_autogroup_enabled = 1): while other sessions are busy, this "
        "session gets its fair share of the 2 cores however many processes it runs, so neither "
        "the sweep nor the control pool can reach 2x; the control pool's ratio is what the "
        "machine allowed during the run, the sweep's ratio over it is Dask's own efficiency",
        "machine": machine(),
    }
    path = write_json(args.out, record)
    print(f"median throughput ratio (serial time / sweep time): {ratio:.2f} -> {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
