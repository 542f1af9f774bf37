"""MuJoCo, Exudyn and SciPy-on-Pinocchio peer models of the closed-loop standard problems:
Andrews' squeezer and the IFToMM A02 N-four-bar (``python -m benchmarks.workprecision squeezer``
and ``... a02``).

Both mechanisms are planar; every peer model is built from the same data as armdyn's
(:data:`armdyn.scenes.standard.SQUEEZER`, :func:`~armdyn.scenes.standard.squeezer_points`, the A02
specification of :func:`~armdyn.scenes.standard.iftomm_a02_four_bar`), not from armdyn's model.

MuJoCo (:func:`mujoco_squeezer`, :func:`mujoco_a02`)
    A kinematic tree of hinge joints about z, built in the starting configuration, each hinge's
    ``ref`` set to its angle there, so qpos are the problem's own angles. Squeezer: ground - K1
    (hinge O, angle beta) - K2 (F, Theta); ground - K3 (B, gamma); ground - K5 (A, delta) - K4
    (G, Phi); ground - K7 (A, epsilon) - K6 (H, Omega); the three loops close at E with
    ``<equality><connect>`` K2-K3, K2-K4, K2-K6. Masses and in-plane inertias about the centres
    of mass as in the Test Set (out-of-plane ones equal, they do not enter). The spring C-D is a
    spatial tendon between a world site C and a site D on K3 with ``stiffness`` c0 and
    ``springlength`` l0: MuJoCo's passive tendon force -c0 (L - l0) along C-D, the armdyn and
    Hairer-Wanner law exactly, evaluated at every RK4 stage (forces put into ``qfrc_applied``
    once per step would be held over the step and cost RK4 its order). The drive torque is a
    ``<general>`` actuator on hinge O with gain 0 and an affine bias 0.033 N m: a constant torque
    that survives ``mj_resetData``. No gravity. A02: crank i a hinge at A_i = (i, 0) to the world,
    coupler i a hinge at B_{i-1} on crank i-1, and a ``connect`` at B_i between coupler i and
    crank i; 1 kg, 1 m uniform bars (inertia 1/12 about the centre, the armdyn values out of
    plane), gravity -9.81 y; the initial velocities (cranks -1 rad/s, couplers translating at
    1 m/s) are the model's keyframe.

    Solver: RK4 (``mjINT_RK4``) at fixed steps h (output spacing / h an integer). MuJoCo's
    constraints are always soft: the constraint acceleration is pulled to aref = -b (J v) - k r
    with the regulariser R = (1 - d) / d * diag(J M^-1 J^T), and the impedance d is clamped to
    mjMAXIMP = 0.9999, so they can be made stiff but never exact. Settings: ``solimp`` =
    (0.9999, 0.9999, 0.001, 0.5, 2) (d = 0.9999 everywhere, the most MuJoCo allows) and
    ``solref`` = (2 h, 1): time constant twice the step (the smallest MuJoCo's ``refsafe`` flag
    allows), critically damped, set again for every step size, so the constraint error shrinks
    like h^2 with the step. Newton solver, default tolerance. A run whose accelerations blow up
    (MuJoCo then resets the state and warns ``mjWARN_BADQACC``) is a failed point. The curves
    come through the problem's ``more_peers`` hook, not ``workprecision.sweep_mujoco``, because
    the time constant changes with every step and the steps must suit each problem's time scale.

Exudyn (:func:`exudyn_squeezer`, :func:`exudyn_a02`)
    Redundant (absolute) coordinates: one ``NodeRigidBody2D`` (x, y, theta of the centre of
    mass) with an ``ObjectRigidBody2D`` per body, every revolute (the tree joints and the loop
    closures alike) an ``ObjectJointRevolute2D`` (two algebraic equations with multipliers)
    between two ``MarkerBodyPosition``. Squeezer: 21 coordinates, 20 constraints; the spring is
    an ``ObjectConnectorSpringDamper`` C-D (stiffness c0, reference length l0, no damping: the
    same law), the torque a ``LoadTorqueVector`` on K1. A02 (N = 40): 243 coordinates and 242
    constraints, gravity a ``LoadMassProportional`` per body; at the flat positions the
    constraint Jacobian loses 40 ranks.

    Solvers: 'GeneralizedAlpha' (index 3, spectral radius 0.9 as for the UR5 peer) and
    'TrapezoidalIndex2' (index 2), both second order at fixed steps (Exudyn has no error control
    for implicit solvers, and its explicit ones refuse constraints: see
    :mod:`benchmarks.peers.exudyn`). Newton relative tolerance 1e-10 (absolute 1e-12), Exudyn's
    default modified Newton; ``EXUdense`` for the 41 unknowns of the squeezer, ``EigenSparse``
    for the 485 of A02. The angles come from node sensors sampled on the output grid, each
    sample checked to lie on it. ``linearSolver.ignoreSingularJacobian`` stays off, so a
    singular factor at A02's flat positions shows as a failure. Failed runs are recorded as
    failed points with the reason.

SciPy on Pinocchio (:class:`PinocchioA02`, A02 only)
    What a SciPy user writes for a closed loop on Pinocchio: the open tree (cranks on the world,
    couplers on the cranks' tips, joints added depth first), the loop closures as the in-plane
    rows of a point constraint between frames on the coupler's and the crank's tips, and the
    index-1 equations with Baumgarte terms (alpha = beta = 10 1/s), solved by ``np.linalg.solve``
    on the dense KKT matrix at every evaluation and integrated by ``solve_ivp`` (DOP853). This is
    the SciPy peer of A02: the SciPy curve of ``workprecision.PROBLEMS['a02']`` integrates the
    reference's own one-DOF equation, which presumes the motion, and is marked as not a peer.
    At the flat positions the KKT matrix is singular; a run that stops there is a failed point
    with the time it reached.

Checks (tests/peers/test_peer_closed_loops.py): the hard-constraint accelerations from MuJoCo's own
terms (``mj_fullM``, ``qfrc_smooth``, ``efc_J``; KKT solve), Exudyn's own initial-acceleration
solve and PinocchioA02's accelerations equal the references'; the errors fall under step
refinement.

CPU time: the median of warm repeats (:func:`benchmarks.common.cpu_time`) of the stepping alone:
MuJoCo ``mj_resetData`` + ``mj_step`` between outputs, Exudyn ``SolveDynamic`` on an assembled
system (which restarts from the initial state each time) + reading its sensors. Building and
compiling the models is not timed.

``python -m benchmarks.peers.closed_loops`` prints the checks and a short convergence table.
Measured figures and the settings tried while building these models:
``benchmarks/results/peer_notes.md``.
"""

from __future__ import annotations

import contextlib
import time

import numpy as np
from armdyn.scenes import standard

from benchmarks import common
from benchmarks.peers.exudyn import _exudyn, implicit_settings, solve_checked
from benchmarks.peers.pinocchio import mass_matrix

SQUEEZER_JOINTS = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")
A02_N = 40  # the workprecision problem's N
# MuJoCo constraint softness: impedance 0.9999 (mjMAXIMP) everywhere; time constant 2 steps
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
TIMECONST_STEPS = 2.0
NEWTON_RTOL = 1e-10
SPECTRAL_RADIUS = 0.9
EXUDYN_METHODS = ("GeneralizedAlpha", "TrapezoidalIndex2")

# work-precision sweeps: MuJoCo step sizes [s], Exudyn numbers of steps
SQUEEZER_MJ_STEPS = tuple(1e-4 / 2**k for k in range(7))  # 1e-4 ... 1.5625e-6
SQUEEZER_MJ_QUICK = (1.25e-5,)
SQUEEZER_EXU_STEPS = (300, 600, 1200, 2400, 4800, 9600, 19200, 38400)
SQUEEZER_EXU_QUICK = (2400,)
A02_MJ_STEPS = (1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4)
A02_MJ_QUICK = (2.5e-3,)
A02_EXU_STEPS = (400, 800, 1600, 3200, 6400, 12800)
A02_EXU_QUICK = (1600,)
A02_SCIPY_RTOLS = (1e-4, 1e-6, 1e-8)  # SciPy DOP853 on Pinocchio
A02_SCIPY_QUICK = (1e-4,)


def _f(x) -> str:
    return repr(float(x))


def _xyz(p) -> str:
    return f"{_f(p[0])} {_f(p[1])} 0"


def squeezer_to_angles(phi: np.ndarray) -> np.ndarray:
    """The seven angles (beta, Theta, gamma, Phi, delta, Omega, epsilon) from the rotations of
    the bodies K1..K7 since the start, (..., 7) -> (..., 7); with ``q0`` = 0 it maps angular
    velocities or accelerations."""
    a = np.asarray(phi, dtype=float)
    return np.stack(
        [
            a[..., 0],
            a[..., 1] - a[..., 0],
            a[..., 2],
            a[..., 3] - a[..., 4],
            a[..., 4],
            a[..., 5] - a[..., 6],
            a[..., 6],
        ],
        axis=-1,
    )


# -- MuJoCo -----------------------------------------------------------------------------------


def squeezer_mjcf() -> str:
    """MJCF of Andrews' squeezer (see the module docstring); qpos = the seven angles in the
    order of ``SQUEEZER_JOINTS`` after a name lookup."""
    p = standard.SQUEEZER
    q0 = [float(a) for a in p["q0"]]
    pts = standard.squeezer_points(q0)
    imp = " ".join(_f(s) for s in SOLIMP)

    def body(k, name, point, origin, angle, inner=""):
        # body frame at its hinge, world-aligned in the starting configuration
        i = _f(p["I"][k])
        return (
            f'<body name="K{k + 1}" pos="{_xyz(pts[point] - origin)}">'
            f'<joint name="{name}" type="hinge" axis="0 0 1" ref="{_f(angle)}"/>'
            f'<inertial pos="{_xyz(pts["com"][k] - pts[point])}" mass="{_f(p["m"][k])}" '
            f'diaginertia="{i} {i} {i}"/>{inner}</body>'
        )

    zero = np.zeros(2)
    d_site = f'<site name="D" pos="{_xyz(pts["D"] - pts["B"])}"/>'
    tree = [
        body(0, "beta", "O", zero, q0[0], body(1, "Theta", "F", pts["O"], q0[1])),
        body(2, "gamma", "B", zero, q0[2], d_site),
        body(4, "delta", "A", zero, q0[4], body(3, "Phi", "G", pts["A"], q0[3])),
        body(6, "epsilon", "A", zero, q0[6], body(5, "Omega", "H", pts["A"], q0[5])),
    ]
    anchor = _xyz(pts["E"] - pts["F"])  # E in K2's frame
    h = 1e-5  # the starting step; set_step(h) sets the same time constant and softness
    loops = "".join(
        f'<connect name="E{k}" body1="K2" body2="K{k}" anchor="{anchor}" '
        f'solref="{_f(TIMECONST_STEPS * h)} 1" solimp="{imp}"/>'
        for k in (3, 4, 6)
    )
    return (
        '<mujoco model="andrews_squeezer"><compiler angle="radian"/>'
        f'<option gravity="0 0 0" integrator="RK4" timestep="{_f(h)}"/>'
        f'<worldbody><site name="C" pos="{_xyz(pts["C"])}"/>{"".join(tree)}</worldbody>'
        f"<equality>{loops}</equality>"
        f'<tendon><spatial name="spring" stiffness="{_f(p["c0"])}" '
        f'springlength="{_f(p["l0"])}"><site site="C"/><site site="D"/></spatial></tendon>'
        f'<actuator><general name="motor" joint="beta" gainprm="0" biastype="affine" '
        f'biasprm="{_f(p["mom"])} 0 0"/></actuator></mujoco>'
    )


def a02_mjcf(n: int = A02_N, phi0: float = np.pi / 2, speed: float = 1.0) -> str:
    """MJCF of the A02 N-four-bar with the cranks at ``phi0`` from +x (the specification:
    upright) turning at -``speed`` rad/s, the couplers translating; qpos of hinge ``A{i}`` is
    crank i's angle from +x."""
    i12 = 1.0 / 12.0
    h = 1e-3  # the starting step; set_step(h) sets the same time constant and softness
    imp = " ".join(_f(s) for s in SOLIMP)
    e = np.array([np.cos(phi0), np.sin(phi0)])
    quat = f"{_f(np.cos(phi0 / 2))} 0 0 {_f(np.sin(phi0 / 2))}"  # crank axis = inertial x
    bodies, loops = [], []
    for i in range(n + 1):
        coupler = ""
        if i < n:
            coupler = (
                f'<body name="coupler{i + 1}" pos="{_xyz(e)}">'
                f'<joint name="B{i}" type="hinge" axis="0 0 1" ref="{_f(-phi0)}"/>'
                f'<inertial pos="0.5 0 0" mass="1" diaginertia="{_f(1e-4 * i12)} {_f(i12)} '
                f'{_f(i12)}"/></body>'
            )
        bodies.append(
            f'<body name="crank{i}" pos="{i} 0 0">'
            f'<joint name="A{i}" type="hinge" axis="0 0 1" ref="{_f(phi0)}"/>'
            f'<inertial pos="{_xyz(0.5 * e)}" quat="{quat}" mass="1" '
            f'diaginertia="{_f(1e-4 * i12)} {_f(i12)} {_f(i12)}"/>{coupler}</body>'
        )
        if i > 0:
            loops.append(
                f'<connect name="C{i}" body1="coupler{i}" body2="crank{i}" anchor="1 0 0" '
                f'solref="{_f(TIMECONST_STEPS * h)} 1" solimp="{imp}"/>'
            )
    # qvel in tree order: A0, B0, A1, B1, ..., A{n}; couplers turn at +speed against their crank
    qvel = " ".join([f"{_f(-speed)} {_f(speed)}"] * n + [_f(-speed)])
    return (
        f'<mujoco model="iftomm_a02_{n}"><compiler angle="radian"/>'
        f'<option gravity="0 {_f(-standard.G)} 0" integrator="RK4" timestep="{_f(h)}"/>'
        f"<worldbody>{''.join(bodies)}</worldbody><equality>{''.join(loops)}</equality>"
        f'<keyframe><key name="start" qvel="{qvel}"/></keyframe></mujoco>'
    )


class MujocoPeer:
    """A compiled MuJoCo model of one closed-loop problem with its observation map.

    ``set_step(h)`` sets the RK4 step and the constraints' time constant (2 h); ``run`` steps
    from the start (keyframe 0 if there is one) and returns qpos on the output grid.
    """

    def __init__(self, xml: str, observed_joints, observe):
        import mujoco

        self.mujoco = mujoco
        self.xml = xml
        self.model = mujoco.MjModel.from_xml_string(xml)  # RK4, softness as set_step
        self.qpos_index = np.array(
            [self.model.joint(name).qposadr[0] for name in observed_joints], dtype=int
        )
        self.dof_index = np.array(
            [self.model.joint(name).dofadr[0] for name in observed_joints], dtype=int
        )
        self._observe = observe

    def set_step(self, h: float) -> None:
        self.model.opt.timestep = float(h)
        self.model.eq_solref[:, 0] = TIMECONST_STEPS * float(h)
        self.model.eq_solref[:, 1] = 1.0
        self.model.eq_solimp[:] = SOLIMP

    def reset(self, data) -> None:
        if self.model.nkey:
            self.mujoco.mj_resetDataKeyframe(self.model, data, 0)
        else:
            self.mujoco.mj_resetData(self.model, data)

    def observe(self, qpos: np.ndarray) -> np.ndarray:
        """qpos (n, nq) -> the problem's observed quantities (n, k)."""
        return self._observe(np.asarray(qpos)[:, self.qpos_index])

    def run(self, data, t_end: float, n_out: int) -> np.ndarray:
        """RK4 from the start to ``t_end`` at the current step; qpos on ``n_out + 1`` equally
        spaced times. Raises ``RuntimeError`` if MuJoCo found the accelerations blowing up."""
        mujoco = self.mujoco
        h = self.model.opt.timestep
        per = round(t_end / n_out / h)
        if per < 1 or abs(per * h * n_out - t_end) > 1e-9 * t_end:
            raise ValueError(f"peer_closed_loops: step {h:g} does not divide the output spacing")
        self.reset(data)
        qpos = np.empty((n_out + 1, self.model.nq))
        qpos[0] = data.qpos
        for k in range(n_out):
            mujoco.mj_step(self.model, data, nstep=per)
            qpos[k + 1] = data.qpos
        bad = data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number
        if bad or not np.all(np.isfinite(qpos)):
            raise RuntimeError(
                f"MuJoCo RK4 unstable at h = {h:g}: NaN/huge qacc ({bad} resets of the state)"
            )
        return qpos

    def loop_residual(self, qpos: np.ndarray) -> float:
        """Largest loop-closure violation |efc_pos| [m] over the given configurations."""
        data = self.mujoco.MjData(self.model)
        worst = 0.0
        for q in qpos:
            data.qpos[:] = q
            self.mujoco.mj_fwdPosition(self.model, data)
            if data.nefc:
                worst = max(worst, float(np.abs(data.efc_pos).max()))
        return worst

    def accelerations(self, qpos=None, qvel=None) -> tuple[np.ndarray, np.ndarray]:
        """At the start (or the given state): MuJoCo's own soft-constraint ``qacc`` and the
        exact-constraint accelerations from MuJoCo's terms, the KKT system
        [M J^T; J 0] [a; -f] = [qfrc_smooth; 0] with M = ``mj_fullM``, J = ``efc_J`` (valid at
        rest only, where J'v = 0). Both for the observed joints."""
        mujoco = self.mujoco
        data = mujoco.MjData(self.model)
        self.reset(data)
        if qpos is not None:
            data.qpos[:] = qpos
        if qvel is not None:
            data.qvel[:] = qvel
        if np.any(data.qvel):
            raise ValueError("peer_closed_loops: the KKT check needs a state at rest")
        jacobian = self.model.opt.jacobian
        self.model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE  # efc_J as a dense matrix
        try:
            mujoco.mj_forward(self.model, data)
        finally:
            self.model.opt.jacobian = jacobian
        nv = self.model.nv
        m = np.zeros((nv, nv))
        mujoco.mj_fullM(self.model, data, m)
        jac = np.asarray(data.efc_J).reshape(-1, nv)
        kkt = np.block([[m, jac.T], [jac, np.zeros((len(jac), len(jac)))]])
        rhs = np.concatenate([data.qfrc_smooth, np.zeros(len(jac))])
        # the out-of-plane rows of the connects are zero: least squares
        hard = np.linalg.lstsq(kkt, rhs, rcond=None)[0][:nv]
        return data.qacc[self.dof_index].copy(), hard[self.dof_index]


def mujoco_squeezer() -> MujocoPeer:
    """Andrews' squeezer in MuJoCo; observes the seven angles."""
    return MujocoPeer(squeezer_mjcf(), SQUEEZER_JOINTS, lambda q: q)


def mujoco_a02(n: int = A02_N, phi0: float = np.pi / 2, speed: float = 1.0) -> MujocoPeer:
    """A02 in MuJoCo; observes B0 = (cos, sin) of crank 0's angle."""
    return MujocoPeer(
        a02_mjcf(n, phi0, speed),
        ["A0"],
        lambda q: np.column_stack([np.cos(q[:, 0]), np.sin(q[:, 0])]),
    )


# -- Exudyn -----------------------------------------------------------------------------------


class _Planar:
    """An Exudyn system of planar rigid bodies (node at the centre of mass) and revolute joints
    given by their world points in the starting configuration."""

    def __init__(self):
        exu, eii = _exudyn()
        self.exu, self.eii = exu, eii
        self.sc = exu.SystemContainer()
        self.mbs = self.sc.AddSystem()
        self.ground = self.mbs.AddObject(
            eii.ObjectGround(visualization=eii.VObjectGround(show=False))
        )
        self.frames = {None: (self.ground, np.zeros(2), 0.0)}  # body, origin, angle
        self.nodes = {}

    def body(self, name, mass, inertia, com, angle=0.0, velocity=(0.0, 0.0), omega=0.0):
        eii = self.eii
        node = self.mbs.AddNode(
            eii.NodeRigidBody2D(
                referenceCoordinates=[float(com[0]), float(com[1]), float(angle)],
                initialVelocities=[float(velocity[0]), float(velocity[1]), float(omega)],
                visualization=eii.VNodeRigidBody2D(show=False),
            )
        )
        obj = self.mbs.AddObject(
            eii.ObjectRigidBody2D(
                mass=float(mass),
                inertia=float(inertia),
                nodeNumber=node,
                visualization=eii.VObjectRigidBody2D(show=False),
            )
        )
        self.frames[name] = (obj, np.asarray(com, dtype=float), float(angle))
        self.nodes[name] = node
        return obj

    def marker(self, name, point):
        obj, origin, angle = self.frames[name]
        c, s = np.cos(angle), np.sin(angle)
        d = np.asarray(point, dtype=float) - origin
        local = (c * d[0] + s * d[1], -s * d[0] + c * d[1])
        return self.mbs.AddMarker(
            self.eii.MarkerBodyPosition(
                bodyNumber=obj, localPosition=[float(local[0]), float(local[1]), 0.0]
            )
        )

    def revolute(self, a, b, point):
        eii = self.eii
        self.mbs.AddObject(
            eii.ObjectJointRevolute2D(
                markerNumbers=[self.marker(a, point), self.marker(b, point)],
                visualization=eii.VObjectJointRevolute2D(show=False),
            )
        )

    def gravity(self, name, g):
        eii = self.eii
        m = self.mbs.AddMarker(eii.MarkerBodyMass(bodyNumber=self.frames[name][0]))
        self.mbs.AddLoad(
            eii.LoadMassProportional(
                markerNumber=m,
                loadVector=[float(g[0]), float(g[1]), 0.0],
                visualization=eii.VLoadMassProportional(show=False),
            )
        )


class ExudynPeer:
    """An Exudyn redundant-coordinate model of one closed-loop problem.

    ``build`` () -> (_Planar, names of the observed bodies); ``observe`` maps the observed
    bodies' rotation angles (n, k) (reference angle + node rotation) to the problem's
    quantities. ``sparse``: ``EigenSparse`` instead of ``EXUdense``.
    """

    def __init__(self, build, observe, sparse=False):
        self._build = build
        self._observe = observe
        self.sparse = sparse

    def system(self):
        """A fresh assembled system with Coordinates sensors on the observed nodes. Returns
        (_Planar, sensors, names and reference angles of the observed bodies)."""
        exu, eii = _exudyn()
        planar, observed = self._build()
        sensors = [
            planar.mbs.AddSensor(
                eii.SensorNode(
                    nodeNumber=planar.nodes[name],
                    outputVariableType=exu.OutputVariableType.Coordinates,
                    storeInternal=True,
                    writeToFile=False,
                    visualization=eii.VSensorNode(show=False),
                )
            )
            for name in observed
        ]
        planar.mbs.Assemble()
        angle0 = np.array([planar.frames[name][2] for name in observed])
        return planar, sensors, observed, angle0

    def _settings(self, t_end, n_steps, n_out, spectral_radius, newton_rtol):
        exu = _exudyn()[0]
        ss = implicit_settings(t_end, n_steps, t_end / n_out, spectral_radius, newton_rtol)
        if self.sparse:
            ss.linearSolver.solverType = exu.LinearSolverType.EigenSparse
        # off: a singular factor shows as a failed run, not as silently regularised steps
        ss.linearSolver.ignoreSingularJacobian = False
        return ss

    def initial_accelerations(self) -> np.ndarray:
        """Angular accelerations of the observed bodies at t = 0 from Exudyn's own initial
        acceleration solve (``computeInitialAccelerations`` in ``InitializeSolver``)."""
        exu = _exudyn()[0]
        planar, _sensors, observed, _angle0 = self.system()
        ss = self._settings(1.0, 1, 1, SPECTRAL_RADIUS, NEWTON_RTOL)
        solver = exu.MainSolverImplicitSecondOrder()
        solver.InitializeSolver(planar.mbs, ss)
        acc = [
            planar.mbs.GetNodeOutput(planar.nodes[name], exu.OutputVariableType.Coordinates_tt)[2]
            for name in observed
        ]
        solver.FinalizeSolver(planar.mbs, ss)
        return np.array(acc)

    def runner(
        self,
        t_end: float,
        n_out: int,
        n_steps: int,
        method: str,
        spectral_radius: float = SPECTRAL_RADIUS,
        newton_rtol: float = NEWTON_RTOL,
    ):
        """A function that solves the problem once more (``SolveDynamic`` restarts from the
        initial state on the same assembled system) and returns (observed quantities on the
        ``n_out + 1`` output times, step statistics). Raises ``RuntimeError`` with Exudyn's
        reason when the solve stops."""
        if method not in EXUDYN_METHODS:
            raise ValueError(f"peer_closed_loops: Exudyn method {method!r} not in {EXUDYN_METHODS}")
        if n_steps % n_out:
            raise ValueError("peer_closed_loops: n_steps must be a multiple of n_out")
        planar, sensors, _observed, angle0 = self.system()
        ss = self._settings(t_end, n_steps, n_out, spectral_radius, newton_rtol)
        t_out = np.linspace(0.0, t_end, n_out + 1)
        h = t_end / n_steps
        mbs = planar.mbs

        def solve():
            stats = solve_checked(mbs, ss, method, t_end)
            data = [np.asarray(mbs.GetSensorStoredData(s)) for s in sensors]
            t = data[0][:, 0]
            if len(t) != n_out + 1 or np.abs(t - t_out).max() > 1e-6 * h:
                raise RuntimeError("peer_closed_loops: Exudyn's sensor samples miss output times")
            angles = angle0 + np.column_stack([d[:, 3] for d in data])
            return self._observe(angles), stats

        return solve

    def trajectory(self, t_end, n_out, n_steps, method, **kwargs):
        """One run: (observed quantities on the output grid, CPU s of the solve, statistics)."""
        solve = self.runner(t_end, n_out, n_steps, method, **kwargs)
        t0 = time.process_time()
        obs, stats = solve()
        return obs, time.process_time() - t0, stats


def _squeezer_planar():
    p = standard.SQUEEZER
    pts = standard.squeezer_points(p["q0"])
    pl = _Planar()
    names = [f"K{k + 1}" for k in range(7)]
    for k, name in enumerate(names):
        pl.body(name, p["m"][k], p["I"][k], pts["com"][k])
    for a, b, point in (
        (None, "K1", "O"),
        ("K1", "K2", "F"),
        (None, "K3", "B"),
        (None, "K5", "A"),
        ("K5", "K4", "G"),
        (None, "K7", "A"),
        ("K7", "K6", "H"),
        ("K2", "K3", "E"),
        ("K2", "K4", "E"),
        ("K2", "K6", "E"),
    ):
        pl.revolute(a, b, pts[point])
    eii = pl.eii
    pl.mbs.AddObject(
        eii.ObjectConnectorSpringDamper(
            markerNumbers=[pl.marker(None, pts["C"]), pl.marker("K3", pts["D"])],
            referenceLength=float(p["l0"]),
            stiffness=float(p["c0"]),
            damping=0.0,
            visualization=eii.VObjectConnectorSpringDamper(show=False),
        )
    )
    rigid = pl.mbs.AddMarker(
        eii.MarkerBodyRigid(bodyNumber=pl.frames["K1"][0], localPosition=[0.0, 0.0, 0.0])
    )
    pl.mbs.AddLoad(
        eii.LoadTorqueVector(
            markerNumber=rigid,
            loadVector=[0.0, 0.0, float(p["mom"])],
            visualization=eii.VLoadTorqueVector(show=False),
        )
    )
    return pl, names


def _a02_planar(n, phi0, speed):
    pl = _Planar()
    e = np.array([np.cos(phi0), np.sin(phi0)])
    v_top = speed * np.array([np.sin(phi0), -np.cos(phi0)])  # B_i at crank rate -speed
    g = (0.0, -standard.G)
    i12 = 1.0 / 12.0
    for i in range(n + 1):
        pl.body(f"crank{i}", 1.0, i12, (i + 0.5 * e[0], 0.5 * e[1]), phi0, 0.5 * v_top, -speed)
        pl.gravity(f"crank{i}", g)
        pl.revolute(None, f"crank{i}", (i, 0.0))
    for i in range(1, n + 1):
        b_prev, b_i = np.array([i - 1 + e[0], e[1]]), np.array([i + e[0], e[1]])
        pl.body(f"coupler{i}", 1.0, i12, 0.5 * (b_prev + b_i), 0.0, v_top, 0.0)
        pl.gravity(f"coupler{i}", g)
        pl.revolute(f"crank{i - 1}", f"coupler{i}", b_prev)
        pl.revolute(f"coupler{i}", f"crank{i}", b_i)
    return pl, ["crank0"]


def exudyn_squeezer() -> ExudynPeer:
    """Andrews' squeezer in Exudyn; observes the seven angles."""
    q0 = np.array(standard.SQUEEZER["q0"])
    return ExudynPeer(_squeezer_planar, lambda phi: q0 + squeezer_to_angles(phi))


def exudyn_a02(n: int = A02_N, phi0: float = np.pi / 2, speed: float = 1.0) -> ExudynPeer:
    """A02 in Exudyn (EigenSparse); observes B0 = (cos, sin) of crank 0's angle."""
    return ExudynPeer(
        lambda: _a02_planar(n, phi0, speed),
        lambda a: np.column_stack([np.cos(a[:, 0]), np.sin(a[:, 0])]),
        sparse=True,
    )


# -- work-precision hook ----------------------------------------------------------------------


def sweep_mujoco_rk4(problem, peer: MujocoPeer, steps, ref, repeats: int) -> list[dict]:
    """MuJoCo RK4 points (setting = step size h; constraint time constant 2 h)."""
    points = []
    for h in steps:
        point = {"setting": float(h), "steps": round(problem.t_end / h)}
        try:
            peer.set_step(h)
            data = peer.mujoco.MjData(peer.model)
            sec, reps, qpos = common.cpu_time(
                lambda d=data: peer.run(d, problem.t_end, problem.n_out), repeats
            )
            point.update(
                cpu_s=sec,
                repeats=reps,
                error=common.error(problem, peer.observe(qpos), ref),
                constraint_timeconst=TIMECONST_STEPS * float(h),
                max_position_residual=peer.loop_residual(qpos),
            )
        except RuntimeError as exc:
            point.update(failed=str(exc)[:200], error=float("nan"))
        points.append(point)
    return points


def sweep_exudyn(problem, peer: ExudynPeer, method: str, n_steps, ref, repeats: int) -> list[dict]:
    """Exudyn points (setting = step size t_end / n)."""
    points = []
    for n in n_steps:
        point = {"setting": problem.t_end / n, "steps": int(n)}
        try:
            solve = peer.runner(problem.t_end, problem.n_out, n, method)
            sec, reps, (obs, stats) = common.cpu_time(solve, repeats)
            point.update(
                cpu_s=sec,
                repeats=reps,
                error=common.error(problem, obs, ref),
                newton_iterations=stats["newton_iterations"],
                jacobians=stats["jacobians"],
            )
        except RuntimeError as exc:
            point.update(failed=str(exc)[:200], error=float("nan"))
        points.append(point)
    return points


def workprecision_curves(problem, ref, quick: bool, repeats: int) -> dict:
    """Curves for ``python -m benchmarks.workprecision squeezer`` and ``a02``: MuJoCo RK4 and Exudyn
    GeneralizedAlpha / TrapezoidalIndex2, each only if its package imports."""
    if problem.name == "squeezer":
        make_mj, make_exu = mujoco_squeezer, exudyn_squeezer
        mj_steps = SQUEEZER_MJ_QUICK if quick else SQUEEZER_MJ_STEPS
        exu_steps = SQUEEZER_EXU_QUICK if quick else SQUEEZER_EXU_STEPS
    elif problem.name == "a02":
        make_mj, make_exu = mujoco_a02, exudyn_a02
        mj_steps = A02_MJ_QUICK if quick else A02_MJ_STEPS
        exu_steps = A02_EXU_QUICK if quick else A02_EXU_STEPS
    else:
        raise ValueError(f"peer_closed_loops: no peer models of {problem.name!r}")
    curves = {}
    with contextlib.suppress(ImportError):
        import mujoco  # noqa: F401

        curves["MuJoCo rk4 (hinge tree + connect loops)"] = sweep_mujoco_rk4(
            problem, make_mj(), mj_steps, ref, repeats
        )
    with contextlib.suppress(ImportError):
        import exudyn  # noqa: F401

        peer = make_exu()
        for method in EXUDYN_METHODS:
            curves[f"Exudyn {method} (redundant coordinates)"] = sweep_exudyn(
                problem, peer, method, exu_steps, ref, repeats
            )
    if problem.name == "a02":
        with contextlib.suppress(ImportError):
            import pinocchio  # noqa: F401

            curves["SciPy DOP853 on Pinocchio (index 1, Baumgarte)"] = common.sweep_scipy(
                problem,
                "DOP853",
                A02_SCIPY_QUICK if quick else A02_SCIPY_RTOLS,
                ref,
                repeats,
                rhs=PinocchioA02().rhs(),
            )
    return curves


# -- SciPy on Pinocchio ----------------------------------------------------------------------


class PinocchioA02:
    """A02 as a SciPy user would write it on Pinocchio: the open tree of revolute-z joints
    (crank i at A_i = (i, 0) to the world, angle from +x; coupler i on crank i-1's tip B_{i-1},
    angle relative to that crank), the n loop closures as the in-plane rows of the point
    constraint coupler i tip = crank i tip, and the index-1 equations with Baumgarte
    stabilisation (the usual remedy for drift when the state is (q, v)):

        [M  J^T] [a     ]   [-h                               ]
        [J  0  ] [lambda] = [-(dJ/dt) v - 2 alpha J v - beta^2 g]

    M from ``pin.crba``, h from ``pin.nonLinearEffects``, J and (dJ/dt) v from Pinocchio's frame
    Jacobians and classical frame accelerations (``LOCAL_WORLD_ALIGNED``). 1 kg, 1 m uniform bars
    (in-plane inertia 1/12 about the centre), gravity -9.81 y. ``rhs()`` gives (f, y0) for
    ``solve_ivp``; y = (q, v). At the flat positions J loses n ranks, the KKT matrix becomes
    singular and the step size collapses: the measured curve records how far each run got."""

    def __init__(self, n: int = A02_N, speed: float = 1.0, baumgarte: float = 10.0):
        import pinocchio as pin

        self.pin, self.n, self.alpha = pin, n, baumgarte
        m = pin.Model()
        m.gravity = pin.Motion(np.array([0.0, -standard.G, 0.0]), np.zeros(3))
        bar = pin.Inertia(1.0, np.array([0.5, 0.0, 0.0]), np.diag([0.0, 1.0, 1.0]) / 12.0)
        # depth first (crank i, then coupler i + 1 on its tip): Pinocchio's CRBA needs every
        # subtree's velocity indices contiguous (with cranks first and couplers after, the
        # crank-coupler blocks of M come out zero)
        self.crank, self.coupler = [], []
        tip = pin.SE3(np.eye(3), np.array([1.0, 0.0, 0.0]))
        for i in range(n + 1):
            place = pin.SE3(np.eye(3), np.array([i, 0.0, 0.0]))
            j = m.addJoint(0, pin.JointModelRZ(), place, f"A{i}")
            m.appendBodyToJoint(j, bar, pin.SE3.Identity())
            self.crank.append(j)
            if i < n:
                j = m.addJoint(self.crank[i], pin.JointModelRZ(), tip, f"B{i}")
                m.appendBodyToJoint(j, bar, pin.SE3.Identity())
                self.coupler.append(j)
        self.frames = []
        for i in range(1, n + 1):
            a = m.addFrame(
                pin.Frame(f"coupler{i}_tip", self.coupler[i - 1], tip, pin.FrameType.OP_FRAME)
            )
            b = m.addFrame(pin.Frame(f"crank{i}_tip", self.crank[i], tip, pin.FrameType.OP_FRAME))
            self.frames.append((a, b))
        self.model, self.data = m, m.createData()
        nv = m.nv
        self.kkt = np.zeros((nv + 2 * n, nv + 2 * n))
        # velocity index of every crank and coupler (revolute joints: one each, v index = id - 1)
        self.crank_v = np.array([j - 1 for j in self.crank])
        self.coupler_v = np.array([j - 1 for j in self.coupler])
        self.y0 = np.concatenate(
            [self.joint_vector(np.pi / 2, -np.pi / 2), self.joint_vector(-speed, speed)]
        )

    def joint_vector(self, crank: float, coupler: float) -> np.ndarray:
        """A vector over Pinocchio's joints: one value on every crank, one on every coupler."""
        x = np.empty(self.model.nv)
        x[self.crank_v] = crank
        x[self.coupler_v] = coupler
        return x

    def accelerations(self, q, v):
        pin, m, d, n = self.pin, self.model, self.data, self.n
        nv = m.nv
        frame = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        M = mass_matrix(pin, m, d, q)
        h = pin.nonLinearEffects(m, d, q, v)
        pin.computeJointJacobians(m, d, q)
        pin.forwardKinematics(m, d, q, v, np.zeros(nv))
        pin.updateFramePlacements(m, d)
        K = self.kkt
        K[:nv, :nv] = M
        rhs = np.empty(nv + 2 * n)
        rhs[:nv] = -h
        for k, (a, b) in enumerate(self.frames):
            r = slice(nv + 2 * k, nv + 2 * k + 2)
            J = (pin.getFrameJacobian(m, d, a, frame) - pin.getFrameJacobian(m, d, b, frame))[:2]
            K[r, :nv] = J
            K[:nv, r] = J.T
            dJv = (
                pin.getFrameClassicalAcceleration(m, d, a, frame).linear
                - pin.getFrameClassicalAcceleration(m, d, b, frame).linear
            )[:2]
            g = (d.oMf[a].translation - d.oMf[b].translation)[:2]
            rhs[r] = -dJv - 2.0 * self.alpha * (J @ v) - self.alpha**2 * g
        return np.linalg.solve(K, rhs)[:nv]

    def rhs(self):
        nv = self.model.nv

        def f(_t, y):
            return np.concatenate([y[nv:], self.accelerations(y[:nv], y[nv:])])

        return f, self.y0.copy()


# -- checks -----------------------------------------------------------------------------------


def main() -> None:
    """The peer models against the references: initial accelerations and short sweeps."""
    from benchmarks import references

    f, y0 = references.squeezer_rhs()
    a_ref = f(0.0, y0)[7:]
    scale = np.abs(a_ref).max()
    mj = mujoco_squeezer()
    soft, hard = mj.accelerations()
    print("squeezer, accelerations at t = 0 against the reference (relative to max |q''|):")
    print(f"  MuJoCo qacc (soft constraints) {np.abs(soft - a_ref).max() / scale:.2e}")
    print(f"  MuJoCo terms, exact KKT        {np.abs(hard - a_ref).max() / scale:.2e}")
    ex = exudyn_squeezer()
    a_ex = squeezer_to_angles(ex.initial_accelerations())
    print(f"  Exudyn initial accelerations   {np.abs(a_ex - a_ref).max() / scale:.2e}")
    t_end, n_out = 0.03, 300
    ref = references.squeezer_angles(np.linspace(0.0, t_end, n_out + 1))
    print("squeezer, max angle error over 300 outputs [rad] and CPU [s] of one run:")
    for h in (1e-4, 2.5e-5, 6.25e-6):
        mj.set_step(h)
        data = mj.mujoco.MjData(mj.model)
        t0 = time.process_time()
        qpos = mj.run(data, t_end, n_out)
        cpu = time.process_time() - t0
        print(f"  MuJoCo rk4 h = {h:.3g}: {np.abs(mj.observe(qpos) - ref).max():.2e}  {cpu:.3f}")
    for method in EXUDYN_METHODS:
        for n in (1200, 4800):
            obs, cpu, _st = ex.trajectory(t_end, n_out, n, method)
            print(f"  Exudyn {method} n = {n}: {np.abs(obs - ref).max():.2e}  {cpu:.3f}")


if __name__ == "__main__":
    main()
