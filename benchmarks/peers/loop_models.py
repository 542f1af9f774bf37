"""MuJoCo, Pinocchio (constrained dynamics) and Exudyn models of a closed-loop armdyn model, built
from the finalized model's own data: its bodies (mass, inertia about the centre of mass, the
assembled pose ``model.u0``), its joints (:meth:`armdyn.Model.joint_frame`: type, bodies, the
joint point and frame in each body) and the rows its rank test found redundant
(``model.redundant_rows``). Used by ``python -m benchmarks.closed_loop``.

:class:`Topology`
    A spanning tree over the bodies from the ground: joints are taken into the tree in the
    order prismatic, revolute (each by model order), each when it joins a body not yet in the
    tree to one that is; every other joint closes a loop. A body no tree joint reaches gets a
    free joint (MuJoCo ``freejoint``, Pinocchio ``JointModelFreeFlyer``). Tree joints start at
    coordinate 0 in the assembled pose. A loop-closing revolute or inline joint becomes a point
    constraint at its joint point (MuJoCo ``connect``, Pinocchio ``CONTACT_3D``) when armdyn's rank
    test says its rotation rows are redundant (the loop is planar about parallel axes: the point
    rows carry the constraint), else two point constraints, the second one length unit along the
    axis; a spherical one a point constraint; a distance rod a MuJoCo tendon equality and, in
    Pinocchio and Exudyn, a distance constraint.

:func:`mujoco_xml`
    MJCF: each body's frame at its centre of mass with its full inertia tensor, nested along
    the tree; hinge / slide joints at the joint point about the joint axis; RK4; constraints as
    stiff as MuJoCo allows (``benchmarks.peers.closed_loops.SOLIMP``, time constant 2 steps:
    :class:`benchmarks.peers.closed_loops.MujocoPeer`'s ``set_step``).

:class:`PinocchioLoop`
    ``pin.Model`` of the tree and one ``RigidConstraintModel`` per loop closure, integrated by
    SciPy ``solve_ivp`` on ``pin.constraintDynamics`` (Pinocchio's constrained forward dynamics:
    the KKT system by its proximal Cholesky, Baumgarte corrector on the constraint models). The
    proximal iterations also solve the redundant rows of planar loops, which an exact Cholesky
    cannot. Force elements besides gravity come through ``extra_tau`` (q, v) -> tau.

:class:`ExudynLoop`
    Redundant (absolute) coordinates, the Cartesian formulation of armdyn itself: one
    ``NodeRigidBodyEP`` body per armdyn body at its centre of mass, every armdyn joint an
    ``ObjectJointGeneric`` whose constrained axes are the joint's rows less those armdyn found
    redundant (Exudyn's implicit solvers need a full-rank constraint Jacobian), distance rods
    ``ObjectConnectorDistance``; gravity as mass-proportional loads; GeneralizedAlpha or
    TrapezoidalIndex2 at fixed steps.

The observed quantity of every model: the world positions of the bodies' centres of mass in
armdyn's body order, (3 nb,).
"""

from __future__ import annotations

import re

import numpy as np

from benchmarks.peers.closed_loops import SOLIMP, TIMECONST_STEPS, MujocoPeer
from benchmarks.peers.exudyn import _exudyn, implicit_settings, solve_checked

TREE_PRIORITY = {"prismatic": 0, "revolute": 1}
POINT_LIKE = ("revolute", "inline", "spherical")
# the rows of each joint type in armdyn's order, as (translation x, y, z, rotation x, y, z)
# axes of the joint frame: the constrained axes of Exudyn's ObjectJointGeneric
ROW_AXES = {
    "revolute": (0, 1, 2, 3, 4),
    "prismatic": (3, 4, 5, 0, 1),  # armdyn: the rotation rows first
    "spherical": (0, 1, 2),
    "inline": (0, 1),
    "fixed": (0, 1, 2, 3, 4, 5),
}


def quat_to_rot(e) -> np.ndarray:
    """Rotation matrix of a scalar-first unit quaternion."""
    w, x, y, z = np.asarray(e, dtype=float) / np.linalg.norm(e)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def rot_to_quat(r) -> np.ndarray:
    """Scalar-first unit quaternion of a rotation matrix."""
    r = np.asarray(r, dtype=float)
    t = np.trace(r)
    if t > 0:
        s = 2.0 * np.sqrt(t + 1.0)
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0] * 4
        q[0] = (r[k, j] - r[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (r[j, i] + r[i, j]) / s
        q[1 + k] = (r[k, i] + r[i, k]) / s
    q = np.array(q)
    return q / np.linalg.norm(q) * (1 if q[0] >= 0 else -1)


class Topology:
    """The spanning tree, loop closures and assembled poses of a finalized armdyn model."""

    def __init__(self, model):
        self.model = model
        self.bodies = list(model.body_names)
        u0 = np.asarray(model.u0, dtype=float).reshape(-1, 7)
        self.pos = {"ground": np.zeros(3)}
        self.rot = {"ground": np.eye(3)}
        for name, u in zip(self.bodies, u0, strict=True):
            self.pos[name], self.rot[name] = u[:3].copy(), quat_to_rot(u[3:])
        self.mass = dict(zip(self.bodies, np.asarray(model.masses, dtype=float), strict=True))
        self.inertia = dict(zip(self.bodies, np.asarray(model.inertias, dtype=float), strict=True))
        self.joints = {name: model.joint_frame(name) for name in model.joint_names}
        self.redundant = self._redundant_rows(model.redundant_rows)
        self.tree, self.closures, self.free = self._spanning_tree()

    @staticmethod
    def _redundant_rows(rows) -> dict:
        out: dict[str, set] = {}
        for text in rows:
            m = re.match(r"joint '(.+)' row (\d+)", text)
            if m is None:
                raise ValueError(f"loop_models: cannot read the redundant row {text!r}")
            out.setdefault(m.group(1), set()).add(int(m.group(2)))
        return out

    def _spanning_tree(self):
        placed = {"ground"}
        order = sorted(
            (j for j, f in self.joints.items() if f["type"] in TREE_PRIORITY),
            key=lambda j: TREE_PRIORITY[self.joints[j]["type"]],
        )
        tree = []  # (joint, inner body, outer body, reversed)
        grew = True
        while grew:
            grew = False
            for j in order:
                f = self.joints[j]
                a, b = f["parent"], f["child"]
                if (a in placed) != (b in placed):
                    rev = b in placed
                    tree.append((j, b if rev else a, a if rev else b, rev))
                    placed.add(a if rev else b)
                    grew = True
                    break
        in_tree = {t[0] for t in tree}
        closures = [j for j in self.joints if j not in in_tree]
        free = [b for b in self.bodies if b not in placed]
        for j in closures:
            kind = self.joints[j]["type"]
            if kind not in (*POINT_LIKE, "distance"):
                raise NotImplementedError(f"loop_models: a {kind} joint ({j}) closing a loop")
        return tree, closures, free

    def depth_first(self) -> list:
        """The tree joints ordered depth first from the ground."""
        out = []

        def visit(body):
            for t in self.tree:
                if t[1] == body:
                    out.append(t)
                    visit(t[2])

        visit("ground")
        return out

    def side(self, joint: str, body: str):
        """(point, frame) of a joint in one of its bodies' frames."""
        f = self.joints[joint]
        if f["parent"] == body:
            return np.asarray(f["point_parent"]), np.asarray(f["frame_parent"])
        return np.asarray(f["point_child"]), np.asarray(f["frame_child"])

    def world_point(self, joint: str, body: str) -> np.ndarray:
        p, _r = self.side(joint, body)
        return self.pos[body] + self.rot[body] @ p

    def closure_points(self, joint: str) -> list[tuple[str, np.ndarray, str, np.ndarray]]:
        """Point constraints of a loop-closing joint: (body a, point in a, body b, point in b);
        body a is never the ground unless both are."""
        f = self.joints[joint]
        a, b = f["parent"], f["child"]
        if a == "ground":
            a, b = b, a
        pa, ra = self.side(joint, a)
        pb, rb = self.side(joint, b)
        points = [(a, pa, b, pb)]
        planar = {3, 4} <= self.redundant.get(joint, set())
        if f["type"] == "revolute" and not planar:
            points.append((a, pa + ra[:, 2], b, pb + rb[:, 2]))
        return points

    @staticmethod
    def observe_u(u: np.ndarray) -> np.ndarray:
        """armdyn Cartesian states (n, nq) -> CoM positions (n, 3 nb)."""
        u = np.atleast_2d(np.asarray(u, dtype=float))
        return u.reshape(len(u), -1, 7)[:, :, :3].reshape(len(u), -1)


# -- MuJoCo -----------------------------------------------------------------------------------


def _f(x) -> str:
    return repr(float(x))


def _v(x) -> str:
    return " ".join(_f(c) for c in np.ravel(x))


def mujoco_xml(topo: Topology, h: float = 1e-4) -> str:
    """MJCF of the model (see the module docstring)."""
    children: dict[str, list] = {}
    for j, inner, outer, _rev in topo.tree:
        children.setdefault(inner, []).append((j, outer))
    for b in topo.free:
        children.setdefault("ground", []).append((None, b))
    imp = _v(SOLIMP)
    soft = f'solref="{_f(TIMECONST_STEPS * h)} 1" solimp="{imp}"'
    sites: dict[str, list[str]] = {}  # body -> its sites' MJCF (the rods' ends)
    eq, tendons = [], []
    for j in topo.closures:
        f = topo.joints[j]
        if f["type"] == "distance":
            for end, body, point in (
                ("a", f["parent"], f["point_parent"]),
                ("b", f["child"], f["point_child"]),
            ):
                sites.setdefault(body, []).append(f'<site name="{j}_{end}" pos="{_v(point)}"/>')
            tendons.append(
                f'<spatial name="{j}"><site site="{j}_a"/><site site="{j}_b"/></spatial>'
            )
            eq.append(f'<tendon name="{j}" tendon1="{j}" {soft}/>')
            continue
        for k, (a, pa, b, _pb) in enumerate(topo.closure_points(j)):
            b2 = "world" if b == "ground" else b
            eq.append(
                f'<connect name="{j}_{k}" body1="{a}" body2="{b2}" anchor="{_v(pa)}" {soft}/>'
            )

    def body(name, joint, parent):
        r_p, p_p = topo.rot[parent], topo.pos[parent]
        rel_p = r_p.T @ (topo.pos[name] - p_p)
        rel_q = rot_to_quat(r_p.T @ topo.rot[name])
        i = topo.inertia[name]
        full = [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]
        if joint is None:
            jxml = "<freejoint/>"
        else:
            point, frame = topo.side(joint, name)
            kind = "slide" if topo.joints[joint]["type"] == "prismatic" else "hinge"
            jxml = (
                f'<joint name="{joint}" type="{kind}" pos="{_v(point)}" axis="{_v(frame[:, 2])}"/>'
            )
        inner = "".join(body(c, jc, name) for jc, c in children.get(name, []))
        return (
            f'<body name="{name}" pos="{_v(rel_p)}" quat="{_v(rel_q)}">{jxml}'
            f'<inertial pos="0 0 0" mass="{_f(topo.mass[name])}" fullinertia="{_v(full)}"/>'
            f"{''.join(sites.get(name, []))}{inner}</body>"
        )

    world = "".join(sites.get("ground", [])) + "".join(
        body(c, jc, "ground") for jc, c in children.get("ground", [])
    )
    return (
        f'<mujoco model="loop"><compiler angle="radian" autolimits="true"/>'
        f'<option gravity="{_v(topo.model.gravity)}" integrator="RK4" timestep="{_f(h)}"/>'
        f"<worldbody>{world}</worldbody><equality>{''.join(eq)}</equality>"
        + (f"<tendon>{''.join(tendons)}</tendon>" if tendons else "")
        + "</mujoco>"
    )


class MujocoLoop(MujocoPeer):
    """:class:`MujocoPeer` of a :class:`Topology`, observing the bodies' CoM positions."""

    def __init__(self, topo: Topology, h: float = 1e-4):
        super().__init__(mujoco_xml(topo, h), [], lambda q: q)
        self.topo = topo
        self.body_ids = [self.model.body(b).id for b in topo.bodies]

    def observe(self, qpos: np.ndarray) -> np.ndarray:
        mujoco = self.mujoco
        data = mujoco.MjData(self.model)
        out = []
        for q in np.atleast_2d(qpos):
            data.qpos[:] = q
            mujoco.mj_kinematics(self.model, data)
            out.append(data.xipos[self.body_ids].ravel().copy())
        return np.array(out)

    def state_accelerations(self, qvel: np.ndarray):
        """At the assembled configuration with joint rates ``qvel``: MuJoCo's exact-constraint
        CoM accelerations (KKT on ``mj_fullM``, ``qfrc_smooth``, ``efc_J`` and the constraint
        bias from finite differences of efc_J v) and the bodies' velocities (CoM world,
        angular world) to give armdyn the same state. Rows of the KKT by least squares."""
        mujoco = self.mujoco
        m = self.model
        data = mujoco.MjData(m)
        m.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
        data.qvel[:] = qvel
        mujoco.mj_forward(m, data)
        nv = m.nv
        mass = np.zeros((nv, nv))
        mujoco.mj_fullM(m, data, mass)
        jac = np.asarray(data.efc_J).reshape(-1, nv).copy()
        # d/dt (J) v by a central difference along the motion
        eps = 1e-7

        def jac_at(s):
            d2 = mujoco.MjData(m)
            d2.qpos[:] = data.qpos
            mujoco.mj_integratePos(m, d2.qpos, qvel, s)
            mujoco.mj_forward(m, d2)
            return np.asarray(d2.efc_J).reshape(-1, nv).copy()

        jdot_v = (jac_at(eps) - jac_at(-eps)) @ qvel / (2 * eps)
        kkt = np.block([[mass, jac.T], [jac, np.zeros((len(jac), len(jac)))]])
        rhs = np.concatenate([data.qfrc_smooth, -jdot_v])
        qacc = np.linalg.lstsq(kkt, rhs, rcond=None)[0][:nv]
        return self._com_motion(data, qvel, qacc)

    def _com_motion(self, data, qvel, qacc):
        mujoco, m = self.mujoco, self.model
        lin_v, ang_v, lin_a = [], [], []
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        eps = 1e-7
        for b in self.body_ids:
            mujoco.mj_jac(m, data, jp, jr, data.xipos[b], b)
            lin_v.append(jp @ qvel)
            ang_v.append(jr @ qvel)

        # CoM accelerations: J a + (d/dt J) v, the latter by central differences
        def com_vel(s):
            d2 = mujoco.MjData(m)
            d2.qpos[:] = data.qpos
            mujoco.mj_integratePos(m, d2.qpos, qvel, s)
            mujoco.mj_kinematics(m, d2)
            mujoco.mj_comPos(m, d2)
            out = []
            for b in self.body_ids:
                mujoco.mj_jac(m, d2, jp, jr, d2.xipos[b], b)
                out.append(jp @ qvel)
            return np.array(out)

        jdot = (com_vel(eps) - com_vel(-eps)) / (2 * eps)
        for k, b in enumerate(self.body_ids):
            mujoco.mj_jac(m, data, jp, jr, data.xipos[b], b)
            lin_a.append(jp @ qacc + jdot[k])
        return np.array(lin_a), np.array(lin_v), np.array(ang_v)


# -- Pinocchio --------------------------------------------------------------------------------


class PinocchioLoop:
    """Pinocchio's model of a :class:`Topology` with ``pin.constraintDynamics`` (see the module
    docstring). ``baumgarte`` = (Kp, Kd) of the constraint models' corrector."""

    def __init__(
        self, topo: Topology, baumgarte=(0.0, 0.0), prox=(1e-13, 1e-10, 50), extra_tau=None
    ):
        import pinocchio as pin

        if topo.free:
            raise NotImplementedError("PinocchioLoop: bodies held only by constraints")
        self.pin, self.topo = pin, topo
        m = pin.Model()
        m.gravity = pin.Motion(np.asarray(topo.model.gravity, dtype=float), np.zeros(3))
        self.at = {"ground": (0, pin.SE3.Identity())}  # body -> (joint id, CoM frame in it)
        # depth first: Pinocchio's CRBA and constrained dynamics need every subtree's velocity
        # indices contiguous
        for j, inner, outer, _rev in topo.depth_first():
            jid_in, x_in = self.at[inner]
            p_in, r_in = topo.side(j, inner)
            p_out, r_out = topo.side(j, outer)
            placement = x_in * pin.SE3(r_in, p_in)
            kind = (
                pin.JointModelPZ() if topo.joints[j]["type"] == "prismatic" else pin.JointModelRZ()
            )
            jid = m.addJoint(jid_in, kind, placement, j)
            x_body = pin.SE3(r_out, p_out).inverse()
            r = x_body.rotation
            inertia = pin.Inertia(
                topo.mass[outer], x_body.translation, r @ topo.inertia[outer] @ r.T
            )
            m.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
            self.at[outer] = (jid, x_body)
        self.model, self.data = m, m.createData()
        self.frames = {}
        for b in topo.bodies:
            jid, x = self.at[b]
            self.frames[b] = m.addFrame(pin.Frame(f"com_{b}", jid, x, pin.FrameType.OP_FRAME))
        self.data = m.createData()
        self.constraints = pin.StdVec_RigidConstraintModel()
        for j in topo.closures:
            if topo.joints[j]["type"] == "distance":
                raise NotImplementedError("PinocchioLoop: distance rods")
            for a, pa, b, pb in topo.closure_points(j):
                ja, xa = self.at[a]
                jb, xb = self.at[b]
                cm = pin.RigidConstraintModel(
                    pin.ContactType.CONTACT_3D,
                    m,
                    ja,
                    xa * pin.SE3(topo.rot[a].T, pa),
                    jb,
                    xb * pin.SE3(topo.rot[b].T, pb),
                    pin.ReferenceFrame.LOCAL,
                )
                if hasattr(cm, "setBaumgarteCorrectorParameters"):  # Pinocchio 4
                    cm.setBaumgarteCorrectorParameters(
                        pin.BaumgarteCorrectorParameters(float(baumgarte[0]), float(baumgarte[1]))
                    )
                else:  # Pinocchio 3: one gain per constraint row
                    cm.corrector.Kp[:] = float(baumgarte[0])
                    cm.corrector.Kd[:] = float(baumgarte[1])
                self.constraints.append(cm)
        self.cdatas = pin.StdVec_RigidConstraintData()
        for cm in self.constraints:
            self.cdatas.append(cm.createData())
        pin.initConstraintDynamics(m, self.data, self.constraints, self.cdatas)
        self.prox = pin.ProximalSettings(prox[0], prox[1], int(prox[2]))
        self.extra_tau = extra_tau
        self.nq, self.nv = m.nq, m.nv
        self.tau0 = np.zeros(m.nv)

    def accelerations(self, q, v):
        tau = self.tau0 if self.extra_tau is None else self.extra_tau(self, q, v)
        return self.pin.constraintDynamics(
            self.model, self.data, q, v, tau, self.constraints, self.cdatas, self.prox
        )

    def rhs(self):
        nq = self.nq

        def f(_t, y):
            return np.concatenate([y[nq:], self.accelerations(y[:nq], y[nq:])])

        return f, np.zeros(nq + self.nv)

    def observe_y(self, y: np.ndarray) -> np.ndarray:
        """States (nq + nv, n) as solve_ivp returns them -> CoM positions (n, 3 nb)."""
        pin, m, d = self.pin, self.model, self.data
        out = []
        for col in np.atleast_2d(y.T):
            pin.framesForwardKinematics(m, d, col[: self.nq])
            out.append(
                np.concatenate([d.oMf[self.frames[b]].translation for b in self.topo.bodies])
            )
        return np.array(out)

    def com_motion(self, q, v, a):
        """CoM world velocities, world angular velocities and CoM (classical) accelerations."""
        pin, m, d = self.pin, self.model, self.data
        pin.forwardKinematics(m, d, q, v, a)
        pin.updateFramePlacements(m, d)
        lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        lin_v, ang_v, lin_a = [], [], []
        for b in self.topo.bodies:
            fid = self.frames[b]
            vel = pin.getFrameVelocity(m, d, fid, lwa)
            lin_v.append(vel.linear.copy())
            ang_v.append(vel.angular.copy())
            lin_a.append(pin.getFrameClassicalAcceleration(m, d, fid, lwa).linear.copy())
        return np.array(lin_a), np.array(lin_v), np.array(ang_v)

    def constraint_jacobian(self, q) -> np.ndarray:
        """The loop closures' Jacobian at q (the constraint datas updated by one
        ``constraintDynamics`` call at rest first: getConstraintsJacobian reads them)."""
        pin = self.pin
        self.accelerations(q, np.zeros(self.nv))
        pin.computeJointJacobians(self.model, self.data, q)
        return pin.getConstraintsJacobian(self.model, self.data, self.constraints, self.cdatas)


# -- Exudyn -----------------------------------------------------------------------------------


class ExudynLoop:
    """Exudyn's redundant-coordinate model of a :class:`Topology` (see the module docstring)."""

    def __init__(self, topo: Topology, extra=None, velocities=None):
        self.topo = topo
        self.extra = extra  # (mbs, bodies: name -> object number) -> None: more loads
        # initial (CoM velocity, angular velocity), both in world, per body; default at rest
        self.velocities = velocities or {}

    def system(self):
        from exudyn.rigidBodyUtilities import RigidBodyInertia

        exu, eii = _exudyn()
        topo = self.topo
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        ground = mbs.AddObject(eii.ObjectGround(visualization=eii.VObjectGround(show=False)))
        objects, nodes = {"ground": ground}, {}
        g = [float(c) for c in topo.model.gravity]
        zero = (np.zeros(3), np.zeros(3))
        for b in topo.bodies:
            res = mbs.CreateRigidBody(
                inertia=RigidBodyInertia(
                    mass=topo.mass[b], inertiaTensor=topo.inertia[b], inertiaTensorAtCOM=True
                ),
                referencePosition=topo.pos[b],
                referenceRotationMatrix=topo.rot[b],
                gravity=g,
                initialVelocity=list(map(float, self.velocities.get(b, zero)[0])),
                initialAngularVelocity=list(map(float, self.velocities.get(b, zero)[1])),
                nodeType=exu.NodeType.RotationEulerParameters,
                show=False,
                returnDict=True,
            )
            objects[b], nodes[b] = res["bodyNumber"], res["nodeNumber"]
        for j, f in topo.joints.items():
            self._joint(mbs, objects, j, f)
        if self.extra is not None:
            self.extra(mbs, objects)
        mbs.Assemble()
        return sc, mbs, nodes

    def _joint(self, mbs, objects, j, f):
        exu, eii = _exudyn()
        topo = self.topo
        if f["type"] == "distance":
            ma, mb = (
                mbs.AddMarker(
                    eii.MarkerBodyPosition(bodyNumber=objects[b], localPosition=list(map(float, p)))
                )
                for b, p in ((f["parent"], f["point_parent"]), (f["child"], f["point_child"]))
            )
            length = np.linalg.norm(
                topo.world_point(j, f["parent"]) - topo.world_point(j, f["child"])
            )
            mbs.AddObject(
                eii.ObjectConnectorDistance(
                    markerNumbers=[ma, mb],
                    distance=float(length),
                    visualization=eii.VObjectConnectorDistance(show=False),
                )
            )
            return
        markers = []
        for b in (f["parent"], f["child"]):
            p, r = topo.side(j, b)
            markers.append(
                mbs.AddMarker(
                    eii.MarkerBodyRigid(
                        bodyNumber=objects[b], localHT=exu.HT(rotation=r, translation=p)
                    )
                )
            )
        rows = ROW_AXES[f["type"]]
        drop = topo.redundant.get(j, set())
        axes = [0] * 6
        for k, axis in enumerate(rows):
            if k not in drop:
                axes[axis] = 1
        mbs.AddObject(
            eii.ObjectJointGeneric(
                markerNumbers=markers,
                constrainedAxes=axes,
                visualization=eii.VObjectJointGeneric(show=False),
            )
        )

    def runner(self, t_end: float, n_steps: int, method: str, newton_rtol: float = 1e-10):
        """A function that solves from the start once more and returns (CoM positions at
        ``t_end`` (1, 3 nb), step statistics); RuntimeError with Exudyn's reason on failure."""
        exu = _exudyn()[0]
        _sc, mbs, nodes = self.system()
        self._keep = _sc  # the system container owns mbs
        ss = implicit_settings(t_end, n_steps, t_end, 0.9, newton_rtol)
        ss.solution.sensors.active = False
        ss.linearSolver.ignoreSingularJacobian = False
        if 6 * len(nodes) > 60:
            ss.linearSolver.solverType = exu.LinearSolverType.EigenSparse
        bodies = self.topo.bodies

        def solve():
            stats = solve_checked(mbs, ss, method, t_end)
            pos = [mbs.GetNodeOutput(nodes[b], exu.OutputVariableType.Position) for b in bodies]
            return np.concatenate(pos)[None, :], stats

        return solve

    def initial_accelerations(self) -> np.ndarray:
        """CoM accelerations at t = 0 from Exudyn's own initial-acceleration solve, (nb, 3)."""
        exu = _exudyn()[0]
        _sc, mbs, nodes = self.system()
        ss = implicit_settings(1.0, 1, 1.0, 0.9, 1e-10)
        ss.linearSolver.ignoreSingularJacobian = False
        solver = exu.MainSolverImplicitSecondOrder()
        solver.InitializeSolver(mbs, ss)
        acc = [
            np.asarray(mbs.GetNodeOutput(nodes[b], exu.OutputVariableType.Acceleration))
            for b in self.topo.bodies
        ]
        solver.FinalizeSolver(mbs, ss)
        return np.array(acc)
