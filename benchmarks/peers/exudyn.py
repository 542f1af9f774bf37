"""Exudyn peer models of a serial (or tree) revolute arm loaded from a URDF, e.g. the UR5.

:class:`ExudynArm` (:func:`build_ur5_like`) is the model for the benchmark, built from the
Pinocchio model of the URDF (``pin.buildModelFromUrdf``) in Exudyn's *redundant* (absolute)
coordinates: one ``NodeRigidBodyEP`` (position + 4 Euler parameters, whose unit norm is an
algebraic equation) with an ``ObjectRigidBody`` per moving link. A body's reference frame is its
joint frame; it carries the link's mass, centre of mass and inertia about the centre of mass
(``pm.inertias[i]``) and gravity (0, 0, -9.81) as a mass-proportional load. Every revolute joint
is an ``ObjectJointRevoluteZ`` (five algebraic constraints with Lagrange multipliers) between two
``MarkerBodyRigid``: one on the parent at the joint placement ``pm.jointPlacements[i]`` and one
at the child's origin, both turned so that their z axis is the joint axis. The bodies start at
the world poses ``data.oMi[i]`` of q0 at rest, so the constraints hold exactly at t = 0.

Joint angles: the final angle comes from the bodies' rotation matrices,
R_rel = (R_parent X_i)^T R_child and q = atan2(a . vex(R_rel), (tr R_rel - 1) / 2) about the axis
a (Pinocchio's sign, checked against its ABA). Its multiple of 2 pi comes from Exudyn's joint
output ``Rotation`` (z component, the same angle but wrapped to (-pi, pi]), which sensors sample
during the run (every step by default) and which is unwrapped.

Solvers: with joint constraints and Euler parameters only Exudyn's implicit solvers work,
'GeneralizedAlpha' (index 3; spectral radius 0.9 by default) and 'TrapezoidalIndex2' (index 2). Both
are second order with fixed steps; Exudyn has no error control for implicit solvers. Its explicit
solvers (RK44, DOPRI5, ODE23, RK67, ...) refuse the model: "explicit integrator detected node ...
which contains algebraic variables" (Euler parameters), and with rotation-vector nodes "... object
... which contains constraints that cannot be solved" -- they only eliminate simple
CoordinateConstraints. So ``ExudynArm.run(..., 'RK4')`` and ``ExudynArm.run_tolerance`` raise
``NotImplementedError``.

For explicit Runge-Kutta in Exudyn, :class:`ExudynTreeArm` (:func:`build_ur5_like_tree`) is the
same arm as an ``ObjectKinematicTree``: *minimal* coordinates (the joint angles, no constraints),
so not the redundant-coordinate peer, but the only way Exudyn runs RK4 or DOPRI5 (with
``automaticStepSize`` and tolerances) on it.

``python -m benchmarks.peers.exudyn`` runs the convergence check against SciPy DOP853 (rtol
1e-13) on Pinocchio's ABA.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks import common

GRAVITY = (0.0, 0.0, -9.81)
IMPLICIT = ("GeneralizedAlpha", "TrapezoidalIndex2")
# Exudyn's explicit solvers; DOPRI5 and ODE23 have automatic step size control (DVERK6 is listed
# in exu.DynamicSolverType but "not implemented" in 1.13)
EXPLICIT = ("RK4", "RK44", "RK67", "RK33", "ExplicitMidpoint", "ExplicitEuler", "DOPRI5", "ODE23")
ADAPTIVE = ("DOPRI5", "ODE23")
_WHY_NOT_EXPLICIT = (
    "Exudyn's explicit solvers cannot integrate redundant-coordinate rigid bodies with joint "
    "constraints (Euler parameters are algebraic variables, revolute joints constraints that "
    "only its implicit solvers handle): use 'GeneralizedAlpha' or 'TrapezoidalIndex2', or the "
    "minimal-coordinate ExudynTreeArm (build_ur5_like_tree) for explicit methods"
)


def _exudyn():
    import exudyn as exu
    from exudyn import itemInterface as eii

    return exu, eii


def _joint_axis(joint) -> np.ndarray:
    """Unit revolute axis of a Pinocchio joint model in its joint frame."""
    name = joint.shortname()
    fixed = {"JointModelRX": (1.0, 0, 0), "JointModelRY": (0, 1.0, 0), "JointModelRZ": (0, 0, 1.0)}
    if name in fixed:
        return np.array(fixed[name], dtype=float)
    if name == "JointModelRevoluteUnaligned":
        a = np.array(joint.extract().axis, dtype=float)
        return a / np.linalg.norm(a)
    raise NotImplementedError(f"peer_exudyn: joint type {name} is not a (bounded) revolute joint")


def _frame_with_z(a: np.ndarray) -> np.ndarray:
    """A rotation matrix whose third column is the unit vector ``a`` (identity for e_z)."""
    if np.allclose(a, (0.0, 0.0, 1.0)):
        return np.eye(3)
    t = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(t, a)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(a, x), a])


def _angle_about(r: np.ndarray, a: np.ndarray) -> float:
    """Angle of a rotation matrix ``r`` that turns about the unit axis ``a``, in (-pi, pi]."""
    vex = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return float(np.arctan2(0.5 * a @ vex, 0.5 * (np.trace(r) - 1.0)))


def _base_settings(t_end: float, n_steps: int):
    exu = _exudyn()[0]
    ss = exu.SimulationSettings()
    ss.show.statistics = False  # = displayStatistics (deprecated name)
    ss.show.computationTime = False  # = displayComputationTime
    ss.solution.file.write = False  # = solutionSettings.writeSolutionToFile
    ss.timeIntegration.verboseMode = 0
    ss.timeIntegration.startTime = 0.0
    ss.timeIntegration.endTime = float(t_end)
    ss.timeIntegration.numberOfSteps = int(n_steps)
    ss.timeIntegration.adaptiveStep = False  # fixed steps: a failed Newton solve is an error
    ss.timeIntegration.automaticStepSize = False
    ss.linearSolver.solverType = exu.LinearSolverType.EXUdense
    return ss


def implicit_settings(
    t_end: float, n_steps: int, sample_dt: float, spectral_radius: float, newton_rtol: float
):
    """Settings of a fixed-step implicit run: sensors every ``sample_dt``, Newton relative
    tolerance ``newton_rtol`` (absolute 1e-2 of it), generalized-alpha ``spectral_radius``,
    consistent initial accelerations."""
    ss = _base_settings(t_end, n_steps)
    ss.solution.sensors.active = True
    ss.solution.sensors.writePeriod = sample_dt
    ss.timeIntegration.newton.relativeTolerance = newton_rtol
    ss.timeIntegration.newton.absoluteTolerance = 1e-2 * newton_rtol
    ss.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
    ss.timeIntegration.generalizedAlpha.computeInitialAccelerations = True
    return ss


def solve_checked(mbs, ss, method: str, t_end: float) -> dict:
    """exu.SolveDynamic to ``t_end``; returns the step statistics, or raises ``RuntimeError``
    with where and why Exudyn stopped (Exudyn's own console banners suppressed)."""
    exu = _exudyn()[0]
    solver_type = getattr(exu.DynamicSolverType, "RK44" if method == "RK4" else method)
    printing = exu.config.printToConsole
    exu.config.printToConsole = False
    try:
        ok = exu.SolveDynamic(mbs, ss, solverType=solver_type, storeSolver=True)
    except (exu.SolverError, RuntimeError):
        ok = False
    finally:
        exu.config.printToConsole = printing
    solver = mbs.sys["dynamicSolver"]
    t_reached = mbs.systemData.GetTime()
    if not ok or abs(t_reached - t_end) > 1e-9 * max(1.0, t_end):
        conv = solver.conv
        why = solver.GetErrorString() or "no reason given"
        if conv.linearSolverFailed or conv.massMatrixNotInvertible:
            why = f"singular system matrix ({why})"
        elif not conv.newtonConverged:
            # at fixed steps Exudyn reports the failed Newton as a failed step reduction
            why = f"Newton did not converge, residual {conv.lastResidual:.3g}"
        h = t_end / ss.timeIntegration.numberOfSteps
        raise RuntimeError(
            f"Exudyn {method} stopped at t = {t_reached:.4g} s (step "
            f"{int(solver.it.currentStepIndex)}, h = {h:.3g} s): {why}"
        )
    it = solver.it
    return {
        "steps": int(it.currentStepIndex) - 1,
        "rejected": int(it.rejectedAutomaticStepSizeSteps),
        "newton_iterations": int(it.newtonStepsCount),
        "jacobians": int(it.newtonJacobiCount),
    }


def _timed_solve(mbs, ss, method: str, t_end: float) -> tuple[float, dict]:
    """:func:`solve_checked` timed with process_time; returns (CPU s, step statistics)."""
    t0 = time.process_time()
    stats = solve_checked(mbs, ss, method, t_end)
    return time.process_time() - t0, stats


class ExudynArm:
    """Exudyn redundant-coordinate model (Euler-parameter rigid bodies, revolute joints as
    algebraic constraints) of a Pinocchio revolute arm released at rest from q0.

    Each :meth:`run` builds a fresh Exudyn system (not timed) and times only
    ``exu.SolveDynamic`` with ``time.process_time``; ``last_stats`` then holds the step counts.
    """

    def __init__(self, pm, q0, gravity=GRAVITY):
        import pinocchio as pin

        self.q0 = np.asarray(q0, dtype=float).copy()
        if pm.nq != pm.nv or self.q0.shape != (pm.nq,):
            raise ValueError("peer_exudyn: q0 must have one angle per revolute joint (nq == nv)")
        self.gravity = [float(g) for g in gravity]
        self.last_stats: dict = {}
        data = pm.createData()
        pin.forwardKinematics(pm, data, self.q0)
        self.links = []  # per moving joint, in Pinocchio order
        for i in range(1, pm.njoints):
            inertia = pm.inertias[i]
            placement = pm.jointPlacements[i]
            self.links.append(
                {
                    "joint": i,
                    "parent": int(pm.parents[i]),
                    "idx_q": int(pm.joints[i].idx_q),
                    "axis": _joint_axis(pm.joints[i]),
                    "mass": float(inertia.mass),
                    "com": np.array(inertia.lever, dtype=float),  # in the joint frame
                    "inertia_com": np.array(inertia.inertia, dtype=float),  # about the CoM
                    "xtree_p": np.array(placement.translation, dtype=float),
                    "xtree_r": np.array(placement.rotation, dtype=float),
                    "pos0": np.array(data.oMi[i].translation, dtype=float),
                    "rot0": np.array(data.oMi[i].rotation, dtype=float),
                }
            )

    def build(self):
        """A fresh, assembled Exudyn system of the arm at q0. Returns (SystemContainer,
        MainSystem, node per link, joint object per link, joint-rotation sensor per link)."""
        from exudyn.rigidBodyUtilities import RigidBodyInertia

        exu, eii = _exudyn()
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        ground = mbs.AddObject(eii.ObjectGround(visualization=eii.VObjectGround(show=False)))
        body_of = {0: ground}
        nodes, joints, sensors = [], [], []
        for link in self.links:
            inertia = RigidBodyInertia(
                mass=link["mass"],
                inertiaTensor=link["inertia_com"],
                com=link["com"],
                inertiaTensorAtCOM=True,
            )
            res = mbs.CreateRigidBody(
                inertia=inertia,
                referencePosition=link["pos0"],
                referenceRotationMatrix=link["rot0"],
                gravity=self.gravity,
                nodeType=exu.NodeType.RotationEulerParameters,
                show=False,
                returnDict=True,
            )
            body = res["bodyNumber"]
            body_of[link["joint"]] = body
            nodes.append(res["nodeNumber"])
            ra = _frame_with_z(link["axis"])  # joint frame -> marker frame (z = axis)
            m0 = mbs.AddMarker(
                eii.MarkerBodyRigid(
                    bodyNumber=body_of[link["parent"]],
                    localHT=exu.HT(rotation=link["xtree_r"] @ ra, translation=link["xtree_p"]),
                )
            )
            m1 = mbs.AddMarker(
                eii.MarkerBodyRigid(
                    bodyNumber=body, localHT=exu.HT(rotation=ra, translation=[0.0, 0.0, 0.0])
                )
            )
            j = mbs.AddObject(
                eii.ObjectJointRevoluteZ(
                    markerNumbers=[m0, m1], visualization=eii.VObjectJointRevoluteZ(show=False)
                )
            )
            joints.append(j)
            sensors.append(
                mbs.AddSensor(
                    eii.SensorObject(
                        objectNumber=j,
                        outputVariableType=exu.OutputVariableType.Rotation,
                        storeInternal=True,
                        writeToFile=False,
                        visualization=eii.VSensorObject(show=False),
                    )
                )
            )
        mbs.Assemble()
        return sc, mbs, nodes, joints, sensors

    def joint_angles_wrapped(self, mbs, nodes) -> np.ndarray:
        """Current joint angles in (-pi, pi], Pinocchio order, from the bodies' orientations."""
        exu = _exudyn()[0]
        rot = {0: np.eye(3)}
        for link, node in zip(self.links, nodes, strict=True):
            r = np.asarray(mbs.GetNodeOutput(node, exu.OutputVariableType.RotationMatrix))
            rot[link["joint"]] = r.reshape(3, 3)
        q = np.empty(len(self.links))
        for link in self.links:
            r_rel = (rot[link["parent"]] @ link["xtree_r"]).T @ rot[link["joint"]]
            q[link["idx_q"]] = _angle_about(r_rel, link["axis"])
        return q

    def _unwrapped_history(self, mbs, sensors):
        """Sample times and unwrapped joint angles (Pinocchio order) from the sensors, the
        first sample anchored at q0."""
        t, hist = None, None
        for link, s in zip(self.links, sensors, strict=True):
            d = np.asarray(mbs.GetSensorStoredData(s))
            if hist is None:
                t, hist = d[:, 0], np.empty((len(d), len(self.links)))
            c = np.unwrap(d[:, 3])
            c += 2 * np.pi * np.round((self.q0[link["idx_q"]] - c[0]) / (2 * np.pi))
            hist[:, link["idx_q"]] = c
        return t, hist

    def _solve(self, t_end, n_steps, method, spectral_radius, newton_rtol, sample_dt):
        if method in EXPLICIT or method == "DVERK6":
            raise NotImplementedError(f"peer_exudyn: method {method!r}: {_WHY_NOT_EXPLICIT}")
        if method not in IMPLICIT:
            raise ValueError(f"peer_exudyn: unknown method {method!r}; supported: {IMPLICIT}")
        _sc, mbs, nodes, _joints, sensors = self.build()
        dt = t_end / n_steps if sample_dt is None else sample_dt
        ss = implicit_settings(t_end, n_steps, dt, spectral_radius, newton_rtol)
        cpu, self.last_stats = _timed_solve(mbs, ss, method, t_end)
        return mbs, nodes, sensors, cpu

    def run(
        self,
        t_end: float,
        n_steps: int,
        method: str = "TrapezoidalIndex2",
        *,
        spectral_radius: float = 0.9,
        newton_rtol: float = 1e-10,
        sample_dt: float | None = None,
    ) -> tuple[np.ndarray, float]:
        """Simulate from q0 at rest for ``t_end`` with ``n_steps`` fixed steps of ``method``.

        ``method``: 'TrapezoidalIndex2' (index 2) or 'GeneralizedAlpha' (index 3, numerical
        damping ``spectral_radius``); both second order. Explicit methods ('RK4', 'DOPRI5',
        ...) raise ``NotImplementedError`` (Exudyn's explicit solvers reject the constraints).
        ``newton_rtol``: Newton relative tolerance (the absolute one is 1e-2 of it).
        ``sample_dt``: period of the joint-angle samples that only unwrap the angles (default
        every step; it must stay below pi / the largest joint speed).

        Returns (final joint angles in Pinocchio order, CPU seconds of ``exu.SolveDynamic``).
        """
        mbs, nodes, sensors, cpu = self._solve(
            t_end, n_steps, method, spectral_radius, newton_rtol, sample_dt
        )
        wrapped = self.joint_angles_wrapped(mbs, nodes)
        last = self._unwrapped_history(mbs, sensors)[1][-1]
        return wrapped + 2 * np.pi * np.round((last - wrapped) / (2 * np.pi)), cpu

    def trajectory(
        self,
        t_end: float,
        n_steps: int,
        n_out: int,
        method: str = "TrapezoidalIndex2",
        *,
        spectral_radius: float = 0.9,
        newton_rtol: float = 1e-10,
    ) -> tuple[np.ndarray, np.ndarray, float]:
        """Like :meth:`run`, with the unwrapped joint angles on ``n_out + 1`` equally spaced
        times (``n_steps`` a multiple of ``n_out``; the angles are sampled every step).
        Returns (times, angles (n_out + 1, nq) in Pinocchio order, CPU seconds of the solve)."""
        if n_steps % n_out:
            raise ValueError("peer_exudyn: n_steps must be a multiple of n_out")
        mbs, _nodes, sensors, cpu = self._solve(
            t_end, n_steps, method, spectral_radius, newton_rtol, None
        )
        t, hist = self._unwrapped_history(mbs, sensors)
        t_out = np.linspace(0.0, t_end, n_out + 1)
        h = t_end / n_steps
        idx = np.minimum(np.searchsorted(t, t_out - 0.5 * h), len(t) - 1)
        if np.abs(t[idx] - t_out).max() > 1e-3 * h:
            raise RuntimeError("peer_exudyn: the sensor samples miss output times")
        return t_out, hist[idx], cpu

    def run_tolerance(self, t_end: float, rtol: float, method: str = "DOPRI5"):
        """Error-controlled run: not available for this model. Exudyn's step size control
        (``timeIntegration.automaticStepSize`` with ``absoluteTolerance`` /
        ``relativeTolerance``) exists only in its explicit solvers (DOPRI5, ODE23), which
        cannot integrate the constrained redundant coordinates; its implicit solvers take fixed
        steps. Always raises ``NotImplementedError`` (see :meth:`ExudynTreeArm.run_tolerance`)."""
        raise NotImplementedError(
            f"peer_exudyn: run_tolerance({method!r}, rtol={rtol:g}): {_WHY_NOT_EXPLICIT}"
        )


class ExudynTreeArm(ExudynArm):
    """The same arm as one Exudyn ``ObjectKinematicTree``: *minimal* coordinates (the joint
    angles, Featherstone-type recursion, no constraints), so Exudyn's explicit solvers apply.
    Not the redundant-coordinate peer; for comparing Exudyn's RK4 and DOPRI5.

    Every joint becomes ``RevoluteZ`` in a frame turned so that z is the Pinocchio axis; the
    offsets, transformations, CoMs and inertias are expressed in those frames.
    """

    def build(self):
        """A fresh, assembled Exudyn system. Returns (SystemContainer, MainSystem, node)."""
        exu, eii = _exudyn()
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        ras = {0: np.eye(3)}
        rots, offsets = exu.Matrix3DList(), exu.Vector3DList()
        inertias, coms = exu.Matrix3DList(), exu.Vector3DList()
        order = {link["joint"]: k for k, link in enumerate(self.links)}
        for k, link in enumerate(self.links):
            if link["idx_q"] != k or (link["parent"] and order[link["parent"]] >= k):
                raise NotImplementedError("peer_exudyn: joints must be in Pinocchio q order")
            ra = ras[link["joint"]] = _frame_with_z(link["axis"])
            rp = ras[link["parent"]]
            rots.Append(rp.T @ link["xtree_r"] @ ra)
            offsets.Append(rp.T @ link["xtree_p"])
            inertias.Append(ra.T @ link["inertia_com"] @ ra)
            coms.Append(ra.T @ link["com"])
        n = len(self.links)
        node = mbs.AddNode(
            eii.NodeGenericODE2(
                referenceCoordinates=[0.0] * n,
                initialCoordinates=list(self.q0),
                initialCoordinates_t=[0.0] * n,
                numberOfODE2Coordinates=n,
            )
        )
        mbs.AddObject(
            eii.ObjectKinematicTree(
                nodeNumber=node,
                jointTypes=[exu.JointType.RevoluteZ] * n,
                linkParents=[link["parent"] - 1 for link in self.links],
                jointTransformations=rots,
                jointOffsets=offsets,
                linkInertiasCOM=inertias,
                linkCOMs=coms,
                linkMasses=[link["mass"] for link in self.links],
                gravity=self.gravity,
                visualization=eii.VObjectKinematicTree(show=False),
            )
        )
        mbs.Assemble()
        return sc, mbs, node

    def run(
        self,
        t_end: float,
        n_steps: int,
        method: str = "RK4",
        *,
        rtol: float = 1e-8,
        atol: float | None = None,
        spectral_radius: float = 0.9,
        newton_rtol: float = 1e-10,
    ) -> tuple[np.ndarray, float]:
        """Simulate from q0 at rest for ``t_end``.

        ``method``: 'RK4' (= Exudyn RK44), 'RK67', 'RK33', 'ExplicitMidpoint', 'ExplicitEuler'
        with ``n_steps`` fixed steps; 'DOPRI5' or 'ODE23' with automatic step size, tolerances
        ``rtol`` / ``atol`` (default ``rtol``), ``t_end / n_steps`` the initial and largest
        step; or 'GeneralizedAlpha' / 'TrapezoidalIndex2' (implicit, fixed steps). Explicit
        runs skip Exudyn's extra end-of-step acceleration evaluation (output only).

        Returns (final joint angles in Pinocchio order, CPU seconds of ``exu.SolveDynamic``).
        """
        exu = _exudyn()[0]
        if method not in EXPLICIT and method not in IMPLICIT:
            raise ValueError(f"peer_exudyn: unknown method {method!r}: {EXPLICIT + IMPLICIT}")
        _sc, mbs, node = self.build()
        ss = _base_settings(t_end, n_steps)
        ss.solution.sensors.active = False
        ss.timeIntegration.explicit.computeEndOfStepAccelerations = False
        if method in ADAPTIVE:
            ss.timeIntegration.automaticStepSize = True
            ss.timeIntegration.relativeTolerance = rtol
            ss.timeIntegration.absoluteTolerance = rtol if atol is None else atol
            ss.timeIntegration.initialStepSize = t_end / n_steps
            ss.timeIntegration.minimumStepSize = 1e-12 * t_end
        ss.timeIntegration.newton.relativeTolerance = newton_rtol
        ss.timeIntegration.newton.absoluteTolerance = 1e-2 * newton_rtol
        ss.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
        cpu, self.last_stats = _timed_solve(mbs, ss, method, t_end)
        q = np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates), dtype=float)
        if not np.all(np.isfinite(q)):
            raise RuntimeError(f"peer_exudyn: Exudyn {method} diverged ({n_steps} steps)")
        return q, cpu

    def run_tolerance(
        self,
        t_end: float,
        rtol: float,
        method: str = "DOPRI5",
        *,
        atol: float | None = None,
        max_steps_hint: int = 100,
    ) -> tuple[np.ndarray, float]:
        """Error-controlled run (Exudyn ``automaticStepSize``, ``relativeTolerance`` = rtol,
        ``absoluteTolerance`` = atol or rtol) with 'DOPRI5' or 'ODE23'; the initial and largest
        step is ``t_end / max_steps_hint``. Returns (final angles, CPU s of the solve)."""
        if method not in ADAPTIVE:
            raise ValueError(f"peer_exudyn: {method!r} has no step size control; use {ADAPTIVE}")
        return self.run(t_end, max_steps_hint, method, rtol=rtol, atol=atol)


def build_ur5_like(pm, q0) -> ExudynArm:
    """Exudyn redundant-coordinate model of any Pinocchio revolute-joint model (serial or tree;
    joints RX, RY, RZ or RevoluteUnaligned), released at rest from ``q0`` (Pinocchio order)."""
    return ExudynArm(pm, q0)


def build_ur5_like_tree(pm, q0) -> ExudynTreeArm:
    """The same arm as an Exudyn ``ObjectKinematicTree`` in minimal coordinates, for Exudyn's
    explicit solvers (RK4, DOPRI5 with tolerances)."""
    return ExudynTreeArm(pm, q0)


# -- work-precision hook ----------------------------------------------------------------------

WP_STEPS = (1000, 2000, 5000, 10000, 20000, 50000)
WP_STEPS_QUICK = (5000,)


def workprecision_curves(problem, ref, quick: bool, repeats: int) -> dict:
    """Curves for ``python -m benchmarks.workprecision ur5``: the redundant-coordinate Exudyn model
    with TrapezoidalIndex2 and GeneralizedAlpha (spectral radius 0.9) at fixed steps (setting = step
    size). Error: max wrapped |q - q_ref| over the problem's output grid; CPU: median over
    ``repeats`` of the ``exu.SolveDynamic`` time (one run when it takes more than 2 s)."""
    import pinocchio as pin

    pm = pin.buildModelFromUrdf(str(common.robot_urdf("ur5")))
    arm = build_ur5_like(pm, np.asarray(common.UR5_Q0))
    curves = {}
    for method in ("TrapezoidalIndex2", "GeneralizedAlpha"):
        points = []
        for n in WP_STEPS_QUICK if quick else WP_STEPS:
            point = {"setting": problem.t_end / n, "steps": n}
            try:
                cpus = []
                while len(cpus) < max(1, repeats) and not (cpus and cpus[0] > 2.0):
                    _t, q, cpu = arm.trajectory(problem.t_end, n, problem.n_out, method)
                    cpus.append(cpu)
                point.update(
                    cpu_s=float(np.median(cpus)),
                    repeats=len(cpus),
                    error=common.error(problem, q, ref),
                    newton_iterations=arm.last_stats["newton_iterations"],
                )
            except RuntimeError as exc:
                point.update(failed=str(exc)[:200], error=float("nan"))
            points.append(point)
        curves[f"Exudyn {method} (redundant coordinates)"] = points
    return curves


# -- verification -----------------------------------------------------------------------------


def _reference(pm, q0, t_end):
    import pinocchio as pin
    from scipy.integrate import solve_ivp

    pd = pm.createData()
    n = pm.nq

    def f(_t, y):
        return np.concatenate([y[n:], pin.aba(pm, pd, y[:n], y[n:], np.zeros(n))])

    y0 = np.concatenate([q0, np.zeros(n)])
    sol = solve_ivp(f, (0, t_end), y0, method="DOP853", rtol=1e-13, atol=1e-13)
    return sol.y[:n, -1]


def main() -> None:
    """Convergence of the Exudyn UR5 models to SciPy DOP853 (rtol 1e-13) on Pinocchio's ABA."""
    import exudyn as exu
    import pinocchio as pin

    path = common.robot_urdf("ur5")
    pm = pin.buildModelFromUrdf(str(path))
    q0 = np.array(common.UR5_Q0)
    t_end = 5.0
    ref = _reference(pm, q0, t_end)
    print(f"Exudyn {exu.__version__}, {path.name}, q0 = {q0.tolist()}, t_end = {t_end} s")
    print(f"reference q(t_end) = {np.array2string(ref, precision=6)}")
    print(f"{'model':10s} {'method':18s} {'steps / rtol':>12s} {'max |q-q_ref|':>14s}", end="")
    print(f" {'CPU [s]':>8s} {'steps':>7s} {'rejected':>8s}")

    def row(model, arm, method, setting, call):
        try:
            q, cpu = call()
            err = f"{np.abs(q - ref).max():14.3e}"
            st = arm.last_stats
            print(f"{model:10s} {method:18s} {setting:>12} {err} {cpu:8.3f}", end="")
            print(f" {st['steps']:7d} {st['rejected']:8d}")
        except (RuntimeError, NotImplementedError) as exc:
            print(f"{model:10s} {method:18s} {setting:>12} {str(exc)[:60]}")

    arm = build_ur5_like(pm, q0)
    for method in ("TrapezoidalIndex2", "GeneralizedAlpha"):
        for n in (5000, 10000, 20000, 50000, 100000):
            row("redundant", arm, method, n, lambda n=n, m=method: arm.run(t_end, n, m))
    for method in ("RK4", "DOPRI5"):
        row("redundant", arm, method, "-", lambda m=method: arm.run(t_end, 10000, m))
    tree = build_ur5_like_tree(pm, q0)
    for n in (5000, 10000, 20000, 50000):
        row("tree", tree, "RK4", n, lambda n=n: tree.run(t_end, n, "RK4"))
    for rtol in (1e-6, 1e-8, 1e-10):
        row("tree", tree, "DOPRI5", f"{rtol:g}", lambda r=rtol: tree.run_tolerance(t_end, r))


if __name__ == "__main__":
    main()
