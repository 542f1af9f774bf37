"""Error against run time (work–precision) on standard problems, with peers on the same axes.

``python -m benchmarks.workprecision [PROBLEM ...] [--quick] [--no-peers] [--out DIR]`` (from the
repository root) or :func:`run`. For each problem and integrator the tolerance (DOPRI5, TR-BDF2)
or step (RK4, MuJoCo) is swept; each point records the error against an independent reference
(:mod:`benchmarks.references`, derived by a different method
in minimal coordinates), the CPU time of the whole solve (median of warm repeats, one warm-up
run first) and the counters (steps, right-hand sides, KKT solves, factorisations). On trees
(the UR5, the geared arm) armdyn's integrators also run on ``simulate(coordinates="joint")``,
the joint-space path (curves "armdyn <integrator> (joint)"). armdyn's curves are
:func:`armdyn.work_precision`, the function a user runs on their own model, given the problem's
reference, observed quantity and error measure. Peers run the same problem in the
same process:

- SciPy ``solve_ivp`` (DOP853, RK45) on the minimal-coordinate equations of the reference
  (for the UR5: on Pinocchio's ABA);
- MuJoCo (RK4 and implicit Euler at fixed steps, ``mj_step`` looping in C between outputs)
  where the problem is a tree (A01; the UR5 through MuJoCo's own URDF import);
- Exudyn (generalized-alpha, fixed steps) on a redundant-coordinate model of the UR5
  (:mod:`benchmarks.peers.exudyn`; Exudyn's explicit solvers do not take its joint constraints);
- MuJoCo (RK4, stiff ``connect`` loop closures) and Exudyn (redundant coordinates) models of the
  closed-loop squeezer and A02 (:mod:`benchmarks.peers.closed_loops`), and of the geared arm
  (:mod:`benchmarks.peers.geared`).

Errors are measured as in the IFToMM benchmark: the largest absolute deviation over the output
grid of the problem's reference quantity (positions of a point [m], or angles [rad]).
Protocol: ``../shared/design/methods.md`` §8 (Hairer–Wanner work–precision diagrams).
Results: ``benchmarks/results/workprecision/`` (JSON and a plot per problem, and a README.md
summary of every problem's JSON in the folder).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from armdyn import _core, work_precision
from armdyn.papers import five_dof
from armdyn.papers.geared_arm import geared_arm_6dof
from armdyn.papers.reproduce import efforts_in_coord_order
from armdyn.scenes import standard

from benchmarks import common, references
from benchmarks.common import error, output_times, sweep_scipy
from benchmarks.peers.mujoco import mujoco_from_urdf
from benchmarks.peers.pinocchio import PinPair


def _quat_angle_z(u: np.ndarray, body: int) -> np.ndarray:
    """Rotation angle about world z of a body that only turns about z (from its quaternion)."""
    e = u[:, 7 * body + 3 : 7 * body + 7]
    return 2.0 * np.arctan2(e[:, 3], e[:, 0])


@dataclass
class Problem:
    name: str
    title: str
    source: str
    t_end: float
    n_out: int  # output intervals
    quantity: str  # what the error measures
    build: Callable
    observe: Callable  # (model, SimulationResult) -> (n_out + 1, k)
    reference: Callable  # t -> (n, k)
    angular: bool = False  # errors of angles are wrapped
    init: Callable | None = None  # model -> simulate kwargs
    sweeps: dict = field(default_factory=dict)
    quick_sweeps: dict = field(default_factory=dict)
    # the same integrators on simulate(coordinates="joint") (trees without drives, gears
    # allowed): curves "armdyn <integrator> (joint)"
    joint_sweeps: dict = field(default_factory=dict)
    quick_joint_sweeps: dict = field(default_factory=dict)
    required: tuple | None = None  # (low, high) precision of the benchmark
    scipy_rhs: Callable | None = None  # () -> (f, y0)
    scipy_observe: Callable | None = None  # y (k, n) -> (n, kq)
    mujoco_xml: str | None = None
    mujoco_model: Callable | None = None  # () -> (MjModel, qpos0) instead of mujoco_xml
    mujoco_observe: Callable | None = None  # qpos (n, nq) -> (n, kq)
    scipy_label: str = "minimal coordinates"
    # further peers: (problem, ref, quick, repeats) -> {curve name: points}
    more_peers: Callable | None = None
    # (reference on the output times) -> {name: value}: the reference against published values
    # or a second method, recorded with the curves
    reference_check: Callable | None = None
    scipy_rtols: tuple | None = None  # the SciPy sweep (default SCIPY_RTOLS)
    # why the SciPy curves are not a peer (they integrate the reference's own reduced equations,
    # which presume the motion); None: they are a peer
    scipy_not_peer: str | None = None


def _a01_observe(_model, res):
    return res.u[:, :2]


def _a02_observe(model, res):
    # B0 is the top of crank 0, whose body x axis is the crank's direction (world angle)
    phi = _quat_angle_z(res.u, model.body_names.index("crank0"))
    return np.column_stack([np.cos(phi), np.sin(phi)])


def _squeezer_observe(model, res):
    q0 = np.array(standard.SQUEEZER["q0"])
    a = np.column_stack(
        [_quat_angle_z(res.u, model.body_names.index(f"K{k}")) for k in range(1, 8)]
    )
    rel = np.column_stack(
        [
            a[:, 0],
            a[:, 1] - a[:, 0],
            a[:, 2],
            a[:, 3] - a[:, 4],
            a[:, 4],
            a[:, 5] - a[:, 6],
            a[:, 6],
        ]
    )
    return q0 + rel


def _five_dof_reference(t):
    """The complete Euler–Lagrange torques (:class:`armdyn.LagrangeValidator`, derived by
    automatic differentiation, independent of the Newton–Euler solver) on the prescribed
    rest-to-rest cubics q(t) = q1 (3 s² − 2 s³), s = t / T."""
    from armdyn.validation import LagrangeValidator

    a = five_dof.ARM5
    t = np.asarray(t, dtype=float)
    ends = np.array([a.target_deg * five_dof.DEG] * 4 + [a.stroke])
    s = t / a.duration
    q = np.outer(3 * s**2 - 2 * s**3, ends)
    qd = np.outer((6 * s - 6 * s**2) / a.duration, ends)
    qdd = np.outer((6 - 12 * s) / a.duration**2, ends)
    # the acceleration jumps at the start and at the end; armdyn's profiles take the value of
    # the rest outside (0, T) there
    qdd[(s <= 0.0) | (s >= 1.0)] = 0.0
    return LagrangeValidator(five_dof.five_dof_arm()).torques(q, qd, qdd, t)


def _a01_check(ref):
    """The closed form against a second method: SciPy DOP853 at rtol 1e-13 on θ'' = -g sin θ."""
    from scipy.integrate import solve_ivp

    f, y0 = references.a01_rhs()
    t = np.linspace(0.0, 2000.0, len(ref))
    y = solve_ivp(f, (0, t[-1]), y0, method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t).y[0]
    pts = np.column_stack([np.sin(y), -np.cos(y)])
    return {"closed_form_vs_dop853_1e-13_m": float(np.abs(pts - ref).max())}


def _squeezer_check(ref):
    d = common.wrap(ref[-1] - references.ANDREWS_TEST_SET_T003)
    return {"reference_vs_test_set_at_0.03_rad": float(np.abs(d).max())}


class _BuiltOnce:
    """A problem's models and references, built on first use and then shared."""

    _cache = None

    @classmethod
    def get(cls):
        if cls._cache is None:
            cls._cache = cls()
        return cls._cache


class _Ur5(_BuiltOnce):
    """The UR5 of example-robot-data in armdyn, Pinocchio and MuJoCo, with the maps between their
    joint orders."""

    def __init__(self):
        path = common.robot_urdf("ur5")
        if path is None:
            raise _core.ModelError("workprecision ur5: example-robot-data is not installed")
        self.pair = PinPair(path)
        self.path = path
        self.q0 = np.array(common.UR5_Q0)
        self._mj_perm = None

    def rhs(self):
        pin, pm, pd = self.pair.pin, self.pair.pm, self.pair.pd
        n = pm.nq
        tau = np.zeros(n)

        def f(_t, y):
            return np.concatenate([y[n:], pin.aba(pm, pd, y[:n], y[n:], tau)])

        return f, np.concatenate([self.q0, np.zeros(n)])

    def reference(self, t):
        from scipy.integrate import solve_ivp

        f, y0 = self.rhs()
        sol = solve_ivp(f, (0, t[-1]), y0, method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
        return sol.y[: len(self.q0)].T

    def init(self, model):
        u0, v0 = _core.state_from_joints(model, self.pair.to_armdyn(self.q0))
        return {"u0": u0, "v0": v0}

    def observe(self, _model, res):
        return res.q[:, self.pair.perm]

    def mujoco(self):
        mj, perm = mujoco_from_urdf(self.path, self.pair)
        qpos0 = np.zeros(mj.nq)
        qpos0[perm] = self.q0
        self._mj_perm = perm
        return mj, qpos0

    @property
    def mj_perm(self):
        """MuJoCo qpos index of each Pinocchio joint."""
        if self._mj_perm is None:
            self.mujoco()
        return self._mj_perm

    def check(self, _ref):
        """The three models are the same mechanism: armdyn's and MuJoCo's accelerations against
        Pinocchio's ABA at 50 random states (relative to the largest acceleration)."""
        import mujoco

        mj, _ = self.mujoco()
        data = mujoco.MjData(mj)
        pin, pm, pd = self.pair.pin, self.pair.pm, self.pair.pd
        rng = np.random.default_rng(0)
        worst = 0.0
        for _ in range(50):
            q, v = rng.uniform(-np.pi, np.pi, size=(2, pm.nq))
            a = pin.aba(pm, pd, q, v, np.zeros(pm.nq))
            data.qpos[self.mj_perm] = q
            data.qvel[self.mj_perm] = v
            mujoco.mj_forward(mj, data)
            worst = max(worst, np.abs(data.qacc[self.mj_perm] - a).max() / np.abs(a).max())
        return {
            "armdyn_qdd_vs_pin_aba_rel": self.pair.cross_check()["fd_rel_error"],
            "mujoco_qacc_vs_pin_aba_rel": float(worst),
        }


def _ur5_more_peers(problem, ref, quick, repeats):
    try:
        from benchmarks.peers import exudyn
    except ImportError:
        return {}
    return exudyn.workprecision_curves(problem, ref, quick, repeats)


def _closed_loop_peers(problem, ref, quick, repeats):
    from benchmarks.peers import closed_loops

    return closed_loops.workprecision_curves(problem, ref, quick, repeats)


def _geared_peers(problem, ref, quick, repeats):
    from benchmarks.peers import geared

    return geared.workprecision_curves(problem, ref, quick, repeats)


class _Geared(_BuiltOnce):
    """The backlash-free geared arm and its Pinocchio reference."""

    ARM = ("waist", "shoulder", "elbow", "wrist_roll", "wrist_pitch", "hand_roll")

    def __init__(self):
        self.ref = references.GearedArmReference()

    @classmethod
    def observe(cls, model, res):
        names = list(model.joint_coord_names)
        return res.q[:, [names.index(j) for j in cls.ARM]]

    def check(self, ref):
        """The reference against itself at rtol 1e-11, and its tree equations (Pinocchio, the
        motor law) against armdyn's Lagrange validator on the open tree at random states."""
        t = output_times(PROBLEMS["geared_arm"])
        loose = self.ref.angles(t, rtol=1e-11)
        worst = self.ref.lagrange_check((0.3, 1.7, 3.0), seed=5)
        return {
            "reference_rtol_1e-12_vs_1e-11_rad": float(np.abs(ref - loose).max()),
            "tree_equations_vs_lagrange_validator_rel": worst,
        }


_A01_XML = """<mujoco><option gravity="0 -9.81 0" timestep="0.001"/>
<worldbody><body name="p"><joint name="pivot" type="hinge" axis="0 0 1"/>
<inertial pos="1 0 0" mass="1" diaginertia="1e-12 1e-12 1e-12"/></body></worldbody></mujoco>"""

PROBLEMS: dict[str, Problem] = {
    "a01": Problem(
        name="a01",
        title="IFToMM A01 simple pendulum (2000 s)",
        source="IFToMM benchmark library, A01_specification.xml (González et al. 2006); "
        "reference: closed form with Jacobi elliptic functions",
        t_end=2000.0,
        n_out=4000,
        quantity="max |P1 - P1_ref| over 4000 outputs [m]",
        build=standard.iftomm_a01_pendulum,
        observe=_a01_observe,
        reference=references.a01_points,
        required=(1e-1, 1e-3),
        sweeps={
            "dopri5": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11],
            "dop853": [1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13],
            "rk4": [1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4],
        },
        quick_sweeps={"dopri5": [1e-6, 1e-8], "dop853": [1e-10], "rk4": [2.5e-3]},
        scipy_rhs=references.a01_rhs,
        scipy_observe=lambda y: np.column_stack([np.sin(y[0]), -np.cos(y[0])]),
        mujoco_xml=_A01_XML,
        mujoco_observe=lambda qpos: np.column_stack([np.cos(qpos[:, 0]), np.sin(qpos[:, 0])]),
        reference_check=_a01_check,
    ),
    "a02": Problem(
        name="a02",
        title="IFToMM A02 N-four-bar, N = 40 (20 s)",
        source="IFToMM benchmark library, A02_specification.xml (González et al. 2006); "
        "reference: the one-DOF parallel branch in the crank angle, DOP853 at rtol 1e-13",
        t_end=20.0,
        n_out=400,
        quantity="max |B0 - B0_ref| over 400 outputs [m]",
        build=lambda: standard.iftomm_a02_four_bar(40),
        observe=_a02_observe,
        reference=lambda t: references.a02_points(t, 40),
        init=lambda model: {"v0": standard.a02_initial_velocity(model, 40)},
        required=(1e-1, 1e-3),
        # near the singular position the KKT solver switches to its regularised block-sparse
        # factor (kkt.hpp): seconds per 20 s run
        sweeps={
            "dopri5": [1e-6, 1e-7, 1e-8, 1e-9, 1e-10],
            "dop853": [1e-4, 1e-5, 1e-6, 1e-7, 1e-8],
        },
        quick_sweeps={"dopri5": [1e-6, 1e-8], "dop853": [1e-6]},
        scipy_rhs=lambda: references.a02_rhs(40),
        scipy_label="the reference's one-DOF branch ODE",
        scipy_not_peer="it integrates the reference's own one-DOF equation, which presumes the "
        "parallel motion of every window (the solution branch); a multibody code is not told "
        "that. The SciPy peer is SciPy on Pinocchio's model of the mechanism",
        scipy_observe=lambda y: np.column_stack([np.cos(y[0]), np.sin(y[0])]),
        more_peers=_closed_loop_peers,
    ),
    "five_dof": Problem(
        name="five_dof",
        title="Five-DOF light-lifting arm, driven (inverse dynamics along the paper's 5 s cubics)",
        source="five-dof-light-lifting-arm-validation (Stage 2); reference: the complete "
        "Euler–Lagrange torques of the same arm (LagrangeValidator) on the exact trajectories",
        t_end=5.0,
        n_out=500,
        quantity="max |tau - tau_Lagrange| of the 5 drive efforts over 500 outputs [N m, N]",
        build=five_dof.five_dof_arm,
        observe=efforts_in_coord_order,
        reference=_five_dof_reference,
        # every joint is driven: the kinematic path (simulate's default here) solves each
        # output from the constraints; the integrators only feed it starting guesses
        sweeps={
            "kinematic": [0.0],
            "dopri5": [1e-4, 1e-6, 1e-8, 1e-10],
            "dop853": [1e-4, 1e-6, 1e-8, 1e-10],
            "rk4": [0.1, 0.05, 0.025, 0.0125],
        },
        quick_sweeps={"kinematic": [0.0], "dopri5": [1e-6], "dop853": [1e-6], "rk4": [0.05]},
    ),
    "ur5": Problem(
        name="ur5",
        title="UR5 (example-robot-data URDF) released from a bent pose, 5 s",
        source="example-robot-data ur5_robot.urdf; reference: SciPy DOP853 at rtol 1e-13 on "
        "Pinocchio's ABA (reduced coordinates, a different method)",
        t_end=5.0,
        n_out=100,
        quantity="max |q - q_ref| of the 6 joint angles over 100 outputs [rad]",
        build=lambda: _Ur5.get().pair.am,
        observe=lambda model, res: _Ur5.get().observe(model, res),
        reference=lambda t: _Ur5.get().reference(t),
        init=lambda model: _Ur5.get().init(model),
        angular=True,
        sweeps={
            "dopri5": [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10],
            "dop853": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11],
            "rk4": [4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4],
        },
        quick_sweeps={"dopri5": [1e-6, 1e-8], "dop853": [1e-8], "rk4": [1e-3]},
        joint_sweeps={
            "dopri5": [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10],
            "dop853": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11],
        },
        quick_joint_sweeps={"dop853": [1e-8]},
        scipy_rhs=lambda: _Ur5.get().rhs(),
        scipy_observe=lambda y: y[:6].T,
        scipy_label="on Pinocchio's ABA",
        mujoco_model=lambda: _Ur5.get().mujoco(),
        mujoco_observe=lambda qpos: qpos[:, _Ur5.get().mj_perm],
        more_peers=_ur5_more_peers,
        reference_check=lambda ref: _Ur5.get().check(ref),
    ),
    "geared_arm": Problem(
        name="geared_arm",
        title="Geared arm (six-DOF paper; 44 bodies, no backlash) on its PD motors, 5 s",
        source="six-dof-arm-topological-projection (armdyn.papers.geared_arm.geared_arm_6dof, "
        "backlash 0); reference: Pinocchio's CRBA and RNEA on the open tree of the same bodies, "
        "reduced by the gear ratios, SciPy DOP853 at rtol 1e-12",
        t_end=5.0,
        n_out=100,
        quantity="max |q - q_ref| of the 6 arm joint angles over 100 outputs [rad]",
        build=lambda: geared_arm_6dof(backlash=0.0),
        observe=_Geared.observe,
        reference=lambda t: _Geared.get().ref.angles(t),
        angular=True,
        # the motors' damping on the light rotors (about 5400 1/s, integrator="auto" reports
        # it) bounds the explicit steps: errors are far below rtol
        sweeps={
            "dopri5": [1e-3, 1e-4, 1e-6, 1e-8],
            "dop853": [1e-4, 1e-6, 1e-8, 1e-10],
            "trbdf2": [1e-3, 1e-4, 1e-5, 1e-6],
            "rk4": [4e-4, 2e-4, 1e-4],
        },
        quick_sweeps={"dopri5": [1e-4]},
        joint_sweeps={
            "dopri5": [1e-3, 1e-4, 1e-6, 1e-8],
            "dop853": [1e-4, 1e-6, 1e-8, 1e-10],
            "trbdf2": [1e-4, 1e-5, 1e-6, 1e-7, 1e-8],
            "rk4": [4e-4, 2e-4, 1e-4],
        },
        quick_joint_sweeps={"trbdf2": [1e-5]},
        scipy_rhs=lambda: _Geared.get().ref.rhs(),
        scipy_observe=lambda y: y[:6].T,
        scipy_label="on Pinocchio's CRBA/RNEA, gear-reduced",
        scipy_rtols=(1e-4, 1e-6, 1e-8, 1e-10),
        more_peers=_geared_peers,
        reference_check=lambda ref: _Geared.get().check(ref),
    ),
    "squeezer": Problem(
        name="squeezer",
        title="Andrews' squeezer (Hairer–Wanner / Test Set; IFToMM A03), 0.03 s",
        source="Hairer & Wanner, Solving ODEs II (1996) §VII.7; Mazzia & Magherini, Test Set for "
        "IVP solvers (2008), problem 'andrews'; reference: the seven-angle index-1 equations, "
        "DOP853 at rtol 1e-13 (agrees with the Test Set's t = 0.03 values to 1.4e-9 rad)",
        t_end=0.03,
        n_out=300,
        quantity="max |angle - angle_ref| of the 7 angles over 300 outputs [rad]",
        build=standard.andrews_squeezer,
        observe=_squeezer_observe,
        reference=references.squeezer_angles,
        angular=True,
        sweeps={
            "dopri5": [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11],
            "dop853": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
            "rk4": [1e-4, 5e-5, 2.5e-5, 1.25e-5, 6.25e-6],
            "trbdf2": [1e-4, 1e-5, 1e-6, 1e-7],
        },
        quick_sweeps={"dopri5": [1e-6, 1e-8], "dop853": [1e-8], "rk4": [2.5e-5]},
        scipy_rhs=references.squeezer_rhs,
        reference_check=_squeezer_check,
        scipy_observe=lambda y: y[:7].T,
        more_peers=_closed_loop_peers,
    ),
}


def _repeats_for(quick: bool) -> int:
    return 3 if quick else 5


def sweep_armdyn(
    problem: Problem,
    integrator: str,
    settings,
    ref,
    repeats: int = 5,
    coordinates: str = "cartesian",
) -> list[dict]:
    """armdyn's curve, by :func:`armdyn.work_precision` (the function users run on their own
    models) with the problem's reference ``ref`` (on the output times), observed quantity and
    error measure; tolerances with atol = rtol (RK4: the steps). Its table's rows become the
    points of the curve."""
    model = problem.build()
    opts = dict(
        problem.init(model) if problem.init else {},
        integrators=[integrator],
        n_out=problem.n_out,
        coordinates=coordinates,
        reference=(output_times(problem), ref),
        observe=lambda res: problem.observe(model, res),
        angular=problem.angular,
        error_measure=problem.quantity,
        repeats=repeats,
        max_steps=10_000_000,  # simulate's default
        # the problems are free motions, as the peers and references integrate them (the UR5's
        # URDF limits would stop its fall at the elbow after 1 s)
        limits="ignore",
    )
    if integrator == "rk4":
        opts["dts"] = settings
    elif integrator != "kinematic":  # no setting: each output is solved exactly
        opts["rtols"] = settings
    table = work_precision(model, problem.t_end, **opts).table
    points = []
    for s, row in zip(settings, table.itertuples(index=False), strict=True):
        point = {"setting": s}
        if row.status == "failed":
            point.update(failed=row.message[:200], error=float("nan"))
        else:
            counters = ("steps", "rejected", "rhs_evals", "kkt_solves", "factorizations")
            point.update(
                cpu_s=row.cpu_s,
                repeats=int(row.repeats),
                error=row.error,
                **{k: int(getattr(row, k)) for k in counters},
                singular_evaluations=int(row.singular_evaluations),
                max_position_residual=row.max_position_residual,
            )
        points.append(point)
    return points


def sweep_mujoco(problem: Problem, integrator: str, steps, ref, repeats: int = 5) -> list[dict]:
    import mujoco

    spacing = problem.t_end / problem.n_out
    points = []
    for h in steps:
        if problem.mujoco_model is not None:
            model, qpos0 = problem.mujoco_model()
        else:
            model, qpos0 = mujoco.MjModel.from_xml_string(problem.mujoco_xml), None
        model.opt.timestep = h
        model.opt.integrator = {
            "rk4": mujoco.mjtIntegrator.mjINT_RK4,
            "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
        }[integrator]
        data = mujoco.MjData(model)
        per = round(spacing / h)

        def call(model=model, data=data, per=per, qpos0=qpos0):
            # the stepping loop runs in C: mj_step(..., nstep) between outputs
            mujoco.mj_resetData(model, data)
            if qpos0 is not None:
                data.qpos[:] = qpos0
            qpos = np.empty((problem.n_out + 1, model.nq))
            qpos[0] = data.qpos
            for k in range(problem.n_out):
                mujoco.mj_step(model, data, nstep=per)
                qpos[k + 1] = data.qpos
            return qpos

        sec, reps, qpos = common.cpu_time(call, repeats)
        obs = problem.mujoco_observe(qpos)
        points.append(
            {
                "setting": h,
                "cpu_s": sec,
                "repeats": reps,
                "error": error(problem, obs, ref),
                "steps": per * problem.n_out,
            }
        )
    return points


SCIPY_RTOLS = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]
SCIPY_QUICK = [1e-6, 1e-8]


def run_problem(name: str, quick: bool = False, peers: bool = True, echo: bool = True) -> dict:
    if name not in PROBLEMS:
        raise _core.ModelError(
            f"workprecision: unknown problem '{name}'; choose from {sorted(PROBLEMS)}"
        )
    p = PROBLEMS[name]
    reps = _repeats_for(quick)
    sweeps = p.quick_sweeps if quick else p.sweeps
    ref = p.reference(output_times(p))
    curves = {}
    for integ, settings in sweeps.items():
        curves[f"armdyn {integ}"] = sweep_armdyn(p, integ, settings, ref, reps)
        if echo:
            _echo(f"armdyn {integ}", curves[f"armdyn {integ}"])
    for integ, settings in (p.quick_joint_sweeps if quick else p.joint_sweeps).items():
        key = f"armdyn {integ} (joint)"
        curves[key] = sweep_armdyn(p, integ, settings, ref, reps, coordinates="joint")
        if echo:
            _echo(key, curves[key])
    not_peers = {}
    if peers and p.scipy_rhs is not None:
        for method in ("DOP853", "RK45"):
            key = f"SciPy {method} ({p.scipy_label})"
            rtols = SCIPY_QUICK if quick else (p.scipy_rtols or SCIPY_RTOLS)
            curves[key] = sweep_scipy(p, method, rtols, ref, reps)
            if p.scipy_not_peer:
                not_peers[key] = p.scipy_not_peer
            if echo:
                _echo(key, curves[key])
    if peers and (p.mujoco_xml is not None or p.mujoco_model is not None):
        try:
            import mujoco  # noqa: F401
        except ImportError:
            pass
        else:
            for integ in ("rk4", "implicit"):
                # implicit Euler is first order: its error falls 10x per 10x smaller step
                hs = [1e-3] if quick else [4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4]
                if integ == "implicit" and not quick:
                    hs = [1e-3, 2.5e-4, 6.25e-5]
                key = f"MuJoCo {integ}"
                curves[key] = sweep_mujoco(p, integ, hs, ref, reps)
                if echo:
                    _echo(key, curves[key])
    if peers and p.more_peers is not None:
        for key, pts in p.more_peers(p, ref, quick, reps).items():
            curves[key] = pts
            if echo:
                _echo(key, pts)
    return {
        "problem": p.name,
        "title": p.title,
        "source": p.source,
        "t_end": p.t_end,
        "outputs": p.n_out,
        "error": p.quantity,
        "required_precision": p.required,
        "reference_check": p.reference_check(ref) if p.reference_check and not quick else {},
        "curves": curves,
        "not_peers": not_peers,
        "fastest_to": _fastest(curves),
    }


def _fastest(curves: dict) -> dict:
    """For target errors 1e-3 and 1e-6: the cheapest point of each curve reaching it, fastest
    curve first."""
    out = {}
    for target in (1e-3, 1e-6):
        best = {k: cpu_to(pts, target) for k, pts in curves.items()}
        best = {k: v for k, v in best.items() if v is not None}
        out[f"{target:g}"] = dict(sorted(best.items(), key=lambda kv: kv[1]))
    return out


def _echo(key, pts):
    for q in pts:
        if "failed" in q:
            print(f"  {key:42s} {q['setting']:9.2e}  failed: {q['failed']}")
        else:
            print(
                f"  {key:42s} {q['setting']:9.2e}  error {q['error']:9.2e}  "
                f"cpu {q['cpu_s'] * 1e3:9.2f} ms"
            )


def plot(result: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10.0, 4.8))
    for key, pts in result["curves"].items():
        e = [q["error"] for q in pts if np.isfinite(q.get("error", np.nan))]
        c = [q["cpu_s"] for q in pts if np.isfinite(q.get("error", np.nan))]
        if e:
            style = "--s"
            if key.startswith("armdyn"):
                style = "-^" if key.endswith("(joint)") else "-o"
            ax.loglog(e, c, style, label=key, ms=4)
    if result.get("required_precision"):
        for r in result["required_precision"]:
            ax.axvline(r, color="grey", lw=0.8, ls=":")
    ax.set_xlabel(f"error: {result['error']}")
    ax.set_ylabel("CPU time [s] (median of warm runs)")
    ax.set_title(result["title"], fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    # beside the axes: the curves stay visible however many there are
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def cpu_to(pts, target):
    """CPU time of the cheapest point of a curve with error <= target (None if none)."""
    ok = [q["cpu_s"] for q in pts if q.get("error", np.nan) <= target]
    return min(ok) if ok else None


def summary_markdown(results: dict) -> str:
    """Table per problem: CPU time of each curve to reach errors 1e-3 and 1e-6, and the failures."""
    lines = ["# Work–precision results", ""]
    for r in results.values():
        lines += [
            f"## {r['title']}",
            "",
            f"Command: `{r['command']}`. Error: {r['error']}. Source: {r['source']}.",
            "",
            *[f"Reference check: {k} = {v:.2g}." for k, v in r.get("reference_check", {}).items()],
            "",
            "| curve | CPU to error 1e-3 [s] | to 1e-6 [s] | smallest error | failed runs |",
            "|---|---|---|---|---|",
        ]
        for key, pts in r["curves"].items():
            fin = [q["error"] for q in pts if np.isfinite(q.get("error", np.nan))]
            fails = [f"{q['setting']:g}: {q['failed']}" for q in pts if "failed" in q]
            cells = []
            for target in (1e-3, 1e-6):
                v = cpu_to(pts, target)
                cells.append("—" if v is None else f"{v:.3g}")
            best = f"{min(fin):.2g}" if fin else "—"
            name = f"{key} (not a peer)" if key in r.get("not_peers", {}) else key
            lines.append(f"| {name} | {cells[0]} | {cells[1]} | {best} | {'; '.join(fails)} |")
        reasons = sorted(set(r.get("not_peers", {}).values()))
        lines += [""] * bool(reasons) + [f"Not a peer: {why}." for why in reasons]
        lines += ["", f"![{r['problem']}]({r['problem']}.png)", ""]
    m = next(iter(results.values()))["machine"] if results else {}
    lines += [f"Machine: {m.get('cpu')}, {m.get('cores')} cores, Python {m.get('python')}.", ""]
    return "\n".join(lines)


ALL = ("squeezer", "a01", "a02", "five_dof", "ur5", "geared_arm")  # "all"
OUT = common.RESULTS / "workprecision"


def run(problems=None, out=OUT, quick=False, peers=True, echo=True):
    """Run the problems (``None`` or ``["all"]``: every one), write ``<problem>.json`` and
    ``<problem>.png`` into ``out`` and a README.md summary of every problem's JSON there."""
    names = list(ALL) if not problems or problems == ["all"] else list(problems)
    outdir = Path(out)
    outdir.mkdir(parents=True, exist_ok=True)
    results = {}
    for name in names:
        if echo:
            print(f"{name}: {PROBLEMS[name].title if name in PROBLEMS else name}")
        r = run_problem(name, quick=quick, peers=peers, echo=echo)
        r["machine"] = common.machine()
        r["command"] = "python -m benchmarks.workprecision " + name + (" --quick" if quick else "")
        common.write_json(outdir / f"{name}.json", r)
        try:
            plot(r, outdir / f"{name}.png")
        except ImportError:
            pass
        results[name] = r
    # the summary covers every problem whose JSON is in the folder, not only this run's
    saved = {}
    for path in sorted(outdir.glob("*.json")):
        saved[path.stem] = json.loads(path.read_text())
    (outdir / "README.md").write_text(summary_markdown(saved))
    return results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.workprecision",
        description="Error against CPU time on the standard problems, with peers.",
    )
    parser.add_argument(
        "problems",
        nargs="*",
        default=["all"],
        help=f"{', '.join(ALL)}, or all (every one; a02 and geared_arm take minutes)",
    )
    parser.add_argument("--out", default=str(OUT), help="folder for JSON + PNG + README.md")
    parser.add_argument("--quick", action="store_true", help="two points per curve")
    parser.add_argument("--no-peers", action="store_true", help="armdyn's curves only")
    args = parser.parse_args(argv)
    run(args.problems, out=args.out, quick=args.quick, peers=not args.no_peers)
    return 0


if __name__ == "__main__":
    sys.exit(main())
