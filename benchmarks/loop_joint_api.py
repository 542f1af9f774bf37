"""The joint-level functions of a loop model (the four-bar, ``armdyn.scenes.four_bar``) in its
independent coordinate: CPU time per row of one batch call over a crank turn (2,000 rows), next
to ``driven_inverse_dynamics`` on the same motion (the Cartesian path the functions reuse: the
position problem by Newton from the last row, the velocity problem, the KKT solve). Prints the
medians of 5 warm calls.

    python -m benchmarks.loop_joint_api
"""

from __future__ import annotations

import armdyn as ad
import numpy as np

from benchmarks import common


def main() -> None:
    model = ad.scenes.four_bar()
    n = 2_000
    q = np.linspace(0.0, 2 * np.pi, n)[:, None]
    qd, qdd = np.ones_like(q), 0.5 * np.ones_like(q)
    driven = ad.scenes.four_bar(crank_drive=ad.profiles.spline(q[:, 0], q[:, 0]))
    for name, fn in (
        ("inverse_dynamics", lambda: ad.inverse_dynamics(model, q, qd, qdd)),
        ("forward_dynamics", lambda: ad.forward_dynamics(model, q, qd, qdd)),
        ("mass_matrix", lambda: ad.mass_matrix(model, q)),
        ("joint_reactions", lambda: ad.joint_reactions(model, q, qd, qdd)),
        ("driven_inverse_dynamics", lambda: ad.driven_inverse_dynamics(driven, q[1:, 0])),
    ):
        seconds, runs, _ = common.cpu_time(fn, 5)
        print(f"{name}: {1e6 * seconds / n:.1f} us per row (median of {runs} calls of {n})")


if __name__ == "__main__":
    main()
