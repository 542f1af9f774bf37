"""Independent numpy reference dynamics for serial (tree) chains of revolute/prismatic joints.

The dynamics here never call armdyn (only `random_serial_arm` uses the builder, to make the
same arm for both sides). The chain is described exactly like the armdyn builder describes it:
everything in WORLD coordinates at the assembly pose q = 0 (joint points, joint axes, centres of
mass, inertias), plus the parent index of every joint (-1 = ground). Joint i moves body i
relative to body parents[i]; parents[i] < i.

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

from types import SimpleNamespace

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


def random_rotation(rng):
    e = rng.normal(size=4)
    return quat_to_rot(e / np.linalg.norm(e))


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
# random test arms, built both with the armdyn builder and as a reference chain
# ----------------------------------------------------------------------------------------------


def random_unit(rng, n: int = 3):
    v = rng.normal(size=n)
    return v / np.linalg.norm(v)


def random_quat(rng):
    """Random unit Euler parameters, scalar-first, e0 >= 0."""
    e = random_unit(rng, 4)
    return e if e[0] >= 0 else -e


def random_inertia(rng, mass: float, lo: float = 0.002, hi: float = 0.03):
    """A random FULL inertia tensor (body axes, about the CoM): R diag(principal) R^T with the
    principal moments built from second moments s_k > 0 (I1 = s2 + s3, ...), so it is symmetric,
    positive-definite and satisfies the triangle inequality strictly."""
    s = mass * rng.uniform(lo, hi, size=3)
    principal = np.array([s[1] + s[2], s[0] + s[2], s[0] + s[1]])
    r = random_rotation(rng)
    inertia = r @ np.diag(principal) @ r.T
    return 0.5 * (inertia + inertia.T)


def random_serial_arm(
    rng, n: int = 6, prismatic: bool = False, gravity=(0.0, 0.0, -9.81), masses=None
):
    """Random spatial serial arm ground - link1 - ... - linkn built with the builder.

    Random link masses, random FULL inertias (R diag R^T, SPD, triangle inequality), random CoM
    offsets, random body orientations, random joint points and random joint axes. With
    prismatic=True every joint with index % 3 == 1 is prismatic (e.g. R P R R P R for n = 6).
    ``masses`` (n values) replaces the random link masses.

    Returns a namespace with the model and everything the numpy reference needs (world frame at
    q = 0): types, points, axes, coms, masses, inertias_body (body axes), inertias_world,
    quats / rotations (body -> world at q = 0), joint_names, body_names, and `chain`, the
    SerialChain of that geometry, and `perm` such that
    q_armdyn[perm[i]] = q_reference[i].
    """
    types = ["P" if (prismatic and i % 3 == 1) else "R" for i in range(n)]
    points = np.zeros((n, 3))
    steps = np.zeros((n, 3))
    p = np.array([0.0, 0.0, 0.1])
    for i in range(n):
        points[i] = p
        d = random_unit(rng) * rng.uniform(0.15, 0.4)
        steps[i] = d
        p = p + d
    axes = np.array([random_unit(rng) for _ in range(n)])
    # guarantee the axes are not all parallel (random ones never are, but be explicit)
    assert np.linalg.matrix_rank(axes, tol=1e-3) >= 2
    coms = points + 0.5 * steps + 0.05 * rng.normal(size=(n, 3))
    drawn = rng.uniform(0.5, 3.0, size=n)  # drawn either way: the same geometry for a seed
    masses = drawn if masses is None else np.asarray(masses, dtype=float)
    inertias_body = np.array([random_inertia(rng, m) for m in masses])
    quats = np.array([random_quat(rng) for _ in range(n)])
    rotations = np.array([quat_to_rot(e) for e in quats])
    inertias_world = np.einsum("nij,njk,nlk->nil", rotations, inertias_body, rotations)

    body_names = [f"link{i + 1}" for i in range(n)]
    joint_names = [f"j{i + 1}" for i in range(n)]
    from armdyn import _core  # only to build the same arm on the armdyn side

    b = _core.ModelBuilder(gravity=gravity)
    for i in range(n):
        b.add_body(
            body_names[i],
            float(masses[i]),
            inertias_body[i],
            position=coms[i],
            orientation=quats[i],
        )
    for i in range(n):
        parent = "ground" if i == 0 else body_names[i - 1]
        add = b.add_revolute if types[i] == "R" else b.add_prismatic
        add(joint_names[i], parent, body_names[i], points[i], axes[i])
    model = b.finalize()
    chain = SerialChain(
        types,
        list(range(-1, n - 1)),
        points,
        axes,
        coms,
        masses,
        inertias_world,
        rotations=rotations,
        gravity=gravity,
    )
    perm = np.array([list(model.coord_names).index(jn) for jn in joint_names])
    return SimpleNamespace(
        model=model,
        builder=b,
        chain=chain,
        types=types,
        points=points,
        axes=axes,
        coms=coms,
        masses=masses,
        inertias_body=inertias_body,
        inertias_world=inertias_world,
        quats=quats,
        rotations=rotations,
        joint_names=joint_names,
        body_names=body_names,
        perm=perm,
        n=n,
    )
