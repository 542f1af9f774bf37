"""Measure the constants of armdyn's dynamics cost model (cpp/src/algorithm/cost_model.cpp).

``python -m benchmarks.cost_model`` times, on spatial chains of 1 to 400 links
(``armdyn.scenes.random_chain``):

- ``forward_dynamics`` per call with ``method="crba"``, ``"aba"`` and ``"cartesian"``, through
  the batch form (one Python call for many rows, the loop in C++, so the binding's overhead is
  spread over the rows), in interleaved rounds;
- ``simulate`` per right-hand side (``integrator="rk4"``, fixed step) with
  ``coordinates="joint"`` and ``"cartesian"``: wall time / ``stats["rhs_evals"]``.

and fits, by non-negative least squares on relative residuals (each row divided by its measured
time, so that a 10 us model counts as much as a 10 ms one),

    crba      = c0 + c_body nb + c_path P + c_chol n^3   (P = sum over coordinates of the
                                                           coordinates on their path to the root)
    aba       = a0 + a_body nb
    cartesian = k0 + k_body nb
    simulate, joint space:  min(crba, aba) + j0 + j_body nb   (the run's own work per rhs)
    simulate, Cartesian:    s0 + s_body nb

in microseconds. Writes ``benchmarks/results/cost_model.json`` and prints the C++ initialiser
to paste into ``cost_constants()``. Chains only: nb = n, so the per-body constants include the
per-coordinate work.
"""

from __future__ import annotations

import time

import armdyn
import numpy as np
from armdyn.scenes import random_chain
from scipy.optimize import nnls

from .common import RESULTS, interleaved_times, machine, write_json

SIZES = (1, 2, 4, 8, 16, 32, 64, 100, 150, 200, 300, 400)


def forward_times(n: int, rng) -> dict:
    model = random_chain(n)
    d = armdyn.Data(model)
    rows = max(4, 4000 // n)
    q = rng.uniform(-1, 1, (rows, n))
    qd = rng.uniform(-1, 1, (rows, n))
    tau = rng.uniform(-1, 1, (rows, n))
    fns = {
        m: (lambda m=m: armdyn.forward_dynamics(model, q, qd, tau, method=m, data=d))
        for m in ("crba", "aba", "cartesian")
    }
    number = max(1, int(2e-2 / (rows * n * 1e-6 * 0.5)))
    t = interleaved_times(fns, number=min(number, 50), repeat=7)
    cost = armdyn.dynamics_cost(model)
    return {
        "n": n,
        "nb": cost["nb"],
        "path": cost["path"],
        **{m: 1e6 * t[m] / rows for m in fns},
    }


def rhs_time(model, coordinates: str, steps: int) -> tuple[float, str]:
    dt = 1e-3
    best = np.inf
    form = ""
    for _ in range(5):
        t0 = time.perf_counter()
        r = armdyn.simulate(model, steps * dt, integrator="rk4", dt=dt, coordinates=coordinates)
        el = time.perf_counter() - t0
        best = min(best, el / r.stats["rhs_evals"])
        form = r.stats["formulation"]
    return 1e6 * best, form


def fit(rows, cols, y):
    a = np.array([[r[c] for c in cols] for r in rows], float) / y[:, None]
    x, _ = nnls(a, np.ones(len(y)))
    pred = np.array([[r[c] for c in cols] for r in rows], float) @ x
    return x, float(np.max(np.abs(pred / y - 1)))


def main():
    rng = np.random.default_rng(0)
    rows = []
    for n in SIZES:
        r = forward_times(n, rng)
        model = random_chain(n)
        steps = max(20, int(20000 / n))
        r["sim_joint"], form = rhs_time(model, "joint", steps)
        r["sim_joint_aba"] = "articulated-body" in form
        r["sim_cartesian"], _ = rhs_time(model, "cartesian", steps)
        rows.append(r)
        print(
            f"n={n:4d}  crba {r['crba']:9.2f}  aba {r['aba']:8.2f}  cartesian {r['cartesian']:8.2f}"
            f"  | rhs joint {r['sim_joint']:9.2f} ({'aba' if r['sim_joint_aba'] else 'crba'})"
            f"  cartesian {r['sim_cartesian']:8.2f}  [us]",
            flush=True,
        )
    for r in rows:
        r["one"] = 1.0
        r["n3"] = float(r["n"]) ** 3
        r["joint_extra"] = r["sim_joint"] - (r["aba"] if r["sim_joint_aba"] else r["crba"])
    c, ec = fit(rows, ["one", "nb", "path", "n3"], np.array([r["crba"] for r in rows]))
    a, ea = fit(rows, ["one", "nb"], np.array([r["aba"] for r in rows]))
    k, ek = fit(rows, ["one", "nb"], np.array([r["cartesian"] for r in rows]))
    s, es = fit(rows, ["one", "nb"], np.array([r["sim_cartesian"] for r in rows]))
    extra = np.array([max(r["joint_extra"], 0.05) for r in rows])
    j, ej = fit(rows, ["one", "nb"], extra)
    consts = {
        "c0": c[0],
        "c_body": c[1],
        "c_path": c[2],
        "c_chol": c[3],
        "a0": a[0],
        "a_body": a[1],
        "k0": k[0],
        "k_body": k[1],
        "j0": j[0],
        "j_body": j[1],
        "s0": s[0],
        "s_body": s[1],
    }
    worst = {"crba": ec, "aba": ea, "cartesian": ek, "sim_joint_extra": ej, "sim_cartesian": es}
    print("constants [us]:", {key: float(f"{v:.4g}") for key, v in consts.items()})
    print("largest relative misfit:", {key: round(v, 3) for key, v in worst.items()})
    print("C++: {" + ", ".join(f"/*{key}*/ {v:.4g}" for key, v in consts.items()) + "}")
    write_json(
        RESULTS / "cost_model.json",
        {
            "command": "python -m benchmarks.cost_model",
            "machine": machine(),
            "constants_us": consts,
            "largest_relative_misfit": worst,
            "rows": [{key: v for key, v in r.items() if key not in ("one",)} for r in rows],
        },
    )


if __name__ == "__main__":
    main()
