"""Pinocchio as a peer: the same URDF in armdyn and Pinocchio, and an armdyn tree rebuilt in
Pinocchio.

:class:`PinPair` loads one URDF in both libraries (armdyn through urdfdom, Pinocchio through its
own parser) with the map between their joint orders, and cross-checks armdyn's public
``forward_dynamics``, ``inverse_dynamics`` and ``mass_matrix`` against ``pin.aba``, ``pin.rnea``
and ``pin.crba`` (with the URDF's joint damping and friction added to Pinocchio's, which leaves
them out: :meth:`PinPair.joint_friction`).

:func:`pinocchio_tree` rebuilds a finalized armdyn model whose joints form a tree of revolute,
prismatic and fixed joints (``model.joint_space``) as a ``pinocchio.Model`` from the model's
own data only: masses, inertias, and each joint's frames (:meth:`armdyn.Model.joint_frame`).
Every armdyn joint with a coordinate becomes a Pinocchio joint about (along) the z axis of its
joint frame, placed where that frame sits in the parent body at the build pose; bodies joined by
fixed joints are appended to their parent's Pinocchio joint. Pinocchio's CRBA and RNEA on it are
then the Euler–Lagrange terms of the same mechanism computed by a different library.

Force elements (motors, springs) and gear couplings are *not* carried over: the caller adds
them in the joint coordinates (see ``benchmarks.references.GearedArmReference``).
"""

from __future__ import annotations

from pathlib import Path

import armdyn as ad
import numpy as np
from armdyn import _core


def mass_matrix(pin, model, data, q) -> np.ndarray:
    """The joint-space mass matrix from ``pin.crba``, which fills only its upper triangle."""
    m = pin.crba(model, data, q)
    return np.triu(m) + np.triu(m, 1).T


def _se3(pin, rotation, translation):
    return pin.SE3(np.asarray(rotation, dtype=float), np.asarray(translation, dtype=float))


def pinocchio_tree(model: _core.Model):
    """``(pin_model, idx_q)``: the Pinocchio model, and for each armdyn joint coordinate (model
    order) its index in Pinocchio's configuration vector (``q_pin[idx_q] = q``). Gravity is the
    model's. Raises ModelError for models outside revolute/prismatic/fixed trees."""
    import pinocchio as pin

    if not model.joint_space:
        raise _core.ModelError(
            "pinocchio_tree: the model is not a tree of joints with coordinates (see summary())"
        )
    names = list(model.body_names)
    masses, inertias = np.asarray(model.masses), np.asarray(model.inertias)
    pm = pin.Model()
    pm.gravity = pin.Motion(np.asarray(model.gravity, dtype=float), np.zeros(3))
    # where each body sits: (Pinocchio joint id, placement of the body's CoM frame in it)
    placed = {"ground": (0, pin.SE3.Identity())}
    coord_joint = {}  # armdyn coordinate -> Pinocchio joint id
    frames = [model.joint_frame(j) for j in model.joint_names]
    # depth first from the ground: Pinocchio's algorithms (CRBA) need each joint's subtree to
    # occupy consecutive velocity indices
    children: dict[str, list[int]] = {}
    for k, jf in enumerate(frames):
        children.setdefault(jf["parent"], []).append(k)
    order, stack = [], list(reversed(children.get("ground", [])))
    while stack:
        k = stack.pop()
        order.append(k)
        stack.extend(reversed(children.get(frames[k]["child"], [])))
    if len(order) != len(frames):
        raise _core.ModelError("pinocchio_tree: some joints do not connect to the ground")
    for k in order:
        jf = frames[k]
        parent_id, x_jp_p = placed[jf["parent"]]
        x_p_j = _se3(pin, jf["frame_parent"], jf["point_parent"])
        x_c_j = _se3(pin, jf["frame_child"], jf["point_child"])
        x_j_c = x_c_j.inverse()
        jname = model.joint_names[k]
        if jf["type"] == "fixed":
            jid, x_body = parent_id, x_jp_p * x_p_j * x_j_c
        elif jf["type"] in ("revolute", "prismatic"):
            joint = pin.JointModelRZ() if jf["type"] == "revolute" else pin.JointModelPZ()
            jid = pm.addJoint(parent_id, joint, x_jp_p * x_p_j, jname)
            coord_joint[jf["coord"]] = jid
            x_body = x_j_c
        else:
            raise _core.ModelError(f"pinocchio_tree: joint '{jname}' is {jf['type']}")
        b = names.index(jf["child"])
        r = x_body.rotation
        inertia = pin.Inertia(masses[b], x_body.translation, r @ inertias[b] @ r.T)
        pm.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        placed[jf["child"]] = (jid, x_body)
    idx_q = np.array([pm.joints[coord_joint[c]].idx_q for c in range(model.n_coords)], dtype=int)
    return pm, idx_q


class PinPair:
    """The same URDF in armdyn (``am``) and Pinocchio (``pm``, ``pd``), with the coordinate map
    between them: ``q_armdyn[perm] = q_pinocchio`` (:meth:`to_armdyn`). ``mimic``: both read
    ``<mimic>`` as couplings (Pinocchio's ``mimic=True``; q then holds the independent
    coordinates) or both give each mimicking joint its own coordinate (``False``)."""

    def __init__(self, path: Path, mimic: bool = False):
        import pinocchio as pin

        self.pin = pin
        self.pm = pin.buildModelFromUrdf(str(path), mimic=mimic)
        self.pd = self.pm.createData()
        self.am = ad.load_urdf(str(path), mimic=mimic)
        names = list(self.am.coord_names)
        pin_names = [
            self.pm.names[i] for i in range(1, self.pm.njoints) if self.pm.joints[i].nq > 0
        ]
        if self.pm.nq != self.pm.nv or self.pm.nq != len(names):
            raise ValueError("only revolute/prismatic arms are compared")
        self.perm = np.array([names.index(n) for n in pin_names])

    def joint_friction(self, v):
        """The URDF's ``<dynamics damping friction>`` torques at rates ``v`` (Pinocchio order),
        from Pinocchio's reading of them (``model.damping``, ``model.friction``): armdyn imports
        them as joint friction -damping v - friction tanh(v / v_s), v_s
        ``armdyn._core.URDF_COULOMB_SMOOTHING``; Pinocchio's algorithms leave them out."""
        v = np.asarray(v, dtype=float)
        vs = _core.URDF_COULOMB_SMOOTHING
        return -self.pm.damping * v - self.pm.friction * np.tanh(v / vs)

    def aba(self, q, v, tau):
        """``pin.aba`` with the URDF's joint friction acting (armdyn's forward dynamics)."""
        return self.pin.aba(self.pm, self.pd, q, v, tau + self.joint_friction(v))

    def rnea(self, q, v, a):
        """``pin.rnea`` with the URDF's joint friction acting (armdyn's inverse dynamics)."""
        return self.pin.rnea(self.pm, self.pd, q, v, a) - self.joint_friction(v)

    def to_armdyn(self, x):
        """A vector (or rows of vectors) in Pinocchio's joint order, in armdyn's."""
        x = np.asarray(x, dtype=float)
        out = np.empty_like(x)
        out[..., self.perm] = x
        return out

    def cross_check(self, n: int = 50, seed: int = 0) -> dict:
        """Worst relative errors over ``n`` random states of armdyn's public functions against
        Pinocchio: ``forward_dynamics`` (default method, and ``method="cartesian"``, the KKT
        path) against ``pin.aba``, ``inverse_dynamics`` against ``pin.rnea`` and ``mass_matrix``
        against ``pin.crba``; each relative to the largest entry of Pinocchio's answer."""
        pin, pm, pd, p = self.pin, self.pm, self.pd, self.perm
        rng = np.random.default_rng(seed)
        worst = dict.fromkeys(("fd", "fd_kkt", "id", "mass_matrix"), 0.0)

        def update(key, a, b):
            worst[key] = max(worst[key], float(np.max(np.abs(a - b)) / np.max(np.abs(b))))

        for _ in range(n):
            q, v, tau, acc = rng.uniform(-np.pi, np.pi, size=(4, pm.nq))
            qa, va, ta, aa = (self.to_armdyn(x) for x in (q, v, tau, acc))
            a_pin = self.aba(q, v, tau)
            update("fd", ad.forward_dynamics(self.am, qa, va, ta)[p], a_pin)
            update("fd_kkt", ad.forward_dynamics(self.am, qa, va, ta, method="cartesian")[p], a_pin)
            update("id", ad.inverse_dynamics(self.am, qa, va, aa)[p], self.rnea(q, v, acc))
            update(
                "mass_matrix",
                ad.mass_matrix(self.am, qa)[np.ix_(p, p)],
                mass_matrix(pin, pm, pd, q),
            )
        return {f"{k}_rel_error": v for k, v in worst.items()}
