"""Type errors a user can make with armdyn: ``mypy --strict`` must flag every line marked
``# error`` (and no other): tests/typing/test_mypy.py."""

from __future__ import annotations

import armdyn as ad
import numpy as np


def misuse(result: ad.SimulationResult, model: ad.Model) -> None:
    y: str = result.q  # error: ndarray is not str
    n: str = model.n_dofs  # error: int is not str
    m: int = ad.mass_matrix(model, np.zeros(2))  # error: ndarray is not int
    ad.simulate(model, "1.0")  # error: t_end is a float
    builder = ad.ModelBuilder()
    builder.add_revolute("j", "ground", "b", [0.0, 0.0, 0.0])  # error: the axis is missing
    builder.add_body("b", mass="1", inertia=[1.0, 1.0, 1.0])  # error: mass is a number
    names: list[int] = builder.joint_names  # error: joint names are str
    ad.urdf_builder("robot.urdf", mimic=1.5)  # error: mimic is a bool
    print(y, n, m, names)
