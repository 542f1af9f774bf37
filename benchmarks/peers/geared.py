"""MuJoCo and Exudyn peer models of the backlash-free geared arm (``geared_arm_6dof(backlash=0)``,
44 bodies, six PD motors behind two-stage gear trains), for
``python -m benchmarks.workprecision geared_arm``.

Both peers are minimal-coordinate models of the same open tree as the reference
(:class:`benchmarks.references.GearedArmReference`): the 18 revolute joints (six arm joints, six
intermediate shafts, six rotors) of the Pinocchio model
:func:`benchmarks.peers.pinocchio.pinocchio_tree`
builds from the scene's bodies, each Pinocchio joint carrying the composite inertia of the bodies
welded to it. The twelve gear meshes are constraints between joint coordinates, from the scene's
pitch radii (:data:`armdyn.papers.geared_arm.JOINTS`): q_motor = -(R1/r1) q_shaft and
q_shaft = -(R2/r2) q_joint. The motors are the scene's PD law on the rotor angles,
clamp(kp (N ref(t) - q_m) + kd (N ref'(t) - q_m'), +-limit), with the quintic references.

MuJoCo (:class:`MujocoGeared`)
    Each Pinocchio joint is a ``<body>`` at its joint placement (``pos``, ``quat``) with a
    ``hinge`` about z and an ``<inertial>`` (mass, centre of mass, ``fullinertia``) from
    ``pm.inertias``; no geoms, contacts off. Each gear mesh is an ``<equality><joint>`` with
    ``polycoef`` = (0, ratio, 0, 0, 0), softened like the closed-loop peers
    (:mod:`benchmarks.peers.closed_loops`: ``solimp`` 0.9999 everywhere, ``solref`` = (2 h,
    1)). Each motor is a ``<general>`` actuator on its rotor with gain 1 and affine bias
    (0, -kp, -kd), ``forcerange`` +-limit: force = ctrl - kp q - kd q' clamped, so the PD law is
    evaluated by MuJoCo at every RK4 stage with the stage's state; only the time-dependent part
    ctrl = kp N ref(t) + kd N ref'(t) comes from outside. ``control="midpoint"`` (the peer's
    curve) sets ctrl before each step to its value at the step's midpoint t + h/2 and holds it
    over the step (a midpoint rule: O(h^2), the order of the soft constraints' error);
    ``control="stage"`` sets it at every stage's own time from a ``mjcb_control`` callback (exact,
    but a Python call per stage). ``python -m benchmarks.peers.geared`` runs both at the same
    steps.
    Solver: RK4 at fixed steps. The explicit step is bounded by the motors' damping on the
    light rotors (about 5400 1/s, as for armdyn's explicit methods): RK4 is stable up to
    h ~ 2.8 / 5400 ~ 5e-4 s.

Exudyn (:class:`ExudynGeared`)
    One ``ObjectKinematicTree`` (minimal coordinates,
    :class:`benchmarks.peers.exudyn.ExudynTreeArm`) with the 18 joints, each gear mesh an
    ``ObjectConnectorCoordinate`` (``factor1`` = ratio) between two ``MarkerNodeCoordinate`` of the
    tree's node, and the motor law the tree's ``forceUserFunction`` (a Python function of t, q, q'
    called at every evaluation). A redundant-coordinate model (rigid bodies with Euler parameters,
    as the UR5 and closed-loop peers) is not available here: Exudyn has no gear element between
    rigid bodies, and a gear couples *relative* joint angles, which are not coordinates of such a
    model. Exudyn's explicit solvers refuse the coordinate constraints ("explicit integrator
    detected CoordinateConstraint object ... that does not have one ground node"), so the curves are
    its implicit 'GeneralizedAlpha' (spectral radius 0.9) and 'TrapezoidalIndex2' at fixed steps,
    Newton relative tolerance 1e-10, as for the other Exudyn peers.

The torque limit (10 N m) is never reached on this run (the largest PD torque is below 4 N m), so
clamping it is part of each model but inactive. The angle error is not wrapped in the peers'
PD laws (the reference wraps it): it stays far below pi.

Checks (tests/peers/test_peer_geared.py): MuJoCo's hard-constraint accelerations (``mj_fullM``,
``qfrc_smooth``, ``efc_J``; the joint equalities have a constant Jacobian, so the KKT solve is
exact at any velocity) and Exudyn's own initial-acceleration solve, at a moving state during the
motion, equal the reference's gear-reduced Pinocchio accelerations; and the errors of both fall
with the step.

CPU time: the median of warm repeats (:func:`benchmarks.common.cpu_time`) of the stepping alone, the
Python loop that sets ctrl (MuJoCo) and the force user function (Exudyn) included, since they are
part of running these models. Building and compiling the models is not timed.
"""

from __future__ import annotations

import contextlib

import numpy as np
from armdyn.papers.geared_arm import JOINTS

from benchmarks import common
from benchmarks.peers.closed_loops import (
    NEWTON_RTOL,
    SOLIMP,
    SPECTRAL_RADIUS,
    TIMECONST_STEPS,
    MujocoPeer,
    sweep_exudyn,
    sweep_mujoco_rk4,
)
from benchmarks.peers.exudyn import _exudyn, implicit_settings, solve_checked
from benchmarks.references import GearedArmReference, _quintic

ARM = tuple(j[0] for j in JOINTS)
CONTROLS = ("midpoint", "stage")
EXUDYN_METHODS = ("GeneralizedAlpha", "TrapezoidalIndex2")

# work-precision sweeps: MuJoCo step sizes (the output spacing 0.05 s over an integer), Exudyn
# numbers of steps; 5e-4 s is at RK4's stability edge
MJ_STEPS = tuple(0.05 / k for k in (100, 110, 125, 250, 500, 1000))
MJ_QUICK = (4e-4,)
EXU_STEPS = (500, 1000, 2000, 4000, 8000)
EXU_QUICK = (1000,)


def _f(x) -> str:
    return repr(float(x))


def _vec(v) -> str:
    return " ".join(_f(x) for x in v)


def gear_couplings():
    """(driven coordinate, driving coordinate, ratio) for every mesh: q_a = ratio q_b."""
    out = []
    for name, _p, _a, _pt, R2, r2, R1, r1, _e in JOINTS:
        out.append((f"{name}_motor", f"{name}_shaft", -R1 / r1))
        out.append((f"{name}_shaft", name, -R2 / r2))
    return out


class _Motors:
    """The scene's PD motor law on the six rotors (in JOINTS order)."""

    def __init__(self, ref):
        s = ref.scene
        self.kp, self.kd, self.limit = float(s["kp"]), float(s["kd"]), float(s["torque_limit"])
        self.t0, self.t1 = float(s["t_start"]), float(s["t_end"])
        self.goal = ref.ratio * np.asarray(s["targets"], dtype=float)  # rotor angles reached

    def reference(self, t: float):
        """Rotor reference angles and rates at t (the quintic rest-to-rest profile)."""
        return _quintic(t, self.goal, self.t0, self.t1)

    def feedforward(self, t: float) -> np.ndarray:
        """The time-dependent part of the PD torque: kp ref(t) + kd ref'(t)."""
        ref, rate = self.reference(t)
        return self.kp * ref + self.kd * rate

    def torques(self, t: float, q_motor, qd_motor) -> np.ndarray:
        ref, rate = self.reference(t)
        u = self.kp * (ref - q_motor) + self.kd * (rate - qd_motor)
        return np.clip(u, -self.limit, self.limit)


def _reference() -> GearedArmReference:
    return GearedArmReference()


# -- MuJoCo -----------------------------------------------------------------------------------


def geared_mjcf(ref, h: float = 1e-4) -> str:
    """MJCF of the geared arm's open tree (``ref``: a GearedArmReference), gear equalities and
    PD actuators; RK4 at step ``h``, equality time constant 2 h."""
    import pinocchio as pin

    pm = ref.pm
    children: dict[int, list[int]] = {}
    for j in range(1, pm.njoints):
        children.setdefault(int(pm.parents[j]), []).append(j)

    def body(j: int) -> str:
        place, inertia = pm.jointPlacements[j], pm.inertias[j]
        quat = pin.Quaternion(place.rotation)
        c = np.asarray(inertia.inertia)
        full = (c[0, 0], c[1, 1], c[2, 2], c[0, 1], c[0, 2], c[1, 2])
        inner = "".join(body(k) for k in children.get(j, []))
        return (
            f'<body name="{pm.names[j]}" pos="{_vec(place.translation)}" '
            f'quat="{_vec((quat.w, quat.x, quat.y, quat.z))}">'
            f'<joint name="{pm.names[j]}" type="hinge" axis="0 0 1"/>'
            f'<inertial pos="{_vec(inertia.lever)}" mass="{_f(inertia.mass)}" '
            f'fullinertia="{_vec(full)}"/>{inner}</body>'
        )

    s = ref.scene
    imp = _vec(SOLIMP)
    eqs = "".join(
        f'<joint joint1="{a}" joint2="{b}" polycoef="0 {_f(k)} 0 0 0" '
        f'solref="{_f(TIMECONST_STEPS * h)} 1" solimp="{imp}"/>'
        for a, b, k in gear_couplings()
    )
    lim = float(s["torque_limit"])
    acts = "".join(
        f'<general name="{name}_pd" joint="{name}_motor" gainprm="1" biastype="affine" '
        f'biasprm="0 {_f(-s["kp"])} {_f(-s["kd"])}" forcelimited="true" '
        f'forcerange="{_f(-lim)} {_f(lim)}"/>'
        for name in ARM
    )
    return (
        '<mujoco model="geared_arm"><compiler angle="radian" balanceinertia="false"/>'
        f'<option timestep="{_f(h)}" integrator="RK4" '
        f'gravity="{_vec(pm.gravity.linear)}"><flag contact="disable"/></option>'
        f"<worldbody>{''.join(body(k) for k in children.get(0, []))}</worldbody>"
        f"<equality>{eqs}</equality><actuator>{acts}</actuator></mujoco>"
    )


class MujocoGeared(MujocoPeer):
    """The geared arm in MuJoCo (module docstring); observes the six arm joint angles.

    ``control``: "midpoint" (ctrl held over each step at its midpoint value) or "stage" (set at
    every RK4 stage by a ``mjcb_control`` callback)."""

    def __init__(self, ref=None, control: str = "midpoint"):
        if control not in CONTROLS:
            raise ValueError(f"peer_geared: control must be one of {CONTROLS}, got {control!r}")
        self.ref = _reference() if ref is None else ref
        self.motors = _Motors(self.ref)
        self.control = control
        super().__init__(geared_mjcf(self.ref), ARM, lambda q: q)
        names = list(self.ref.tree.coord_names)
        self.coord_qpos = np.array(
            [self.model.joint(n).qposadr[0] for n in names], dtype=int
        )  # armdyn coordinate k -> qpos index
        self.coord_dof = np.array([self.model.joint(n).dofadr[0] for n in names], dtype=int)

    def _stage_callback(self, _model, data):
        data.ctrl[:] = self.motors.feedforward(data.time)

    def run(self, data, t_end: float, n_out: int) -> np.ndarray:
        """RK4 from rest at t = 0 to ``t_end``; qpos on ``n_out + 1`` equally spaced times.
        Raises ``RuntimeError`` if MuJoCo found the accelerations blowing up."""
        mujoco, model = self.mujoco, self.model
        h = model.opt.timestep
        per = round(t_end / n_out / h)
        if per < 1 or abs(per * h * n_out - t_end) > 1e-9 * t_end:
            raise ValueError(f"peer_geared: step {h:g} does not divide the output spacing")
        self.reset(data)
        qpos = np.empty((n_out + 1, model.nq))
        qpos[0] = data.qpos
        if self.control == "stage":
            mujoco.set_mjcb_control(self._stage_callback)
        try:
            ff, step = self.motors.feedforward, mujoco.mj_step
            for k in range(n_out):
                if self.control == "stage":
                    step(model, data, nstep=per)
                else:
                    for _ in range(per):
                        data.ctrl[:] = ff(data.time + 0.5 * h)
                        step(model, data)
                qpos[k + 1] = data.qpos
        finally:
            if self.control == "stage":
                mujoco.set_mjcb_control(None)
        bad = data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number
        if bad or not np.all(np.isfinite(qpos)):
            raise RuntimeError(
                f"MuJoCo RK4 unstable at h = {h:g}: NaN/huge qacc ({bad} resets of the state)"
            )
        return qpos

    def accelerations_at(self, t: float, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """At time t and the tree state (q, qd) in armdyn's coordinate order: MuJoCo's own
        (soft) ``qacc`` and the hard-constraint accelerations from MuJoCo's terms,
        [M J^T; J 0] [a; -f] = [qfrc_smooth; 0] (exact at any velocity: the gear equalities'
        Jacobian J is constant). Both in armdyn's coordinate order."""
        mujoco, model = self.mujoco, self.model
        data = mujoco.MjData(model)
        data.time = float(t)
        data.qpos[self.coord_qpos] = q
        data.qvel[self.coord_dof] = qd
        data.ctrl[:] = self.motors.feedforward(t)
        jacobian = model.opt.jacobian
        model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
        try:
            mujoco.mj_forward(model, data)
        finally:
            model.opt.jacobian = jacobian
        nv = model.nv
        m = np.zeros((nv, nv))
        mujoco.mj_fullM(model, data, m)
        jac = np.asarray(data.efc_J).reshape(-1, nv)
        kkt = np.block([[m, jac.T], [jac, np.zeros((len(jac), len(jac)))]])
        hard = np.linalg.solve(kkt, np.concatenate([data.qfrc_smooth, np.zeros(len(jac))]))
        return data.qacc[self.coord_dof].copy(), hard[:nv][self.coord_dof]


# -- Exudyn -----------------------------------------------------------------------------------


class ExudynGeared:
    """The geared arm as an Exudyn ``ObjectKinematicTree`` with coordinate constraints for the
    gears and the motor law as its force user function (module docstring)."""

    def __init__(self, ref=None):
        from benchmarks.peers.exudyn import ExudynTreeArm

        self.ref = _reference() if ref is None else ref
        self.motors = _Motors(self.ref)
        pm = self.ref.pm
        self.tree = ExudynTreeArm(pm, np.zeros(pm.nq), gravity=pm.gravity.linear)
        self.names = [pm.names[j] for j in range(1, pm.njoints)]  # node coordinate order
        if [int(pm.joints[j].idx_q) for j in range(1, pm.njoints)] != list(range(pm.nq)):
            raise NotImplementedError("peer_geared: Pinocchio joints are not in q order")
        self.motor_index = np.array([self.names.index(f"{n}_motor") for n in ARM], dtype=int)
        self.arm_index = np.array([self.names.index(n) for n in ARM], dtype=int)
        # armdyn coordinate k -> node coordinate
        self.coord_index = np.array(
            [self.names.index(n) for n in self.ref.tree.coord_names], dtype=int
        )

    def system(self, q=None, qd=None):
        """A fresh assembled system (tree, gears, motors), optionally starting from the tree
        state (q, qd) in armdyn's coordinate order (the start time is the solver settings').
        Returns (SystemContainer, MainSystem, node)."""
        eii = _exudyn()[1]
        sc, mbs, node = self.tree.build()
        for a, b, k in gear_couplings():
            ma, mb = (
                mbs.AddMarker(
                    eii.MarkerNodeCoordinate(nodeNumber=node, coordinate=self.names.index(c))
                )
                for c in (a, b)
            )
            mbs.AddObject(
                eii.ObjectConnectorCoordinate(
                    markerNumbers=[ma, mb],
                    factor1=float(k),
                    visualization=eii.VObjectConnectorCoordinate(show=False),
                )
            )
        n, motor, law = len(self.names), self.motor_index, self.motors.torques

        def force(_mbs, t, _item, q_node, qd_node):
            f = np.zeros(n)
            f[motor] = law(t, np.asarray(q_node)[motor], np.asarray(qd_node)[motor])
            return f

        mbs.SetObjectParameter(0, "forceUserFunction", force)
        if q is not None:
            q0, v0 = np.zeros(n), np.zeros(n)
            q0[self.coord_index], v0[self.coord_index] = q, qd
            mbs.SetNodeParameter(node, "initialCoordinates", list(q0))
            mbs.SetNodeParameter(node, "initialCoordinates_t", list(v0))
        mbs.Assemble()
        return sc, mbs, node

    def initial_accelerations(self, t: float, q, qd) -> np.ndarray:
        """Exudyn's own initial-acceleration solve (``computeInitialAccelerations``) at time t
        from the tree state (q, qd); the accelerations in armdyn's coordinate order."""
        exu = _exudyn()[0]
        _sc, mbs, node = self.system(q, qd)
        ss = implicit_settings(t + 1.0, 1, 1.0, SPECTRAL_RADIUS, NEWTON_RTOL)
        ss.timeIntegration.startTime = float(t)
        solver = exu.MainSolverImplicitSecondOrder()
        solver.InitializeSolver(mbs, ss)
        acc = np.asarray(mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates_tt))
        solver.FinalizeSolver(mbs, ss)
        return acc[self.coord_index]

    def runner(self, t_end: float, n_out: int, n_steps: int, method: str):
        """A function that solves once more from rest at t = 0 on the same assembled system and
        returns (the six arm angles on the ``n_out + 1`` output times, step statistics)."""
        exu, eii = _exudyn()
        if method not in EXUDYN_METHODS:
            raise ValueError(f"peer_geared: Exudyn method {method!r} not in {EXUDYN_METHODS}")
        if n_steps % n_out:
            raise ValueError("peer_geared: n_steps must be a multiple of n_out")
        _sc, mbs, node = self.system()
        sensor = mbs.AddSensor(
            eii.SensorNode(
                nodeNumber=node,
                outputVariableType=exu.OutputVariableType.Coordinates,
                storeInternal=True,
                writeToFile=False,
                visualization=eii.VSensorNode(show=False),
            )
        )
        mbs.Assemble()
        ss = implicit_settings(t_end, n_steps, t_end / n_out, SPECTRAL_RADIUS, NEWTON_RTOL)
        t_out = np.linspace(0.0, t_end, n_out + 1)
        h = t_end / n_steps

        def solve():
            stats = solve_checked(mbs, ss, method, t_end)
            data = np.asarray(mbs.GetSensorStoredData(sensor))
            if len(data) != n_out + 1 or np.abs(data[:, 0] - t_out).max() > 1e-6 * h:
                raise RuntimeError("peer_geared: Exudyn's sensor samples miss output times")
            return data[:, 1:][:, self.arm_index], stats

        return solve


# -- work-precision hook ----------------------------------------------------------------------


def workprecision_curves(problem, ref, quick: bool, repeats: int) -> dict:
    """Curves for ``python -m benchmarks.workprecision geared_arm``: MuJoCo RK4 (midpoint
    control) and Exudyn GeneralizedAlpha / TrapezoidalIndex2, each only if its package imports."""
    curves = {}
    reference = None
    with contextlib.suppress(ImportError):
        import mujoco  # noqa: F401

        peer = MujocoGeared()
        reference = peer.ref
        curves["MuJoCo rk4 (hinge tree + joint-equality gears)"] = sweep_mujoco_rk4(
            problem, peer, MJ_QUICK if quick else MJ_STEPS, ref, repeats
        )
    with contextlib.suppress(ImportError):
        import exudyn  # noqa: F401

        peer = ExudynGeared(reference)
        for method in EXUDYN_METHODS:
            curves[f"Exudyn {method} (kinematic tree + coordinate-constraint gears)"] = (
                sweep_exudyn(problem, peer, method, EXU_QUICK if quick else EXU_STEPS, ref, repeats)
            )
    return curves


def moving_state(ref, t: float = 1.7, seed: int = 3):
    """(p, p', t): the reference's arm state at t during the motion, perturbed by up to 0.01
    rad and 0.05 rad/s (the rotor errors stay far below pi, where the reference's wrapped PD
    error and the peers' plain one agree)."""
    from scipy.integrate import solve_ivp

    f, y0 = ref.rhs()
    # stiff (the rotors' damping): Radau takes far fewer evaluations than DOP853 here
    y = solve_ivp(f, (0.0, t), y0, method="Radau", rtol=1e-8, atol=1e-8).y[:, -1]
    rng = np.random.default_rng(seed)
    return y[:6] + rng.uniform(-0.01, 0.01, 6), y[6:] + rng.uniform(-0.05, 0.05, 6), t


def main() -> None:
    """Checks against the reference and a short convergence table (both MuJoCo controls)."""
    import time

    ref = _reference()
    p, pd, t = moving_state(ref)
    q, qd = ref.T @ p, ref.T @ pd
    f, _y0 = ref.rhs()
    pdd = f(t, np.concatenate([p, pd]))[6:]
    expect = ref.T @ pdd
    mj = MujocoGeared(ref)
    soft, hard = mj.accelerations_at(t, q, qd)
    exu_acc = ExudynGeared(ref).initial_accelerations(t, q, qd)
    scale = np.abs(expect).max()
    for what, acc in (
        ("MuJoCo hard-constraint accelerations", hard),
        ("MuJoCo soft qacc", soft),
        ("Exudyn initial accelerations", exu_acc),
    ):
        print(f"{what + ' vs reference:':52s}{np.abs(acc - expect).max() / scale:.2e}")
    t_end, n_out = 5.0, 100  # the geared_arm problem's run and output grid
    t_out = np.linspace(0.0, t_end, n_out + 1)
    angles = ref.angles(t_out)
    for control in CONTROLS:
        peer = MujocoGeared(ref, control)
        for h in (4e-4, 2e-4):
            peer.set_step(h)
            data = peer.mujoco.MjData(peer.model)
            t0 = time.process_time()
            qpos = peer.run(data, t_end, n_out)
            cpu = time.process_time() - t0
            err = common.max_error(peer.observe(qpos), angles, angular=True)
            print(f"MuJoCo rk4 control={control:8s} h = {h:.1e}: error {err:.2e}, CPU {cpu:.2f} s")


if __name__ == "__main__":
    main()
