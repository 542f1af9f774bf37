"""A mechanism with welded parts shared by the tests of welding (tests/simulate/test_welded.py)
and of the joint reactions (tests/algorithm/test_joint_reactions.py): two links on revolutes,
a bracket welded to ground carrying the first pivot, a weight and a sensor welded in a chain to
link 1, a tip welded to link 2, a spring and a load on welded members and a PI motor on the
second joint (an auxiliary, integral state)."""

import armdyn as ad
import numpy as np


def quat(axis, angle):
    """The scalar-first unit quaternion of a rotation by ``angle`` about ``axis``."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])


def welded_pendulums():
    """The mechanism of the module notes, finalized."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body(
        "bracket", 2.0, [0.02, 0.03, 0.04], position=(0, 0, 0.1), orientation=quat((1, 1, 0), 0.4)
    )
    b.add_fixed("bracket_mount", "ground", "bracket", point=(0, 0, 0))
    b.add_body("link1", 1.0, [0.001, 0.02, 0.02], position=(0.2, 0, 0.2))
    b.add_revolute("pivot1", "bracket", "link1", point=(0, 0, 0.2), axis=(0, 1, 0))
    b.add_body(
        "weight",
        0.5,
        [1e-3, 2e-3, 3e-3],
        position=(0.4, 0.05, 0.2),
        orientation=quat((0, 0.3, 1), 1.1),
    )
    b.add_fixed("weight_mount", "link1", "weight", point=(0.4, 0, 0.2))
    b.add_body(
        "sensor",
        0.1,
        [1e-4, 1e-4, 2e-4],
        position=(0.45, 0.1, 0.25),
        orientation=quat((1, 0, 0), -0.7),
    )
    b.add_fixed("sensor_mount", "weight", "sensor", point=(0.45, 0.1, 0.2))
    b.add_body("link2", 0.8, [0.001, 0.015, 0.015], position=(0.55, 0, 0.2))
    b.add_revolute("pivot2", "link1", "link2", point=(0.4, 0, 0.2), axis=(0, 0, 1))
    b.add_body("tip", 0.2, [1e-4, 1e-4, 1e-4], position=(0.7, 0, 0.2))
    b.add_fixed("tip_mount", "link2", "tip", point=(0.7, 0, 0.2))
    b.add_spring_damper("spring", "ground", (0.5, 0.3, 0.6), "sensor", (0.45, 0.1, 0.25), 40.0, 0.5)
    b.add_body_force("tip", force=(0.0, 1.5, 0.0), point=(0.72, 0.0, 0.21))
    b.add_motor("pivot2", ad.profiles.sine(0.5, 1.0, 0.0, 0.0), 20.0, 1.0, ki=5.0)
    return b.finalize()
