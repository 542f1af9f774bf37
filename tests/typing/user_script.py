"""A user's script: build a model and load a URDF, simulate, read the results. The typing tests
run ``mypy --strict`` on it (the ``reveal_type`` lines, under TYPE_CHECKING, are for mypy only)
and run it."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import armdyn as ad
import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from typing_extensions import reveal_type

FloatArray = npt.NDArray[np.float64]


def pendulum(length: float = 1.0, mass: float = 2.0) -> ad.Model:
    builder = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    builder.add_body("bob", mass, [1e-4, 1e-4, 1e-4], position=[length, 0.0, 0.0])
    builder.add_revolute("pivot", "ground", "bob", [0.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    builder.add_joint_torque("pivot", ad.profiles.sine(0.5, 1.0))
    names: list[str] = builder.joint_names
    assert names == ["pivot"]
    return builder.finalize()


def summarise(result: ad.SimulationResult) -> dict[str, float]:
    t: FloatArray = result.t
    q: FloatArray = result.q
    qd: FloatArray = result.qd
    tau: FloatArray = result.joint_torques
    energy: FloatArray = result.total_energy
    if TYPE_CHECKING:
        reveal_type(result.q)
        reveal_type(result.joint_torques)
    return {
        "t_end": float(t[-1]),
        "q_end": float(q[-1, 0]),
        "qd_max": float(np.abs(qd).max()),
        "tau_max": float(np.abs(tau).max()),
        "energy_span": float(energy.max() - energy.min()),
    }


def main() -> None:
    model = pendulum()
    n: int = model.n_dofs
    q0: FloatArray = np.full(n, 0.3)
    result = ad.simulate(model, 1.0, q0=q0, output_dt=0.01)
    print(summarise(result))

    # joint-space functions of the compiled core
    qdd: FloatArray = ad.forward_dynamics(model, q0, np.zeros(n), np.zeros(n))
    tau: FloatArray = ad.inverse_dynamics(model, q0, np.zeros(n), qdd)
    mass: FloatArray = ad.mass_matrix(model, q0)
    pose: FloatArray = ad.frame_pose(model, q0, 0) if model.frame_names else np.eye(4)
    if TYPE_CHECKING:
        reveal_type(qdd)
        reveal_type(model.coord_names)
    y, yd, ydd = ad.profiles.cubic(0.0, 1.0, 0.0, 2.0).eval(1.0)
    print(float(tau[0]), float(mass[0, 0]), pose.shape, y + yd + ydd)

    # a URDF robot
    urdf = Path(__file__).resolve().parents[1] / "data" / "urdf" / "arm6.urdf"
    robot = ad.load_urdf(urdf)
    coords: list[str] = robot.coord_names
    run = ad.simulate(robot, 0.05, q0=np.zeros(robot.n_coords))
    reaction: FloatArray = run.reaction_forces
    print(len(coords), reaction.shape, run.status, file=sys.stderr)


if __name__ == "__main__":
    main()
