"""The joint-level functions of a tree with ideal gears in its independent coordinates: the
44-body geared arm (``armdyn.papers.geared_arm.geared_arm_6dof``, 18 joint coordinates, 12 ideal
gears, 6 independent). CPU time per row of one batch call along a moving motion (the states of a
joint-space run of its PD motors, 200 rows over 1 s, a rotor passing 1.5 turns) and at rest
(200 rows at the start pose, zero rates and accelerations), next to the joint-space run's own
right-hand side (TreeDynamics, all coordinates: ``_core._TreeDynamics``) at the same states.
Prints the medians of 5 warm calls.

    python -m benchmarks.gear_joint_api
"""

from __future__ import annotations

import armdyn as ad
import numpy as np
from armdyn import _core
from armdyn.papers.geared_arm import geared_arm_6dof

from benchmarks import common


def main() -> None:
    model = geared_arm_6dof(backlash=0.0, t_start=0.1, t_end=1.1)
    n = 200
    res = ad.simulate(
        model, 1.0, coordinates="joint", integrator="dop853", rtol=1e-8, atol=1e-8, output_dt=1e-3
    )
    rows = np.linspace(0, len(res.t) - 1, n).astype(int)
    idx = list(model.independent_coords)
    t = res.t[rows]
    q, qd, qdd = (x[rows][:, idx] for x in (res.q, res.qd, res.qdd))
    print(
        f"geared arm: {model.nb} bodies, {model.n_joint_coords} joint coordinates, "
        f"{model.n_coords} independent {list(model.coord_names)}"
    )
    rest = np.repeat(q[:1], n, axis=0)
    zero = np.zeros_like(q)
    td = _core._TreeDynamics(model)
    qf, qdf = res.q[rows], res.qd[rows]
    tauf = np.zeros(model.n_joint_coords)

    def tree_rhs():
        for k in range(n):
            td(qf[k], qdf[k], tauf, t[k])

    for name, fn in (
        ("inverse_dynamics (moving)", lambda: ad.inverse_dynamics(model, q, qd, qdd, t)),
        ("inverse_dynamics (at rest)", lambda: ad.inverse_dynamics(model, rest, zero, zero)),
        ("forward_dynamics (moving)", lambda: ad.forward_dynamics(model, q, qd, zero, t)),
        ("mass_matrix (moving)", lambda: ad.mass_matrix(model, q)),
        ("joint_reactions (moving)", lambda: ad.joint_reactions(model, q, qd, qdd, t)),
        ("trajectory_run (moving)", lambda: ad.trajectory_run(model, t, q, qd, qdd)),
        ("TreeDynamics rhs, all coordinates (moving)", tree_rhs),
    ):
        seconds, runs, _ = common.cpu_time(fn, 5)
        print(f"{name}: {1e6 * seconds / n:.1f} us per row (median of {runs} calls of {n})")


if __name__ == "__main__":
    main()
