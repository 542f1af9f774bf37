"""Every option of the public run and dynamics functions fed a wrong type, a value out of
range, None, a huge integer, NaN, a complex number or array and a lone-surrogate string: a
ModelError naming the argument, never pybind11's "incompatible function arguments" signature
dump nor "Unable to cast" (armdyn._checks in the Python facade, common.hpp in the bindings).

Also: finite inputs whose results overflow raise a SolverError naming the input (never NaN in
the output), checked against the same call at a representable scale."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

LEAKS = ("incompatible function arguments", "Unable to cast", "isfinite", "ComplexWarning")


def _pendulum():
    b = ad.ModelBuilder()
    b.add_body("bob", 1.0, np.diag([1e-3, 1e-3, 1e-3]), position=(0.0, 0.0, -1.0))
    b.add_revolute("hinge", "ground", "bob", (0, 0, 0), (0, 1, 0))
    b.add_frame("tip", "bob", position=(0.0, 0.0, -0.1))
    return b.finalize()


M = _pendulum()
U0, V0 = M.u0, M.v0
COMPLEX = np.array([0.1 + 1j])
OBJECTS = np.array(["a"], dtype=object)
SURROGATE = "bad\ud800name"

# bad values by kind of option; None is bad unless the option takes it
BAD = {
    "positive": ["1", 1j, np.nan, np.inf, -1.0, 0.0, [1.0], object()],
    "unit": ["0.5", 1j, np.nan, -0.1, 1.5],
    "count": [1.5, 2**70, "3", True, 0, -1, np.nan],
    "choice": [123, "nope", SURROGATE, 1j],
    "flag": ["yes", 2, 1j],
    "array1": [COMPLEX, OBJECTS, "abc", [[0.1], [0.2, 0.3]]],
    "array2": [COMPLEX[None, :], OBJECTS[None, :], "abc"],
    "frame": [2**63, 2**70, -1, SURROGATE, 1.5, None],
    "time": ["1", 1j, None, object()],
    "path": [2, 1j, object()],
    "name": [SURROGATE, 5, b"tip"],
}

# (function id, call(**options), {option: (kind, None accepted)})
SIM = {
    "t_end": ("positive", False),
    "integrator": ("choice", True),
    "rtol": ("positive", False),
    "atol": ("positive", False),
    "dt": ("positive", True),
    "output_dt": ("positive", True),
    "max_step": ("positive", True),
    "max_steps": ("count", False),
    "projection": ("choice", False),
    "coordinates": ("choice", False),
    "limits": ("choice", False),
    "merge_welded": ("flag", False),
    "restitution": ("unit", False),
    "q0": ("array1", True),
    "max_output_bytes": ("positive", True),
}
SIM_BASE = dict(t_end=0.05, output_dt=0.01)
ROLL_BASE = dict(q0=[[0.1]], t_end=0.05, output_dt=0.01)
ROLL = {**{k: v for k, v in SIM.items() if k != "q0"}, "threads": ("count", True)}
ROLL |= {"q0": ("array2", False), "qd0": ("array2", True)}

WP_BASE = dict(t_end=0.05, integrators=["rk4"], dts=[0.01], n_out=5)
URDF = """<robot name="r"><link name="base"/><link name="arm"><inertial><mass value="1"/>
  <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
  <origin xyz="0 0 -0.5"/></joint></robot>"""
RUN = ad.simulate(M, 0.1, q0=[0.3], output_dt=0.01, limits="ignore")
RUN.joint_torques[:] = 1.0  # a torque to size and sweep
GRS_BASE = dict(ratios=[10.0, 20.0], actuators={"hinge": {"rotor_inertia": 1e-5}})
TRAJ = dict(t=[0.0, 1.0], q=[[0.0], [0.1]], qd=[[0.0], [0.0]], qdd=[[0.0], [0.0]])

FUNCTIONS = [
    ("simulate", lambda **o: ad.simulate(M, **{**SIM_BASE, **o}), SIM),
    ("rollout", lambda **o: ad.rollout(M, **{**ROLL_BASE, **o}), ROLL),
    (
        "forward_dynamics",
        lambda **o: ad.forward_dynamics(M, **{**dict(q=[0.1], qd=[0.0], tau=[0.0]), **o}),
        {
            "q": ("array1", False),
            "qd": ("array1", False),
            "tau": ("array1", False),
            "t": ("time", False),
            "method": ("choice", False),
        },
    ),
    (
        "inverse_dynamics",
        lambda **o: ad.inverse_dynamics(M, **{**dict(q=[0.1], qd=[0.0], qdd=[0.0]), **o}),
        {
            "q": ("array1", False),
            "qd": ("array1", False),
            "qdd": ("array1", False),
            "t": ("time", False),
            "method": ("choice", False),
        },
    ),
    ("mass_matrix", lambda **o: ad.mass_matrix(M, **{"q": [0.1], **o}), {"q": ("array1", False)}),
    (
        "frame_pose",
        lambda **o: ad.frame_pose(M, **{"q": [0.1], "frame": "tip", **o}),
        {"q": ("array1", False), "frame": ("frame", False)},
    ),
    (
        "frame_jacobian",
        lambda **o: ad.frame_jacobian(M, **{"q": [0.1], "frame": "tip", **o}),
        {"q": ("array1", False), "frame": ("frame", False)},
    ),
    (
        "frame_pose_cartesian",
        lambda **o: ad.frame_pose_cartesian(M, **{"u": U0, "frame": "tip", **o}),
        {"u": ("array1", False), "frame": ("frame", False)},
    ),
    (
        "frame_jacobian_cartesian",
        lambda **o: ad.frame_jacobian_cartesian(M, **{"u": U0, "frame": "tip", **o}),
        {"u": ("array1", False), "frame": ("frame", False)},
    ),
    (
        "state_from_joints",
        lambda **o: ad.state_from_joints(M, **{"q": [0.1], "qd": [0.0], **o}),
        {"q": ("array1", False), "qd": ("array1", True)},
    ),
    (
        "joint_coordinates",
        lambda **o: ad.joint_coordinates(M, **{"u": U0, "v": V0, **o}),
        {"u": ("array1", False), "v": ("array1", False)},
    ),
    (
        "energy",
        lambda **o: ad.energy(M, **{"u": U0, "v": V0, **o}),
        {"u": ("array1", False), "v": ("array1", False)},
    ),
    (
        "body_accelerations",
        lambda **o: ad.body_accelerations(M, **{"u": U0, "v": V0, **o}),
        {"u": ("array1", False), "v": ("array1", False)},
    ),
    (
        "trajectory_run",
        lambda **o: ad.trajectory_run(M, **{**TRAJ, **o}),
        {
            "t": ("array1", False),
            "q": ("array2", False),
            "qd": ("array2", False),
            "qdd": ("array2", False),
        },
    ),
    (
        "work_precision",
        lambda **o: ad.work_precision(M, **{**WP_BASE, **o}),
        {
            "t_end": ("positive", False),
            "n_out": ("count", False),
            "repeats": ("count", False),
            "max_steps": ("count", False),
            "atol_factor": ("positive", False),
            "coordinates": ("choice", False),
            "limits": ("choice", False),
        },
    ),
    (
        "load_urdf",
        lambda **o: ad.load_urdf(URDF, **o),
        {
            "fixed_base": ("flag", False),
            "physical_inertia": ("flag", False),
            "mimic": ("flag", False),
            "gravity": ("array1", False),
        },
    ),
    (
        "LagrangeValidator",
        lambda **o: ad.LagrangeValidator(M, **o),
        {"rotational_inertia": ("flag", False)},
    ),
    (
        "gear_ratio_sweep",
        lambda **o: ad.gear_ratio_sweep(RUN, M, **{**GRS_BASE, **o}),
        {"ratios": ("array1", False)},
    ),
    (
        "sizing_report",
        lambda **o: ad.sizing_report(RUN, M, **o),
        {"out": ("path", True)},
    ),
    ("Model.frame", lambda **o: M.frame(**{"frame": "tip", **o}), {"frame": ("name", False)}),
    (
        "Model.joint_limits",
        lambda **o: M.joint_limits(**{"joint": "hinge", **o}),
        {"joint": ("name", False)},
    ),
    (
        "Model.joint_frame",
        lambda **o: M.joint_frame(**{"joint": "hinge", **o}),
        {"joint": ("name", False)},
    ),
    (
        "Model.with_kkt_path",
        lambda **o: M.with_kkt_path(**{"path": "dense", **o}),
        {"path": ("name", False)},
    ),
    (
        "driven_inverse_dynamics",
        lambda **o: ad.driven_inverse_dynamics(ad.scenes.slider_crank(), **{"t": [0.0, 0.1], **o}),
        {"t": ("array1", False)},
    ),
]


def _cases():
    for fid, call, options in FUNCTIONS:
        for name, (kind, none_ok) in options.items():
            values = BAD[kind] + ([] if none_ok or None in BAD[kind] else [None])
            for k, value in enumerate(values):
                yield pytest.param(call, name, value, id=f"{fid}-{name}-{k}")


def test_the_baselines_are_valid():
    """Each call above succeeds with its baseline options: the failures below are the bad
    option's."""
    for _fid, call, _options in FUNCTIONS:
        call()


@pytest.mark.parametrize("call, name, value", list(_cases()))
def test_a_bad_option_is_a_model_error_naming_it(call, name, value):
    with pytest.raises(ad.ModelError) as err:
        call(**{name: value})
    message = str(err.value)
    assert name in message, message
    assert not any(leak in message for leak in LEAKS), message


@pytest.mark.parametrize("not_a_model", [None, 5, "ur5.urdf", ad.ModelBuilder()])
@pytest.mark.parametrize(
    "name, call",
    [
        ("forward_dynamics", lambda m: ad.forward_dynamics(m, [0.1], [0.0], [0.0])),
        ("inverse_dynamics", lambda m: ad.inverse_dynamics(m, [0.1], [0.0], [0.0])),
        ("mass_matrix", lambda m: ad.mass_matrix(m, [0.1])),
        ("frame_pose", lambda m: ad.frame_pose(m, [0.1], 0)),
        ("frame_jacobian", lambda m: ad.frame_jacobian(m, [0.1], 0)),
        ("dynamics_cost", lambda m: ad.dynamics_cost(m)),
        ("Data", lambda m: ad.Data(m)),
    ],
)
def test_a_model_argument_that_is_not_a_model_is_named(name, call, not_a_model):
    with pytest.raises(ad.ModelError, match=rf"{name}: model must be an armdyn.Model") as err:
        call(not_a_model)
    assert not any(leak in str(err.value) for leak in LEAKS)
    call(M)  # the same call with the model runs


def test_no_complex_warning_leaks(recwarn):
    with pytest.raises(ad.ModelError, match=r"q: .*real numbers"):
        ad.forward_dynamics(M, [0.1 + 0j], [0.0], [0.0])
    with pytest.raises(ad.ModelError, match=r"tau: .*complex"):
        ad.forward_dynamics(M, [0.1], [0.0], np.array([0.0 + 0j]))
    assert not [w for w in recwarn if "Complex" in type(w.message).__name__]


# --- finite in, finite out ------------------------------------------------------------------


def ur5():
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return ad.load_urdf(path)


def test_forward_dynamics_overflow_is_a_solver_error_naming_tau():
    """The issue's case: one torque of 1.7e308 (finite) gave all-NaN accelerations. A torque
    of 1e300 on the same joint gives finite accelerations, 1e300 times those of a unit torque
    (the map is linear at rest without gravity's share: compared at qd = 0 with the bias
    removed)."""
    model = ur5()
    q, z = np.array(common.UR5_Q0), np.zeros(6)
    tau = z.copy()
    tau[1] = 1.7e308
    for method in ("auto", "crba", "aba", "cartesian"):
        with pytest.raises(ad.SolverError, match=r"forward_dynamics: .*largest input is tau\[1\]"):
            ad.forward_dynamics(model, q, z, tau, method=method)
    # batch: the row is named
    qs, zs = np.tile(q, (3, 1)), np.zeros((3, 6))
    taus = zs.copy()
    taus[2, 1] = 1.7e308
    with pytest.raises(ad.SolverError, match=r"row 2: .*tau\[1\]"):
        ad.forward_dynamics(model, qs, zs, taus)
    # the scale below overflow is a correct answer: qdd(τ) − qdd(0) = M⁻¹ τ
    bias = ad.forward_dynamics(model, q, z, z)
    unit = z.copy()
    unit[1] = 1.0
    big = unit * 1e300
    m_inv_unit = np.linalg.solve(ad.mass_matrix(model, q), unit)
    np.testing.assert_allclose(
        (ad.forward_dynamics(model, q, z, big) - bias) / 1e300, m_inv_unit, rtol=1e-9
    )


def test_inverse_dynamics_overflow_is_a_solver_error_naming_qdd():
    model = ur5()
    q, z = np.array(common.UR5_Q0), np.zeros(6)
    qdd = z.copy()
    qdd[0] = 1.7e308
    with pytest.raises(ad.SolverError, match=r"inverse_dynamics: .*largest input is qdd\[0\]"):
        ad.inverse_dynamics(model, q, z, qdd)
    # below overflow: tau(qdd) − tau(0) = M qdd
    qdd[0] = 1e300
    tau = ad.inverse_dynamics(model, q, z, qdd) - ad.inverse_dynamics(model, q, z, z)
    np.testing.assert_allclose(tau / 1e300, ad.mass_matrix(model, q)[:, 0], rtol=1e-9)


def test_floating_base_mass_matrix_far_away_equals_the_one_at_the_origin():
    """The issue's case: the floating-base mass matrix was all NaN once the base position
    reached 1e154 (and, found here, wrong by 1e-3 relative at 1e6 m: the world-frame products
    lose precision with the square of the distance). M does not depend on where the base is
    (a translation of the whole tree): every position gives the matrix at the origin, which
    is checked against the composite-body closed form of this two-body robot."""
    m_base, m_arm, arm = 2.0, 1.0, 0.5
    i_base, i_arm = np.array([0.1, 0.2, 0.3]), np.array([0.01, 0.02, 0.03])
    b = ad.ModelBuilder(gravity=(0, 0, -9.81))
    b.add_body("base", m_base, np.diag(i_base))
    b.add_free("float", "base")
    b.add_body("arm", m_arm, np.diag(i_arm), position=(0.0, 0.0, -arm))
    b.add_revolute("hinge", "base", "arm", (0, 0, 0), (0, 1, 0))
    model = b.finalize()
    q = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    m0 = ad.mass_matrix(model, q)
    # at q = 0 (arm hanging along -z): total mass on the linear block, the arm's rotation
    # about y: its own inertia plus m l^2
    np.testing.assert_allclose(np.diag(m0)[:3], m_base + m_arm, rtol=1e-12)
    assert m0[6, 6] == pytest.approx(i_arm[1] + m_arm * arm**2, rel=1e-12)
    for x in (1e6, 1e154, 1e300):
        far = q.copy()
        far[:3] = (x, -x, x)
        np.testing.assert_array_equal(ad.mass_matrix(model, far), m0)
        np.testing.assert_array_equal(ad.mass_matrix(model, np.stack([q, far]))[1], m0)


@pytest.mark.parametrize("method", ["crba", "aba"])
def test_floating_base_forward_dynamics_1e6_m_away_keeps_its_precision(method):
    """forward_dynamics does not depend on where a floating base is. 1e6 m from the origin the
    base position's own round-off (1e6 * eps) bounds the change; the CRBA path took its inertias
    about the world origin and lost precision with the square of the distance (4.5e-2 relative
    on solo12 before it took them about the base)."""
    path = common.robots_dir()
    if path is None:
        pytest.skip("example-robot-data is not installed")
    m = ad.load_urdf(path / "solo_description" / "robots" / "solo12.urdf", fixed_base=False)
    rng = np.random.default_rng(0)
    q = np.zeros(m.n_coords)
    q[3] = 1.0
    q[7:] = rng.uniform(-1, 1, m.n_coords - 7)
    qd, tau = rng.uniform(-1, 1, m.n_dofs), rng.uniform(-1, 1, m.n_dofs)
    near = ad.forward_dynamics(m, q, qd, tau, method=method)
    q[:3] = 1e6
    far = ad.forward_dynamics(m, q, qd, tau, method=method)
    assert np.abs(far - near).max() <= 1e-8 * np.abs(near).max()
