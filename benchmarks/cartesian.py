"""``armdyn.motion`` inverse kinematics and Cartesian moves on the UR5 (example-robot-data, frame
``tool0``): the CPU time and iterations of ``inverse_kinematics`` on 200 random reachable
targets (start: the solution plus N(0, 0.3 rad) per joint); the knots and CPU time of a
``linear_move`` (0.27 m, 0.54 rad); its exact evaluation at 2001 values of s in one batched call
against one call per s (``frame_pose`` / ``frame_jacobian`` take all rows at once), and the
frame's largest distance to the line there.

    python -m benchmarks.cartesian
"""

from __future__ import annotations

import time

import armdyn as ad
import numpy as np
from armdyn.motion import inverse_kinematics, linear_move
from scipy.spatial.transform import Rotation

from benchmarks import common


def _ik(model) -> None:
    rng = np.random.default_rng(1)
    cases = []
    for _ in range(200):
        q = rng.uniform(-np.pi, np.pi, 6)
        cases.append((ad.frame_pose(model, q, "tool0"), q + rng.normal(0.0, 0.3, 6)))
    cpu = time.process_time()
    res = [inverse_kinematics(model, "tool0", target, start) for target, start in cases]
    cpu = time.process_time() - cpu
    its = [r.iterations for r in res]
    print(
        f"inverse_kinematics: {1e3 * cpu / len(cases):.2f} ms CPU per target ({len(cases)}), "
        f"iterations mean {np.mean(its):.1f} max {max(its)}, largest position error "
        f"{max(r.position_error for r in res):.1e} m"
    )


def _move(model) -> None:
    q0 = np.array(common.UR5_Q0)
    t0 = ad.frame_pose(model, q0, "tool0")
    t1 = t0.copy()
    t1[:3, 3] += (0.1, 0.15, -0.2)
    t1[:3, :3] = Rotation.from_rotvec([0.2, -0.3, 0.4]).as_matrix() @ t0[:3, :3]
    cpu = time.process_time()
    path = linear_move(model, "tool0", q0, t1)
    cpu = time.process_time() - cpu
    print(
        f"linear_move: {path.info['length']:.3f} m, {path.info['rotation']:.3f} rad: "
        f"{len(path.s)} knots in {1e3 * cpu:.0f} ms CPU"
    )
    s = np.linspace(0.0, 1.0, 2001)
    batched, _, (q, _, _) = common.cpu_time(lambda: path.evaluate(s), 3)
    cpu = time.process_time()
    for i in range(len(s)):
        path.evaluate(s[i : i + 1])
    single = time.process_time() - cpu
    x = ad.frame_pose(model, q, "tool0")[:, :3, 3]
    d = (t1[:3, 3] - t0[:3, 3]) / np.linalg.norm(t1[:3, 3] - t0[:3, 3])
    r = x - t0[:3, 3]
    off = np.linalg.norm(r - np.outer(r @ d, d), axis=1).max()
    print(
        f"evaluate at {len(s)} s: {1e3 * batched:.0f} ms CPU batched (median of 3), "
        f"{1e3 * single:.0f} ms CPU one call per s ({single / batched:.0f}x); largest distance "
        f"to the line {off:.1e} m"
    )


def main() -> None:
    path = common.robot_urdf("ur5")
    if path is None:
        raise SystemExit("example-robot-data is not installed")
    model = ad.load_urdf(str(path))
    _ik(model)
    _move(model)


if __name__ == "__main__":
    main()
