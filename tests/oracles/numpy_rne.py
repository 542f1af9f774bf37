"""Test oracle: independent numpy dynamics for serial (tree) chains of revolute/prismatic joints.

The dynamics here never call armdyn (only `random_serial_arm` takes its random geometry from
`armdyn.scenes.extreme.random_spatial_arm`, which builds the same arm with the builder). The chain
is described exactly like the armdyn builder describes it: everything in WORLD coordinates at the
assembly pose q = 0 (joint points, joint axes, centres of mass, inertias), plus the parent index of
every joint (-1 = ground). Joint i moves body i relative to body parents[i]; parents[i] < i.

Joint coordinate convention (the one armdyn documents): q_i = 0 at the assembly pose; a revolute
coordinate is the right-handed rotation of the child about the joint axis relative to the parent,
a prismatic coordinate is the displacement of the child along the axis relative to the parent.

The pose at q is the product of exponentials: body i is moved by the rigid displacement
D_i(q) = D_parent(q) o E_i(q_i), where E_i is the rotation about (or translation along) the
assembly-pose joint axis. Velocities and accelerations are propagated outward with the classical
rigid-body formulas in world coordinates, joint torques come from the inward Newton-Euler pass.

Only rotation matrices are used; the small quaternion helpers at the top are for building
models and for comparing orientations, and are self-contained.
"""

from __future__ import annotations

import numpy as np

# ----------------------------------------------------------------------------------------------
# small rotation / quaternion helpers (scalar-first Euler parameters, body -> world)
# ----------------------------------------------------------------------------------------------


def skew(a):
    a = np.asarray(a, dtype=float)
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def rot_axis_angle(axis, angle):
    """Rodrigues: rotation by `angle` about the unit vector `axis` (right-handed)."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    kx = skew(k)
    return np.eye(3) + np.sin(angle) * kx + (1.0 - np.cos(angle)) * (kx @ kx)


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_to_rot(rpy):
    """URDF convention: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    return rot_z(y) @ rot_y(p) @ rot_x(r)


def quat_to_rot(e):
    e0, e1, e2, e3 = np.asarray(e, dtype=float)
    return np.array(
        [
            [1 - 2 * (e2 * e2 + e3 * e3), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)],
            [2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 * e1 + e3 * e3), 2 * (e2 * e3 - e0 * e1)],
            [2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 * e1 + e2 * e2)],
        ]
    )


def rot_to_quat(r):
    """Unit quaternion (scalar-first, e0 >= 0) of a proper rotation matrix, via the eigenvector
    of the symmetric 4x4 (Bar-Itzhack) matrix: robust and independent of branch choices."""
    r = np.asarray(r, dtype=float)
    k = (
        np.array(
            [
                [
                    r[0, 0] - r[1, 1] - r[2, 2],
                    r[1, 0] + r[0, 1],
                    r[2, 0] + r[0, 2],
                    r[2, 1] - r[1, 2],
                ],
                [
                    r[1, 0] + r[0, 1],
                    r[1, 1] - r[0, 0] - r[2, 2],
                    r[2, 1] + r[1, 2],
                    r[0, 2] - r[2, 0],
                ],
                [
                    r[2, 0] + r[0, 2],
                    r[2, 1] + r[1, 2],
                    r[2, 2] - r[0, 0] - r[1, 1],
                    r[1, 0] - r[0, 1],
                ],
                [
                    r[2, 1] - r[1, 2],
                    r[0, 2] - r[2, 0],
                    r[1, 0] - r[0, 1],
                    r[0, 0] + r[1, 1] + r[2, 2],
                ],
            ]
        )
        / 3.0
    )
    w, vecs = np.linalg.eigh(k)
    x, y, z, s = vecs[:, np.argmax(w)]
    e = np.array([s, x, y, z])
    if e[0] < 0:
        e = -e
    return e / np.linalg.norm(e)


def quat_mul(a, b):
    """Scalar-first quaternion product a (x) b, R(a (x) b) = R(a) R(b)."""
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return np.array(
        [
            a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
        ]
    )


def quat_exp(theta):
    """Unit quaternion of the rotation vector theta (axis * angle)."""
    theta = np.asarray(theta, dtype=float)
    a = np.linalg.norm(theta)
    if a < 1e-300:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[np.cos(0.5 * a)], np.sin(0.5 * a) / a * theta])


# ----------------------------------------------------------------------------------------------
# the chain
# ----------------------------------------------------------------------------------------------


class SerialChain:
    """Tree of revolute ('R') / prismatic ('P') joints described at the assembly pose q = 0.

    Parameters (all world coordinates at q = 0):
      types      sequence of 'R' / 'P', one per joint = one per body
      parents    parent body index of every joint, -1 for ground, parents[i] < i
      points     (n, 3) joint points
      axes       (n, 3) joint axes (normalised here)
      coms       (n, 3) centres of mass
      masses     (n,)
      inertias   (n, 3, 3) inertia about the centre of mass in WORLD axes at q = 0
      rotations  optional (n, 3, 3) body orientations (body -> world) at q = 0 (for body_states)
    """

    def __init__(
        self,
        types,
        parents,
        points,
        axes,
        coms,
        masses,
        inertias,
        rotations=None,
        gravity=(0.0, 0.0, -9.81),
    ):
        self.types = [t.upper()[0] for t in types]
        self.n = len(self.types)
        self.parents = [int(p) for p in parents]
        for i, p in enumerate(self.parents):
            if not (-1 <= p < i):
                raise ValueError("parents must satisfy -1 <= parents[i] < i")
        self.points = np.array(points, dtype=float).reshape(self.n, 3)
        axes = np.array(axes, dtype=float).reshape(self.n, 3)
        self.axes = axes / np.linalg.norm(axes, axis=1)[:, None]
        self.coms = np.array(coms, dtype=float).reshape(self.n, 3)
        self.masses = np.array(masses, dtype=float).reshape(self.n)
        self.inertias = np.array(inertias, dtype=float).reshape(self.n, 3, 3)
        self.rotations = (
            np.array(rotations, dtype=float).reshape(self.n, 3, 3)
            if rotations is not None
            else np.tile(np.eye(3), (self.n, 1, 1))
        )
        self.gravity = np.array(gravity, dtype=float)

    # -- kinematics ----------------------------------------------------------------------------
    def kinematics(self, q, qd=None, qdd=None):
        """Outward pass. Returns a dict of per-body arrays (world coordinates):
        Rd (displacement rotation), c (CoM), R (orientation), w, alpha (angular velocity and
        acceleration), vc, ac (CoM velocity and acceleration), a (joint axis), j (joint point),
        I (inertia about the CoM, world axes)."""
        n = self.n
        q = np.asarray(q, dtype=float).reshape(n)
        qd = np.zeros(n) if qd is None else np.asarray(qd, dtype=float).reshape(n)
        qdd = np.zeros(n) if qdd is None else np.asarray(qdd, dtype=float).reshape(n)
        Rd = np.zeros((n, 3, 3))
        pd = np.zeros((n, 3))
        c = np.zeros((n, 3))
        w = np.zeros((n, 3))
        al = np.zeros((n, 3))
        vc = np.zeros((n, 3))
        ac = np.zeros((n, 3))
        a = np.zeros((n, 3))
        j = np.zeros((n, 3))
        for i in range(n):
            p = self.parents[i]
            if p < 0:
                Rp, pp = np.eye(3), np.zeros(3)
                cp = wp = alp = vcp = acp = np.zeros(3)
            else:
                Rp, pp, cp, wp, alp, vcp, acp = Rd[p], pd[p], c[p], w[p], al[p], vc[p], ac[p]
            a0, j0 = self.axes[i], self.points[i]
            a[i] = Rp @ a0
            j[i] = Rp @ j0 + pp

            def vel_p(r, cp=cp, wp=wp, vcp=vcp):
                return vcp + np.cross(wp, r - cp)

            def acc_p(r, cp=cp, wp=wp, alp=alp, acp=acp):
                d = r - cp
                return acp + np.cross(alp, d) + np.cross(wp, np.cross(wp, d))

            if self.types[i] == "R":
                Rq = rot_axis_angle(a0, q[i])
                Rd[i] = Rp @ Rq
                pd[i] = Rp @ (j0 - Rq @ j0) + pp
                c[i] = Rd[i] @ self.coms[i] + pd[i]
                w[i] = wp + a[i] * qd[i]
                al[i] = alp + a[i] * qdd[i] + np.cross(wp, a[i]) * qd[i]
                d = c[i] - j[i]
                vc[i] = vel_p(j[i]) + np.cross(w[i], d)
                ac[i] = acc_p(j[i]) + np.cross(al[i], d) + np.cross(w[i], np.cross(w[i], d))
            elif self.types[i] == "P":
                Rd[i] = Rp
                pd[i] = Rp @ (a0 * q[i]) + pp
                c[i] = Rd[i] @ self.coms[i] + pd[i]
                w[i] = wp
                al[i] = alp
                vc[i] = vel_p(c[i]) + a[i] * qd[i]
                ac[i] = acc_p(c[i]) + 2.0 * np.cross(wp, a[i]) * qd[i] + a[i] * qdd[i]
            else:
                raise ValueError(f"unsupported joint type {self.types[i]!r}")
        R = np.einsum("nij,njk->nik", Rd, self.rotations)
        inertia = np.einsum("nij,njk,nlk->nil", Rd, self.inertias, Rd)
        return dict(Rd=Rd, pd=pd, c=c, R=R, w=w, alpha=al, vc=vc, ac=ac, a=a, j=j, I=inertia)

    # -- dynamics ------------------------------------------------------------------------------
    def rnea(self, q, qd, qdd, gravity=None):
        """Inverse dynamics: generalised joint forces tau(q, qd, qdd)."""
        g = self.gravity if gravity is None else np.asarray(gravity, dtype=float)
        k = self.kinematics(q, qd, qdd)
        n = self.n
        f = np.zeros((n, 3))  # force transmitted from parent into the subtree of body i
        m = np.zeros((n, 3))  # its moment about the world origin
        for i in range(n):
            F = self.masses[i] * (k["ac"][i] - g)
            N = k["I"][i] @ k["alpha"][i] + np.cross(k["w"][i], k["I"][i] @ k["w"][i])
            f[i] = F
            m[i] = N + np.cross(k["c"][i], F)
        for i in reversed(range(n)):
            p = self.parents[i]
            if p >= 0:
                f[p] += f[i]
                m[p] += m[i]
        tau = np.zeros(n)
        for i in range(n):
            if self.types[i] == "R":
                tau[i] = k["a"][i] @ (m[i] - np.cross(k["j"][i], f[i]))
            else:
                tau[i] = k["a"][i] @ f[i]
        return tau

    def mass_matrix(self, q):
        """Joint-space mass matrix by unit accelerations at zero velocity and zero gravity."""
        n = self.n
        M = np.zeros((n, n))
        zero = np.zeros(n)
        for col in range(n):
            e = np.zeros(n)
            e[col] = 1.0
            M[:, col] = self.rnea(q, zero, e, gravity=np.zeros(3))
        return 0.5 * (M + M.T)

    def bias(self, q, qd):
        """Coriolis, centrifugal and gravity terms: rnea(q, qd, 0)."""
        return self.rnea(q, qd, np.zeros(self.n))

    def forward(self, q, qd, tau):
        """Forward dynamics qdd = M^-1 (tau - bias)."""
        return np.linalg.solve(self.mass_matrix(q), np.asarray(tau, dtype=float) - self.bias(q, qd))

    # -- states and energies -------------------------------------------------------------------
    def body_states(self, q, qd):
        """armdyn-style body states: CoM (world), orientation matrix (body -> world), CoM velocity
        (world) and angular velocity in the BODY frame."""
        k = self.kinematics(q, qd)
        w_body = np.einsum("nji,nj->ni", k["R"], k["w"])
        return k["c"], k["R"], k["vc"], w_body

    def kinetic_energy(self, q, qd):
        k = self.kinematics(q, qd)
        t = 0.0
        for i in range(self.n):
            t += 0.5 * self.masses[i] * k["vc"][i] @ k["vc"][i]
            t += 0.5 * k["w"][i] @ k["I"][i] @ k["w"][i]
        return t

    def potential_energy(self, q):
        k = self.kinematics(q)
        return -float(np.sum(self.masses * (k["c"] @ self.gravity)))


# ----------------------------------------------------------------------------------------------
# the numpy model of armdyn's random spatial arms
# ----------------------------------------------------------------------------------------------


def serial_chain(arm) -> SerialChain:
    """The SerialChain of an arm of :func:`armdyn.scenes.extreme.random_spatial_arm` (or
    ``mass_ratio_chain``), from its geometry only (joint types, points and axes, centres of
    mass, masses, body-axis inertias and orientations at q = 0); rotations and world inertias
    are computed here."""
    axes = np.asarray(arm.axes, dtype=float)
    assert np.linalg.matrix_rank(axes, tol=1e-3) >= min(2, arm.n)  # not all parallel
    rotations = np.array([quat_to_rot(e) for e in arm.quats])
    inertias_world = np.einsum("nij,njk,nlk->nil", rotations, arm.inertias_body, rotations)
    return SerialChain(
        arm.types,
        list(range(-1, arm.n - 1)),
        arm.points,
        axes,
        arm.coms,
        arm.masses,
        inertias_world,
        rotations=rotations,
        gravity=arm.gravity,
    )


def random_serial_arm(
    rng, n: int = 6, prismatic: bool = False, gravity=(0.0, 0.0, -9.81), masses=None
):
    """:func:`armdyn.scenes.extreme.random_spatial_arm` (random geometry, built with the builder)
    with the numpy model of the same arm: the namespace gains ``chain`` (:func:`serial_chain`),
    ``rotations`` (body -> world at q = 0) and ``inertias_world``; ``perm`` maps the chain's
    joint order to armdyn's, q_armdyn[perm[i]] = q_reference[i]."""
    from armdyn.scenes.extreme import random_spatial_arm

    arm = random_spatial_arm(rng, n, prismatic=prismatic, gravity=gravity, masses=masses)
    arm.chain = serial_chain(arm)
    arm.rotations = arm.chain.rotations
    arm.inertias_world = arm.chain.inertias
    return arm
