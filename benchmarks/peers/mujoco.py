"""MuJoCo as a peer on a URDF arm: MuJoCo's own URDF import of the same file armdyn and Pinocchio
read (the UR5 of ``python -m benchmarks.workprecision ur5``).

The MuJoCo models of the closed-loop problems and of the geared arm are in
:mod:`benchmarks.peers.closed_loops` and :mod:`benchmarks.peers.geared`.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np


def mujoco_from_urdf(path: Path, pair=None):
    """MuJoCo's own URDF import of the arm, for the same-URDF comparison: visual and collision
    elements removed (no meshes are needed and no contacts exist), static bodies fused, joint
    limits, damping, armature and friction off (Pinocchio's ABA and armdyn have none).
    Returns the MjModel and, with ``pair`` (a :class:`benchmarks.peers.pinocchio.PinPair`),
    the map from Pinocchio's joint order to qpos."""
    import mujoco

    txt = Path(path).read_text()
    txt = re.sub(r"<(visual|collision)\b.*?</\1>", "", txt, flags=re.S)
    txt = re.sub(
        r"(<robot\b[^>]*>)",
        r'\1<mujoco><compiler discardvisual="true" fusestatic="true" balanceinertia="false"/>'
        r"</mujoco>",
        txt,
        count=1,
    )
    model = mujoco.MjModel.from_xml_string(txt)
    model.jnt_limited[:] = 0
    model.dof_damping[:] = 0.0
    model.dof_armature[:] = 0.0
    model.dof_frictionloss[:] = 0.0
    model.opt.gravity[:] = (0.0, 0.0, -9.81)
    if pair is None:
        return model, None
    names = [model.joint(i).name for i in range(model.njnt)]
    perm = np.array(
        [model.jnt_qposadr[names.index(pair.pm.names[i])] for i in range(1, pair.pm.njoints)]
    )
    return model, perm
