"""armdyn overview: build a three-joint arm in code, evaluate its dynamics at one state, and
simulate it for a second. The C++ twin, examples/cpp/overview.cpp, prints the same lines."""

import armdyn
import numpy as np


def show(name, x):
    print(f"{name}:" + "".join(f" {v:.6f}" for v in x))


def main():
    # a shoulder turning about z, a shoulder pitching about y and an elbow about y; links along x
    b = armdyn.ModelBuilder([0.0, 0.0, -9.81])
    upright = [1.0, 0.0, 0.0, 0.0]  # Euler parameters, scalar first
    b.add_body("base", 4.0, np.diag([0.02, 0.02, 0.01]), [0.0, 0.0, 0.1], upright)
    b.add_body("upper_arm", 2.0, np.diag([0.004, 0.04, 0.04]), [0.2, 0.0, 0.2], upright)
    b.add_body("forearm", 1.0, np.diag([0.002, 0.015, 0.015]), [0.55, 0.0, 0.2], upright)
    b.add_revolute("yaw", "ground", "base", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    b.add_revolute("shoulder", "base", "upper_arm", [0.0, 0.0, 0.2], [0.0, 1.0, 0.0])
    b.add_revolute("elbow", "upper_arm", "forearm", [0.4, 0.0, 0.2], [0.0, 1.0, 0.0])
    model = b.finalize()
    print(
        f"bodies {model.nb}, joint coordinates {model.n_coords}, "
        f"degrees of freedom {model.mobility}"
    )

    # one state: joint coordinates, rates and torques
    q = np.array([0.3, -0.5, 0.8])
    qd = np.array([0.2, 1.0, -0.4])
    tau = np.array([0.5, 2.0, -1.0])
    qdd = armdyn.forward_dynamics(model, q, qd, tau)
    show("forward dynamics qdd", qdd)
    show("inverse dynamics tau", armdyn.inverse_dynamics(model, q, qd, qdd))
    show("mass matrix diagonal", np.diag(armdyn.mass_matrix(model, q)))

    # released from the assembly pose at rest: one second of motion
    run = armdyn.simulate(model, 1.0, integrator="dop853", rtol=1e-10, atol=1e-12, output_dt=0.25)
    for t, qk in zip(run.t, run.q, strict=True):
        show(f"t = {t:.2f} q", qk)
    energy = run.kinetic_energy + run.potential_energy
    print(f"energy at t = 0 and 1: {energy[0]:.6f} {energy[-1]:.6f} J")


if __name__ == "__main__":
    main()
