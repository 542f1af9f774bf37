"""Speed against peers, measured in one process on one machine, as ratios.

    python -m benchmarks.bench [--quick] [--out DIR]        (from the repository root)

* Per call from Python, on real URDF arms (UR5 and Panda from ``example-robot-data``): armdyn's
  public ``forward_dynamics(model, q, qd, tau)``, ``inverse_dynamics(model, q, qd, qdd)`` and
  ``mass_matrix(model, q)`` against Pinocchio's ``aba``, ``rnea`` and ``crba``, one state per
  call for both (targets: ratio ≤ 1). The answers are cross-checked in the same run (relative
  error; also a test, ``tests/algorithm/test_pinocchio.py``).
  ``forward_dynamics(..., method="cartesian")`` (the KKT path) is timed beside them.
* A batch: ``forward_dynamics(model, Q, QD, TAU)`` on 1000 states (2-D arrays, one state per row)
  in one call against a Python loop of ``pin.aba`` over the same states (target: ratio ≤ 0.5);
  likewise ``inverse_dynamics`` against a loop of ``pin.rnea``.
* A whole run: 5 s of the UR5 falling under gravity from rest (``workprecision ur5``): armdyn's
  integrators against MuJoCo's import of the same URDF (RK4), Exudyn's redundant-coordinate model
  of it, and SciPy's ``solve_ivp`` (DOP853, RK45) on Pinocchio's ABA, each swept over tolerances
  or step sizes, with the error of each against a tight-tolerance reference; the summary gives
  the CPU time per step and to errors 1e-4 and 1e-6 rad.
* One DOPRI5 step of the 44-body geared arm (the first paper's mechanism), and 5 s of the
  five-DOF validation run (outputs every 0.01 s): by its default path, which is kinematic (every
  joint is driven: each output is solved from the constraints), and by DOPRI5 at rtol 1e-8.
* Scaling: spatial revolute chains of n = 2 … 1000 bodies, time per RK4 step against n, with the
  fitted log-log slope.

Peers come from the ``bench`` extra (``pip install ".[bench]"``); a missing peer is reported and
skipped. Results: ``bench.json`` and ``bench.png`` in the output folder (default
``benchmarks/results``), with the machine and the command. Timings are medians of repeated warm
runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import armdyn as ad
import numpy as np
from armdyn import ModelError
from armdyn.papers.geared_arm import geared_arm_6dof
from armdyn.scenes.extreme import random_chain

from benchmarks import common
from benchmarks.common import median_time
from benchmarks.peers.pinocchio import PinPair

SCALING_FULL = (2, 5, 10, 20, 50, 100, 200, 500, 1000)
SCALING_QUICK = (2, 5, 10, 20, 50, 100)
BATCH = 1000  # states in the batch call
TARGET_PER_CALL = 1.0  # armdyn / Pinocchio, one state per call from Python
TARGET_BATCH = 0.5  # one armdyn call on BATCH states / a Python loop of pin.aba over them


def per_call_timings(pair: PinPair, number: int = 2000) -> dict:
    """Microseconds per call from Python, one state per call, and armdyn / Pinocchio ratios."""
    pin, pm, pd, am = pair.pin, pair.pm, pair.pd, pair.am
    rng = np.random.default_rng(1)
    q, v, tau = rng.uniform(-1, 1, size=(3, pm.nq))
    qa, va, ta = (pair.to_armdyn(x) for x in (q, v, tau))

    t = common.interleaved_times(
        {
            "pin_aba": lambda: pin.aba(pm, pd, q, v, tau),
            "armdyn_forward_dynamics": lambda: ad.forward_dynamics(am, qa, va, ta),
            "pin_rnea": lambda: pin.rnea(pm, pd, q, v, tau),
            "armdyn_inverse_dynamics": lambda: ad.inverse_dynamics(am, qa, va, ta),
            "pin_crba": lambda: pin.crba(pm, pd, q),
            "armdyn_mass_matrix": lambda: ad.mass_matrix(am, qa),
            "armdyn_forward_dynamics_cartesian": lambda: ad.forward_dynamics(
                am, qa, va, ta, method="cartesian"
            ),
        },
        number,
    )
    r = {f"{name}_us": 1e6 * t[name] for name in t if name != "rounds"}
    # ratios round by round (interleaved: the same load on both), then their median
    r["ratio_forward_dynamics"] = common.paired_ratio(t, "armdyn_forward_dynamics", "pin_aba")
    r["ratio_inverse_dynamics"] = common.paired_ratio(t, "armdyn_inverse_dynamics", "pin_rnea")
    r["ratio_mass_matrix"] = common.paired_ratio(t, "armdyn_mass_matrix", "pin_crba")
    r["ratio_forward_dynamics_cartesian"] = common.paired_ratio(
        t, "armdyn_forward_dynamics_cartesian", "pin_aba"
    )
    return r


def batch_timings(pair: PinPair, n: int = BATCH, number: int = 5) -> dict:
    """One armdyn call on ``n`` states (2-D arrays) against a Python loop of Pinocchio over the
    same states: milliseconds per batch, ratios, and the batch answers' worst relative error
    against Pinocchio's."""
    pin, pm, pd, am = pair.pin, pair.pm, pair.pd, pair.am
    rng = np.random.default_rng(2)
    Q, V, U = rng.uniform(-np.pi, np.pi, size=(3, n, pm.nq))
    Qa, Va, Ua = (pair.to_armdyn(x) for x in (Q, V, U))

    def aba_loop():
        return [pin.aba(pm, pd, Q[i], V[i], U[i]) for i in range(n)]

    def rnea_loop():
        return [pin.rnea(pm, pd, Q[i], V[i], U[i]) for i in range(n)]

    a_ad = ad.forward_dynamics(am, Qa, Va, Ua)[:, pair.perm]
    t_ad = ad.inverse_dynamics(am, Qa, Va, Ua)[:, pair.perm]
    # the reference adds the URDF's <dynamics> joint friction, which armdyn imports and
    # Pinocchio's algorithms leave out (PinPair.aba, PinPair.rnea); the timed loops are plain
    a_pin = np.array([pair.aba(Q[i], V[i], U[i]) for i in range(n)])
    t_pin = np.array([pair.rnea(Q[i], V[i], U[i]) for i in range(n)])
    t = common.interleaved_times(
        {
            "pin_aba_loop": aba_loop,
            "armdyn_forward_dynamics": lambda: ad.forward_dynamics(am, Qa, Va, Ua),
            "pin_rnea_loop": rnea_loop,
            "armdyn_inverse_dynamics": lambda: ad.inverse_dynamics(am, Qa, Va, Ua),
        },
        number,
    )
    r = {
        "states": n,
        "fd_rel_error": float(np.max(np.abs(a_ad - a_pin)) / np.max(np.abs(a_pin))),
        "id_rel_error": float(np.max(np.abs(t_ad - t_pin)) / np.max(np.abs(t_pin))),
    }
    r.update({f"{name}_ms": 1e3 * t[name] for name in t if name != "rounds"})
    r["ratio_forward_dynamics"] = common.paired_ratio(t, "armdyn_forward_dynamics", "pin_aba_loop")
    r["ratio_inverse_dynamics"] = common.paired_ratio(t, "armdyn_inverse_dynamics", "pin_rnea_loop")
    r["armdyn_forward_dynamics_us_per_state"] = 1e3 * r["armdyn_forward_dynamics_ms"] / n
    return r


def bench_arms(quick: bool = False) -> dict:
    """Per-call and batch timings of the public functions on the UR5 and the Panda."""
    out = {}
    try:
        import pinocchio  # noqa: F401
    except ImportError:
        return {"skipped": "pinocchio (pip package 'pin') is not installed"}
    for name in common.ROBOTS:
        path = common.robot_urdf(name)
        if path is None:
            out[name] = {"skipped": "example-robot-data is not installed"}
            continue
        pair = PinPair(path)
        out[name] = {
            "dof": int(pair.pm.nq),
            "bodies": int(pair.am.nb),
            "kkt_path": pair.am.kkt_path,
            **pair.cross_check(),
            "per_call": per_call_timings(pair, 500 if quick else 2000),
            "batch": batch_timings(pair, number=2 if quick else 5),
        }
    out["targets"] = {"per_call": TARGET_PER_CALL, "batch": TARGET_BATCH}
    return out


def bench_whole_run(quick: bool = False) -> dict:
    """5 s of the UR5 released from a bent pose (``workprecision ur5``): armdyn (DOPRI5,
    RK4) against MuJoCo (its URDF import, RK4), Exudyn (redundant coordinates) and SciPy's
    ``solve_ivp`` on Pinocchio's ABA, each swept over tolerances or steps, with the error against
    a DOP853 (rtol 1e-13) reference on Pinocchio. Summary: per integrator the CPU time of one
    step and the cheapest run reaching max angle errors 1e-4 and 1e-6 rad over the 100 outputs,
    and each peer's time over armdyn's best."""
    from benchmarks import workprecision as wp

    try:
        r = wp.run_problem("ur5", quick=quick, echo=False)
    except (ImportError, ModelError) as e:
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
        return ad.simulate(
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
        cpu = median_time(lambda merge=merge, coords=coords: run(merge, coords), 1, 3)
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
    from armdyn.papers.five_dof import five_dof_arm

    model = five_dof_arm()

    def run(integrator=None):
        return ad.simulate(model, 5.0, integrator=integrator, rtol=1e-8, atol=1e-10, output_dt=0.01)

    res = run()
    dop = run("dopri5")
    scale = float(np.max(np.abs(dop.drive_forces)))
    return {
        "kkt_path": model.kkt_path,
        "path": res.stats["integrator"],
        "outputs": len(res.t),
        "factorizations": int(res.stats["factorizations"]),
        "ms": 1e3 * median_time(run, 1, 5),
        "dopri5": {
            "steps": int(dop.stats["steps"]),
            "rhs_evals": int(dop.stats["rhs_evals"]),
            "factorizations": int(dop.stats["factorizations"]),
            "ms": 1e3 * median_time(lambda: run("dopri5"), 1, 5),
        },
        "max_effort_difference_relative": float(
            np.max(np.abs(res.drive_forces - dop.drive_forces)) / scale
        ),
        "target_ms": 5.0,
    }


def bench_scaling(ns=SCALING_FULL, steps: int = 20) -> dict:
    rows = []
    for n in ns:
        t0 = time.perf_counter()
        model = random_chain(n, masses=np.ones(n))
        build = time.perf_counter() - t0
        dt = 1e-4

        def run(model=model, dt=dt):
            return ad.simulate(model, steps * dt, integrator="rk4", dt=dt, output_dt=steps * dt)

        per_step = median_time(run, 1, 3) / steps
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

    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2))
    rows = results["scaling"]["rows"]
    ax[0].loglog([r["n"] for r in rows], [r["us_per_step"] for r in rows], "o-", label="armdyn")
    n = np.array([r["n"] for r in rows], float)
    ax[0].loglog(n, rows[-1]["us_per_step"] * n / n[-1], "k:", label="slope 1")
    ax[0].set_xlabel("bodies in the chain")
    ax[0].set_ylabel("µs per RK4 step")
    ax[0].set_title(f"scaling, fitted slope {results['scaling']['slope_n_ge_20']:.2f}")
    ax[0].legend()
    arms = {k: v for k, v in results["arms"].items() if isinstance(v, dict) and "dof" in v}
    labels, vals, colors = [], [], []
    for name, r in arms.items():
        c, b = r["per_call"], r["batch"]
        labels += [f"{name}\nFD/aba", f"{name}\nID/rnea", f"{name}\nM/crba", f"{name}\nbatch FD"]
        vals += [
            c["ratio_forward_dynamics"],
            c["ratio_inverse_dynamics"],
            c["ratio_mass_matrix"],
            b["ratio_forward_dynamics"],
        ]
        colors += ["C0", "C0", "C0", "C1"]
    if vals:
        ax[1].bar(labels, vals, color=colors)
        ax[1].axhline(TARGET_PER_CALL, color="C0", ls=":", label="target per call (1×)")
        ax[1].axhline(TARGET_BATCH, color="C1", ls=":", label=f"target batch of {BATCH} (0.5×)")
        ax[1].set_ylabel("armdyn time / Pinocchio time")
        ax[1].set_title("public functions from Python against Pinocchio", fontsize=10)
        ax[1].tick_params(axis="x", labelsize=7)
        ax[1].legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(out=common.RESULTS, quick: bool = False, echo: bool = True) -> dict:
    """Every section; writes ``bench.json`` and ``bench.png`` into ``out``."""
    results = {
        "command": "python -m benchmarks.bench" + (" --quick" if quick else ""),
        "machine": common.machine(),
        "arms": bench_arms(quick),
        "whole_run": bench_whole_run(quick),
        "geared_arm_step": bench_geared_arm(),
        "five_dof_run": bench_five_dof(),
        "scaling": bench_scaling(SCALING_QUICK if quick else SCALING_FULL),
    }
    out = Path(out)
    common.write_json(out / "bench.json", results)
    plot(results, out / "bench.png")
    if echo:
        print(summary(results))
        print(f"written: {out / 'bench.json'}, {out / 'bench.png'}")
    return results


def summary(results: dict) -> str:
    """The headline ratios as a Markdown table."""
    lines = [
        "| arm | forward_dynamics / pin.aba | inverse_dynamics / pin.rnea | mass_matrix / pin.crba "
        "| batch: forward_dynamics / loop of pin.aba |",
        "|---|---|---|---|---|",
    ]
    for name, r in results["arms"].items():
        if isinstance(r, dict) and "dof" in r:
            c, b = r["per_call"], r["batch"]
            lines.append(
                f"| {name} | {c['ratio_forward_dynamics']:.2f} | {c['ratio_inverse_dynamics']:.2f} "
                f"| {c['ratio_mass_matrix']:.2f} | {b['ratio_forward_dynamics']:.2f} "
                f"({b['states']} states) |"
            )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m benchmarks.bench", description=__doc__.splitlines()[0]
    )
    p.add_argument("--out", default=str(common.RESULTS), help="folder for bench.json, bench.png")
    p.add_argument("--quick", action="store_true", help="fewer calls, chains up to 100 bodies")
    a = p.parse_args(argv)
    run(a.out, quick=a.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
