"""``armdyn.joint_reactions`` on the UR5 (example-robot-data): CPU time per state of one batch
call of 20,000 random states, next to ``armdyn.inverse_dynamics`` on the same states (the
reactions add the Cartesian pipeline's kinematics, constraint rows and each body's balance to
the recursive Newton-Euler pass). Prints the medians of 5 warm calls.

    python -m benchmarks.joint_reactions
"""

from __future__ import annotations

import armdyn as ad
import numpy as np

from benchmarks import common


def main() -> None:
    path = common.robot_urdf("ur5")
    if path is None:
        raise SystemExit("example-robot-data is not installed")
    model = ad.load_urdf(str(path))
    n = 20_000
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.uniform(-1.0, 1.0, (n, model.n_dofs)) for _ in range(3))
    for name, fn in (
        ("inverse_dynamics", lambda: ad.inverse_dynamics(model, q, qd, qdd)),
        ("joint_reactions", lambda: ad.joint_reactions(model, q, qd, qdd)),
    ):
        seconds, runs, _ = common.cpu_time(fn, 5)
        print(f"{name}: {1e6 * seconds / n:.2f} us per state (median of {runs} calls of {n})")


if __name__ == "__main__":
    main()
