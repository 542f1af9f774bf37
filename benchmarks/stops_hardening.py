"""Joint stops that always hold (issue 31): the issue's pendulum and a URDF arm on its stops.

    python -m benchmarks.stops_hardening

1. The pendulum of the issue (1 kg at 1 m, a stop at 0.3 rad, released at 1.2 rad), 20 s at
   default tolerances (DOPRI5), for each restitution e: the worst excursion beyond the stop and
   the number of stop events, both formulations.
2. The 5-joint URDF arm of tests/simulate/test_stops_hardening.py (five pitch joints limited to
   +-0.3 rad, released straight), 2.5 s: the worst excursion, the events, the events repeated by
   one stop at one instant (a "rest" and a "release" together) and the largest velocity
   residual of the run.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import armdyn as ad
import numpy as np

G = 9.81


def pendulum():
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("bob", 1.0, np.eye(3) * 1e-4, position=(0, 0, -1.0))
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.set_joint_limits("hinge", 0.3, 3.0)
    return b.finalize()


def main() -> None:
    m = pendulum()
    print("1. pendulum, 20 s")
    for e in [0.05, 0.3, 0.5, 0.8, 0.95]:
        row = []
        for c in ["cartesian", "joint"]:
            r = ad.simulate(m, 20.0, q0=[1.2], restitution=e, coordinates=c, output_dt=1e-3)
            over = max(0.0, (0.3 - r.q[:, 0]).max())
            row.append(f"{c}: beyond {over:.3g} rad, {len(r.events['limits']['t'])} events")
        print(f"   e={e}: " + "; ".join(row))
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "simulate"))
    from test_stops_hardening import arm5

    arm = arm5(Path(tempfile.mkdtemp()))
    print("2. URDF arm, 2.5 s")
    for e in [0.0, 0.5]:
        for c in ["cartesian", "joint"]:
            r = ad.simulate(arm, 2.5, restitution=e, coordinates=c, output_dt=1e-3)
            ev = r.events["limits"]
            keys = list(zip(ev["t"], ev["joint"], ev["side"], strict=True))
            over = max(0.0, np.maximum(r.q - arm.coord_upper, arm.coord_lower - r.q).max())
            print(
                f"   e={e} {c}: beyond {over:.3g} rad, {len(keys)} events, "
                f"{len(keys) - len(set(keys))} repeated at one instant, "
                f"velocity residual {r.velocity_residual.max():.2g}"
            )


if __name__ == "__main__":
    main()
