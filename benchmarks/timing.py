"""The time-optimal timing of a UR5 path (armdyn.motion.time_optimal) against the same problem
solved otherwise, in one run: toppra alone (its own two passes on the same constraint rows) and
the convex formulation of Verscheure et al. 2009 in cvxpy (Clarabel) on the same grid. Per
grid size: the CPU time of each (median of warm calls), the durations and their relative
differences, and the worst torque limit ratio of each answer recomputed by
armdyn.inverse_dynamics on its (u, x) pairs, and through its x alone (toppra's own forward pass
lowers each x by 1e-8, so its u are not exactly those of its x), and time_optimal's between
its samples too (its exact evaluator, 20 points per interval: collocation meets the limits at
the grid points only, between them to first order in the grid step). Then
armdyn.motion.shortest_cycle on the UR5 with a geared motor on every joint (datasheets with
thermal data), over the path there and back, for two dwells: CPU time, the slowdown found and
the check that binds.

    python -m benchmarks.timing [--grids N ...] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

import armdyn as ad
import numpy as np
from armdyn.motion import Path as MotionPath
from armdyn.motion import time_optimal
from armdyn.motion import timing as _timing

from benchmarks.common import cpu_time, machine, robot_urdf, write_json

TORQUE = np.array([60.0, 60.0, 40.0, 10.0, 10.0, 10.0])
WAYPOINTS = np.array(
    [
        [0.0, -1.2, 1.0, -1.4, -1.57, 0.0],
        [0.8, -1.5, 1.6, -1.0, -1.3, 0.3],
        [1.5, -0.6, 0.4, -0.8, -1.0, 1.0],
    ]
)


def coefficients(model, path, s):
    q, d1, d2 = path.evaluate(s)
    z = np.zeros_like(q)
    c = ad.inverse_dynamics(model, q, z, z)
    a = ad.inverse_dynamics(model, q, z, d1) - c
    b = ad.inverse_dynamics(model, q, d1, d2) - c
    with np.errstate(divide="ignore"):
        x_max = np.min(np.where(d1 != 0, (model.coord_velocity_limit / np.abs(d1)) ** 2, np.inf), 1)
    return a, b, c, x_max


def cvxpy_solve(s, a, b, c, x_max):
    import cvxpy as cp

    n, delta = len(s) - 1, np.diff(s)
    x, u = cp.Variable(n + 1), cp.Variable(n)
    torque = cp.multiply(a[:-1], u[:, None]) + cp.multiply(b[:-1], x[:-1][:, None]) + c[:-1]
    problem = cp.Problem(
        cp.Minimize(cp.sum(cp.multiply(2 * delta, cp.inv_pos(cp.sqrt(x[:-1]) + cp.sqrt(x[1:]))))),
        [
            x[0] == 0,
            x[n] == 0,
            x >= 0,
            x <= np.minimum(x_max, 1e12),
            x[1:] == x[:-1] + 2 * cp.multiply(delta, u),
            cp.abs(torque) <= TORQUE,
        ],
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        problem.solve(solver="CLARABEL")
    return duration_of(s, x.value), np.maximum(x.value, 0.0), u.value


def duration_of(s, x):
    """Σ 2Δ/(√x_i + √x_{i+1}) of a solution, its ends at rest exactly: the solver meets
    x_0 = x_N = 0 to its tolerance (~1e-8), and the square root makes that a 1e-4 error in the
    end intervals' times."""
    x = np.maximum(np.asarray(x, dtype=float), 0.0)
    x[0] = x[-1] = 0.0
    sd = np.sqrt(x)
    return float(np.sum(2 * np.diff(s) / (sd[1:] + sd[:-1])))


def toppra_alone(s, a, b, c, x_max):
    """toppra's own TOPPRA (controllable sets and its forward pass) on the torque rows."""
    import toppra.algorithm as algo
    from toppra.constraint import DiscretizationType, LinearConstraint

    rows_a = np.concatenate([a, -a], axis=1)
    rows_b = np.concatenate([b, -b], axis=1)
    rows_c = np.concatenate([c - TORQUE, -c - TORQUE], axis=1)
    m = rows_a.shape[1]

    class Rows(LinearConstraint):
        def __init__(self):
            super().__init__()
            self.identical = True
            self.set_discretization_type(DiscretizationType.Collocation)

        def compute_constraint_params(self, path, gridpoints, *args, **kwargs):
            xb = np.stack([np.zeros(len(s)), np.minimum(x_max, 1e8)], axis=1)
            return rows_a, rows_b, rows_c, np.eye(m), np.zeros(m), None, xb

    class Interval:
        path_interval = np.array([0.0, 1.0])
        dof = 1

    solver = algo.TOPPRA([Rows()], Interval(), gridpoints=s, solver_wrapper="seidel")
    sdd, sd, _ = solver.compute_parameterization(0.0, 0.0)
    return 2 * np.sum(np.diff(s) / (sd[1:] + sd[:-1])), sd**2, sdd


def worst_ratio(a, b, c, x, u=None):
    """max |a u + b x + c| / τ_max over the grid points 0 … N-1 (u the interval's; None: the
    u that x itself implies, (x_{i+1} − x_i) / 2Δ, what a trajectory through x does)."""
    if u is None:
        u = np.diff(x) / (2 * np.diff(np.linspace(0.0, 1.0, len(x))))
    tau = a[:-1] * u[:, None] + b[:-1] * x[:-1, None] + c[:-1]
    return float(np.max(np.abs(tau) / TORQUE))


def measure(model, path, grid: int) -> dict:
    """One grid size: the three solves, their CPU times, durations and torque ratios."""
    s = np.linspace(0.0, 1.0, grid + 1)
    a, b, c, x_max = coefficients(model, path, s)
    t_ours, _, traj = cpu_time(lambda: time_optimal(model, path, max_torque=TORQUE, grid=grid), 5)
    tau = ad.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    t_toppra, _, (d_toppra, x_t, u_t) = cpu_time(lambda: toppra_alone(s, a, b, c, x_max), 5)
    t_cvx, _, (d_cvx, x_c, u_c) = cpu_time(lambda: cvxpy_solve(s, a, b, c, x_max), 3)
    # time_optimal's share spent in toppra (its controllable sets) on the same rows
    along = _timing._along("bench", model, path, s)
    v_max = np.asarray(model.coord_velocity_limit, dtype=float)
    prob = _timing._problem(
        model, along, list(model.dof_names), v_max, np.full(6, np.inf), TORQUE, True
    )
    lin = _timing._linearised(prob, np.ones(len(s)))
    t_sets, _, _ = cpu_time(lambda: _timing._scaled_controllable(s, *lin[:3], prob.xmax), 5)
    # between the samples (the exact evaluator, 20 points per interval): collocation holds the
    # limits at the grid points only, between them to first order in the grid step
    fine = traj.sample(dt=traj.duration / (20 * grid))
    tau_fine = ad.inverse_dynamics(model, fine.q, fine.qd, fine.qdd)
    row = {
        "grid": grid,
        "worst_torque_ratio_time_optimal_between_samples": float(np.max(np.abs(tau_fine) / TORQUE)),
        "duration_time_optimal_s": traj.duration,
        "duration_cvxpy_s": d_cvx,
        "duration_toppra_alone_s": d_toppra,
        "time_optimal_vs_cvxpy": traj.duration / d_cvx - 1.0,
        "toppra_alone_vs_cvxpy": d_toppra / d_cvx - 1.0,
        "cpu_time_optimal_s": t_ours,
        "cpu_of_which_toppra_controllable_sets_s": t_sets,
        "cpu_toppra_alone_s": t_toppra,
        "cpu_cvxpy_s": t_cvx,
        "cvxpy_over_time_optimal": t_cvx / t_ours,
        "worst_torque_ratio_time_optimal_samples": float(np.max(np.abs(tau) / TORQUE)),
        "worst_torque_ratio_toppra_alone": worst_ratio(a, b, c, x_t, u_t),
        "worst_torque_ratio_toppra_alone_through_its_x": worst_ratio(a, b, c, x_t),
        "worst_torque_ratio_cvxpy": worst_ratio(a, b, c, x_c, u_c),
    }
    print(
        f"grid {grid}: duration {traj.duration:.6f} s (cvxpy {d_cvx:.6f}, "
        f"{row['time_optimal_vs_cvxpy']:+.2e}; toppra alone {d_toppra:.6f}); CPU "
        f"time_optimal {t_ours * 1e3:.1f} ms (toppra's sets {t_sets * 1e3:.1f} ms), toppra "
        f"alone {t_toppra * 1e3:.1f} ms, cvxpy {t_cvx * 1e3:.1f} ms; worst |tau|/limit: "
        f"{row['worst_torque_ratio_time_optimal_samples']:.9f} (ours, on the samples; "
        f"{row['worst_torque_ratio_time_optimal_between_samples']:.4f} between them), "
        f"{row['worst_torque_ratio_toppra_alone']:.6f} (toppra's pairs), "
        f"{row['worst_torque_ratio_toppra_alone_through_its_x']:.6f} (toppra's x), "
        f"{row['worst_torque_ratio_cvxpy']:.6f} (cvxpy)"
    )
    return row


MOTORS = (
    dict(torque_constant=0.1, resistance=0.5, voltage=48.0, peak_torque=1.5,
         continuous_torque=0.5, thermal_resistance=1.5, thermal_time_constant=30.0,
         max_winding_temperature=120.0, no_load_speed=450.0),
    dict(torque_constant=0.05, resistance=1.0, voltage=24.0, peak_torque=0.4,
         continuous_torque=0.15, thermal_resistance=3.0, thermal_time_constant=15.0,
         max_winding_temperature=120.0, no_load_speed=450.0),
)  # fmt: skip


def cycles(dwells=(0.2, 2.0), grid: int = 500) -> list[dict]:
    """shortest_cycle of the UR5 with motors (N = 100, η = 0.85; the larger motor on the first
    three joints) over the path there and back."""
    from armdyn.motion import shortest_cycle

    urdf = robot_urdf("ur5")
    b = ad.urdf_builder(str(urdf))
    for k, joint in enumerate(ad.load_urdf(urdf).dof_names):
        b.add_actuator(
            joint, gear_ratio=100.0, rotor_inertia=3e-5 if k < 3 else 1e-5, efficiency=0.85,
            motor=ad.Motor(**MOTORS[0 if k < 3 else 1]),
        )  # fmt: skip
    model = b.finalize()
    w = WAYPOINTS
    loop = MotionPath([0.0, 0.25, 0.5, 0.75, 1.0], [w[0], w[1], w[2], w[1], w[0]])
    out = []
    for dwell in dwells:
        cpu, _, c = cpu_time(
            lambda dwell=dwell: shortest_cycle(model, loop, dwell=dwell, grid=grid), 3
        )
        row = {
            "dwell_s": dwell,
            "grid": grid,
            "cpu_s": cpu,
            "time_optimal_duration_s": c.info["time_optimal_duration"],
            "slowdown": c.info["slowdown"],
            "period_s": c.info["period"],
            "binding": list(c.info["binding"]) if c.info["binding"] else None,
        }
        out.append(row)
        motion, period = row["time_optimal_duration_s"], row["period_s"]
        print(
            f"shortest_cycle, dwell {dwell} s: time-optimal motion {motion:.4f} s, slowdown "
            f"{row['slowdown']:.4f}, period {period:.4f} s, binding {row['binding']}; "
            f"CPU {cpu:.2f} s"
        )
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--grids", type=int, nargs="+", default=[200, 1000, 4000])
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    model = ad.load_urdf(robot_urdf("ur5"))
    path = MotionPath([0.0, 0.5, 1.0], WAYPOINTS)
    rows = [measure(model, path, grid) for grid in args.grids]
    result = {
        "command": "python -m benchmarks.timing " + " ".join(sys.argv[1:]),
        "path": "UR5, natural cubic spline through 3 waypoints (benchmarks/timing.py WAYPOINTS)",
        "limits": "joint torques [60, 60, 40, 10, 10, 10] N m, the URDF's joint speeds",
        "rows": rows,
        "shortest_cycle": cycles(),
        "machine": machine(),
        "load_average_1min": os.getloadavg()[0],
    }
    print("written", write_json(Path(args.out) / "timing.json", result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
