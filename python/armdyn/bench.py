"""``armdyn bench``: speed against peers, measured in one process on one machine, as ratios.

* Forward and inverse dynamics of real URDF arms (UR5 and Panda from ``example-robot-data``):
  armdyn (Cartesian Newton–Euler KKT path) against Pinocchio's ``aba`` and ``rnea``, per call
  from Python for both, and per call in a C++ loop for armdyn. The answers are cross-checked in
  the same run (relative error of q̈ and τ; also a test, ``tests/test_pinocchio.py``).
* A whole run: 5 s of the UR5 falling under gravity from rest (``armdyn workprecision ur5``):
  armdyn's DOPRI5 and RK4 against MuJoCo's import of the same URDF (RK4), Exudyn's redundant-
  coordinate model of it, and SciPy's ``solve_ivp`` (DOP853, RK45) on Pinocchio's ABA, each
  swept over tolerances or step sizes, with the error of each against a tight-tolerance
  reference; the summary gives the CPU time per step and to errors 1e-4 and 1e-6 rad.
* One DOPRI5 step of the 44-body geared arm (the first paper's mechanism), and 5 s of the
  five-DOF validation run (outputs every 0.01 s): by its default path, which is kinematic (every
  joint is driven: each output is solved from the constraints), and by DOPRI5 at rtol 1e-8.
* Scaling: spatial revolute chains of n = 2 … 1000 bodies, time per RK4 step against n, with the
  fitted log-log slope.

Peers come from the ``bench`` extra (``pip install .[bench]``); a missing peer is reported and
skipped. Results: JSON and a plot into the output folder (default ``docs/results``), with the
machine and the command. Timings are medians of repeated warm runs.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import site
import time
from pathlib import Path

import numpy as np

from armdyn import _core
from armdyn.scenes.extreme import random_chain
from armdyn.scenes.geared_arm import geared_arm_6dof
from armdyn.simulation import load_urdf, simulate

SCALING_FULL = (2, 5, 10, 20, 50, 100, 200, 500, 1000)
SCALING_QUICK = (2, 5, 10, 20, 50, 100)
ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
}


def robot_urdf(name: str) -> Path | None:
    """Path of an example-robot-data URDF, or None when the package is not installed."""
    for base in [*site.getsitepackages(), site.getusersitepackages()]:
        p = Path(base) / "cmeel.prefix" / "share" / "example-robot-data" / "robots" / ROBOTS[name]
        if p.is_file():
            return p
    return None


def mujoco_from_urdf(path: Path, pair: PinPair | None = None):
    """MuJoCo's own URDF import of the arm, for the same-URDF comparison: visual and collision
    elements removed (no meshes are needed and no contacts exist), static bodies fused, joint
    limits, damping, armature and friction off (Pinocchio's ABA and armdyn have none).
    Returns the MjModel and, with ``pair``, the map from Pinocchio's joint order to qpos."""
    import re

    import mujoco

    txt = Path(path).read_text()
    txt = re.sub(r"<(visual|collision)\b.*?</\1>", "", txt, flags=re.S)
    txt = re.sub(
        r"(<robot\b[^>]*>)",
        r'\1<mujoco><compiler discardvisual="true" fusestatic="true" balanceinertia="false"/>'
        r"</mujoco>",
        txt,
        count=1,
    )
    model = mujoco.MjModel.from_xml_string(txt)
    model.jnt_limited[:] = 0
    model.dof_damping[:] = 0.0
    model.dof_armature[:] = 0.0
    model.dof_frictionloss[:] = 0.0
    model.opt.gravity[:] = (0.0, 0.0, -9.81)
    if pair is None:
        return model, None
    names = [model.joint(i).name for i in range(model.njnt)]
    perm = np.array(
        [model.jnt_qposadr[names.index(pair.pm.names[i])] for i in range(1, pair.pm.njoints)]
    )
    return model, perm


def _median_time(fn, number: int, repeat: int = 7) -> float:
    """Median over `repeat` runs of the time per call of `number` calls (after one warm-up)."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t0) / number)
    return float(np.median(times))


def _cpp_time(loop, solver, a, b, c, number: int) -> float:
    """Median of 5 C++ timing loops (seconds per call)."""
    return float(np.median([loop(solver, a, b, c, number) for _ in range(5)]))


class PinPair:
    """The same URDF in armdyn and Pinocchio, with the coordinate map between them."""

    def __init__(self, path: Path):
        import pinocchio as pin

        self.pin = pin
        self.pm = pin.buildModelFromUrdf(str(path))
        self.pd = self.pm.createData()
        self.am = load_urdf(str(path))
        names = list(self.am.coord_names)
        pin_names = [self.pm.names[i] for i in range(1, self.pm.njoints)]
        if self.pm.nq != self.pm.nv or self.pm.nq != len(names):
            raise ValueError("only revolute/prismatic arms are compared")
        self.perm = np.array([names.index(n) for n in pin_names])
        self.fd = _core.JointSpaceForwardDynamics(self.am)  # CRBA + Cholesky
        self.fd_kkt = _core.JointSpaceForwardDynamics(self.am, "kkt")  # Cartesian KKT
        self.id = _core.JointSpaceInverseDynamics(self.am)

    def to_armdyn(self, x):
        out = np.empty(len(self.perm))
        out[self.perm] = x
        return out

    def cross_check(self, n: int = 50, seed: int = 0) -> dict:
        """Worst relative errors of armdyn against aba (q̈) and rnea (τ) over random states."""
        rng = np.random.default_rng(seed)
        worst_fd = worst_kkt = worst_id = 0.0
        for _ in range(n):
            q, v, tau, acc = rng.uniform(-np.pi, np.pi, size=(4, self.pm.nq))
            a_pin = self.pin.aba(self.pm, self.pd, q, v, tau)
            args = (self.to_armdyn(q), self.to_armdyn(v), self.to_armdyn(tau))
            a_ad = self.fd(*args)[self.perm]
            worst_fd = max(worst_fd, np.max(np.abs(a_ad - a_pin)) / np.max(np.abs(a_pin)))
            a_kkt = self.fd_kkt(*args)[self.perm]
            worst_kkt = max(worst_kkt, np.max(np.abs(a_kkt - a_pin)) / np.max(np.abs(a_pin)))
            t_pin = self.pin.rnea(self.pm, self.pd, q, v, acc)
            t_ad = self.id(self.to_armdyn(q), self.to_armdyn(v), self.to_armdyn(acc))[self.perm]
            worst_id = max(worst_id, np.max(np.abs(t_ad - t_pin)) / np.max(np.abs(t_pin)))
        return {
            "fd_rel_error": float(worst_fd),
            "fd_kkt_rel_error": float(worst_kkt),
            "id_rel_error": float(worst_id),
        }

    def timings(self, number: int = 2000) -> dict:
        rng = np.random.default_rng(1)
        q, v, tau = rng.uniform(-1, 1, size=(3, self.pm.nq))
        qa, va, ta = (self.to_armdyn(x) for x in (q, v, tau))
        pin, pm, pd = self.pin, self.pm, self.pd
        r = {
            "pin_aba_python_us": 1e6 * _median_time(lambda: pin.aba(pm, pd, q, v, tau), number),
            "pin_rnea_python_us": 1e6 * _median_time(lambda: pin.rnea(pm, pd, q, v, tau), number),
            "armdyn_fd_python_us": 1e6 * _median_time(lambda: self.fd(qa, va, ta), number),
            "armdyn_id_python_us": 1e6 * _median_time(lambda: self.id(qa, va, ta), number),
            "armdyn_fd_kkt_python_us": 1e6 * _median_time(lambda: self.fd_kkt(qa, va, ta), number),
            "armdyn_fd_cpp_us": 1e6
            * float(
                np.median([_core._time_forward_loop(self.fd, qa, va, ta, number) for _ in range(5)])
            ),
            "armdyn_fd_kkt_cpp_us": 1e6
            * float(
                np.median(
                    [_core._time_forward_loop(self.fd_kkt, qa, va, ta, number) for _ in range(5)]
                )
            ),
            "armdyn_id_cpp_us": 1e6
            * float(
                np.median([_core._time_inverse_loop(self.id, qa, va, ta, number) for _ in range(5)])
            ),
        }
        r["ratio_fd_python"] = r["armdyn_fd_python_us"] / r["pin_aba_python_us"]
        r["ratio_id_python"] = r["armdyn_id_python_us"] / r["pin_rnea_python_us"]
        r["ratio_fd_kkt_python"] = r["armdyn_fd_kkt_python_us"] / r["pin_aba_python_us"]
        return r


def bench_arms() -> dict:
    out = {}
    try:
        import pinocchio  # noqa: F401
    except ImportError:
        return {"skipped": "pinocchio (pip package 'pin') is not installed"}
    for name in ROBOTS:
        path = robot_urdf(name)
        if path is None:
            out[name] = {"skipped": "example-robot-data is not installed"}
            continue
        pair = PinPair(path)
        out[name] = {
            "dof": int(pair.pm.nq),
            "bodies": int(pair.am.nb),
            "kkt_path": pair.am.kkt_path,
            **pair.cross_check(),
            **pair.timings(),
        }
    return out


def bench_whole_run(quick: bool = False) -> dict:
    """5 s of the UR5 released from a bent pose (``armdyn workprecision ur5``): armdyn (DOPRI5,
    RK4) against MuJoCo (its URDF import, RK4), Exudyn (redundant coordinates) and SciPy's
    ``solve_ivp`` on Pinocchio's ABA, each swept over tolerances or steps, with the error against
    a DOP853 (rtol 1e-13) reference on Pinocchio. Summary: per integrator the CPU time of one
    step and the cheapest run reaching max angle errors 1e-4 and 1e-6 rad over the 100 outputs,
    and each peer's time over armdyn's best."""
    from armdyn import workprecision as wp

    try:
        r = wp.run_problem("ur5", quick=quick, echo=False)
    except (ImportError, _core.ModelError) as e:
        return {"skipped": str(e)}
    out = {"problem": r["title"], "error": r["error"], "reference_check": r["reference_check"]}
    per_step = {}
    for key, pts in r["curves"].items():
        ok = [p for p in pts if "steps" in p and np.isfinite(p.get("error", np.nan))]
        if ok:
            per_step[key] = float(np.median([1e6 * p["cpu_s"] / p["steps"] for p in ok]))
    out["us_per_step"] = per_step
    for target in (1e-4, 1e-6):
        best = {k: wp.cpu_to(pts, target) for k, pts in r["curves"].items()}
        best = {k: v for k, v in best.items() if v is not None}
        ours = min((v for k, v in best.items() if k.startswith("armdyn")), default=None)
        out[f"cpu_s_to_{target:g}"] = dict(sorted(best.items(), key=lambda kv: kv[1]))
        if ours:
            out[f"peer_over_armdyn_to_{target:g}"] = {
                k: v / ours for k, v in best.items() if not k.startswith("armdyn")
            }
    out["curves"] = r["curves"]
    return out


def bench_geared_arm() -> dict:
    """Time per DOPRI5 step of the 44-body geared arm with backlash (0.3 s into the motion).

    By default simulate integrates the welded model (bodies joined by fixed joints as one
    composite: 18 bodies, 96 rows); the full 44-body model (252 rows) is timed beside it, and
    the joint-space path (``coordinates="joint"``: 18 joint coordinates, CRBA), whose error
    control acts on (q, qd) instead of (u, v), so its steps differ."""
    model = geared_arm_6dof(n_motors=1, backlash=1e-4)

    def run(merge=True, coordinates="cartesian"):
        return simulate(
            model,
            0.3,
            rtol=1e-6,
            atol=1e-8,
            output_dt=0.3,
            merge_welded=merge,
            coordinates=coordinates,
        )

    out = {"bodies": int(model.nb), "kkt_path": model.kkt_path}
    for key, merge, coords in (
        ("welded", True, "cartesian"),
        ("full", False, "cartesian"),
        ("joint", True, "joint"),
    ):
        res = run(merge, coords)
        cpu = _median_time(lambda merge=merge, coords=coords: run(merge, coords), 1, 3)
        out[key] = {
            "solver_bodies": int(res.stats["solver_bodies"]),
            "solver_rows": int(res.stats["solver_rows"]),
            "steps": int(res.stats["steps"]),
            "rhs_evals": int(res.stats["rhs_evals"]),
            "us_per_step": 1e6 * cpu / res.stats["steps"],
            "us_per_rhs": 1e6 * cpu / res.stats["rhs_evals"],
        }
    out["us_per_step"] = out["welded"]["us_per_step"]
    out["target_us_per_step"] = 100.0
    return out


def bench_five_dof() -> dict:
    """5 s of the five-DOF validation arm (driven by the paper's trajectories), 500 outputs.

    Every joint is driven, so the default path is kinematic: each output state is solved from
    the constraints (no integration). The DOPRI5 run at rtol 1e-8 (which only feeds starting
    guesses to the same problems) is timed beside it, with the largest difference of the drive
    efforts between the two."""
    from armdyn.scenes.paper import five_dof_arm

    model = five_dof_arm()

    def run(integrator=None):
        return simulate(model, 5.0, integrator=integrator, rtol=1e-8, atol=1e-10, output_dt=0.01)

    res = run()
    dop = run("dopri5")
    scale = float(np.max(np.abs(dop.drive_forces)))
    return {
        "kkt_path": model.kkt_path,
        "path": res.stats["integrator"],
        "outputs": len(res.t),
        "factorizations": int(res.stats["factorizations"]),
        "ms": 1e3 * _median_time(run, 1, 5),
        "dopri5": {
            "steps": int(dop.stats["steps"]),
            "rhs_evals": int(dop.stats["rhs_evals"]),
            "factorizations": int(dop.stats["factorizations"]),
            "ms": 1e3 * _median_time(lambda: run("dopri5"), 1, 5),
        },
        "max_effort_difference_relative": float(
            np.max(np.abs(res.drive_forces - dop.drive_forces)) / scale
        ),
        "target_ms": 5.0,
    }


def bench_scaling(ns=(2, 5, 10, 20, 50, 100, 200, 500, 1000), steps: int = 20) -> dict:
    rows = []
    for n in ns:
        t0 = time.perf_counter()
        model = random_chain(n, masses=np.ones(n))
        build = time.perf_counter() - t0
        dt = 1e-4

        def run(model=model, dt=dt):
            return simulate(model, steps * dt, integrator="rk4", dt=dt, output_dt=steps * dt)

        per_step = _median_time(run, 1, 3) / steps
        rows.append(
            {"n": n, "kkt_path": model.kkt_path, "us_per_step": 1e6 * per_step, "finalize_s": build}
        )
    big = [r for r in rows if r["n"] >= 20]
    slope = float(
        np.polyfit(np.log([r["n"] for r in big]), np.log([r["us_per_step"] for r in big]), 1)[0]
    )
    return {"rows": rows, "slope_n_ge_20": slope, "target_slope": 1.1}


def plot(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    rows = results["scaling"]["rows"]
    ax[0].loglog([r["n"] for r in rows], [r["us_per_step"] for r in rows], "o-", label="armdyn")
    n = np.array([r["n"] for r in rows], float)
    ax[0].loglog(n, rows[-1]["us_per_step"] * n / n[-1], "k:", label="slope 1")
    ax[0].set_xlabel("bodies in the chain")
    ax[0].set_ylabel("µs per RK4 step")
    ax[0].set_title(f"scaling, fitted slope {results['scaling']['slope_n_ge_20']:.2f}")
    ax[0].legend()
    arms = {k: v for k, v in results["arms"].items() if isinstance(v, dict) and "dof" in v}
    labels, vals = [], []
    for name, r in arms.items():
        labels += [f"{name} FD", f"{name} ID"]
        vals += [r["ratio_fd_python"], r["ratio_id_python"]]
    if vals:
        ax[1].bar(labels, vals)
        ax[1].axhline(2.0, color="r", ls=":", label="target 2×")
        ax[1].set_ylabel("armdyn time / Pinocchio time (per call from Python)")
        ax[1].legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(out="docs/results", quick: bool = False, echo: bool = True) -> dict:
    results = {
        "command": "armdyn bench" + (" --quick" if quick else ""),
        "machine": {
            "platform": platform.platform(),
            "processor": platform.processor(),
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
        },
        "arms": bench_arms(),
        "whole_run": bench_whole_run(quick),
        "geared_arm_step": bench_geared_arm(),
        "five_dof_run": bench_five_dof(),
        "scaling": bench_scaling(
            (2, 5, 10, 20, 50, 100) if quick else (2, 5, 10, 20, 50, 100, 200, 500, 1000)
        ),
    }
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench.json").write_text(json.dumps(results, indent=1), encoding="utf-8")
    plot(results, out / "bench.png")
    if echo:
        print(json.dumps(results, indent=1))
        print(f"written: {out / 'bench.json'}, {out / 'bench.png'}")
    return results


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="armdyn bench", description=__doc__.splitlines()[0])
    p.add_argument("--out", default="docs/results", help="folder for bench.json and bench.png")
    p.add_argument("--quick", action="store_true", help="chains up to 100 bodies only")
    a = p.parse_args(argv)
    run(a.out, quick=a.quick)
    return 0
