"""base_parameters: the identifiable combinations of pi (issue 35)."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.identification import base_parameters
from armdyn.identification.base import random_states

from benchmarks import common

ROBOTS = common.robots_dir()
needs_robots = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data not installed")

L1 = 0.3  # the planar arm's first link length [m]


def _planar_2r(gravity):
    """Two links turning about parallel z axes: joint 1 at the origin, joint 2 at (L1, 0, 0);
    each body has a named frame with its own name at its joint (axes = world axes at q = 0), so
    pi is about the joints, as in the textbook (Khalil & Dombre's frames)."""
    b = ad.ModelBuilder(gravity=gravity)
    b.add_body("link1", 2.0, (0.01, 0.02, 0.03), (0.12, 0.01, 0.02))
    b.add_revolute("joint1", "ground", "link1", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_frame("link1", "link1", (0.0, 0.0, 0.0))
    b.add_body("link2", 1.5, (0.006, 0.01, 0.012), (L1 + 0.1, -0.02, 0.01))
    b.add_revolute("joint2", "link1", "link2", (L1, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_frame("link2", "link2", (L1, 0.0, 0.0))
    b.add_joint_friction("joint1", 0.1, 0.2)
    return b.finalize()


def _closed_form_2r(names, in_plane_gravity):
    """The base parameters of the planar 2R, derived by hand (Lagrange).

    With frame 1 at joint 1 and frame 2 at joint 2 (angle q1 + q2), first moments h_i = (mcx_i,
    mcy_i) and Izz_i about the joints, the kinetic energy is
        T = 1/2 (Izz1 + L1^2 m2 + Ia1) qd1^2 + 1/2 Izz2 (qd1 + qd2)^2 + 1/2 Ia2 qd2^2
            + L1 qd1 (qd1 + qd2) (mcx2 cos q2 - mcy2 sin q2)
    (Ia_j: the reflected rotor inertia, tau_j += Ia_j qdd_j), and with gravity g along -y
        V = g (mcx1 s1 + mcy1 c1 + L1 m2 s1 + mcx2 s12 + mcy2 c12).
    The torques are linear in the groups ZZ1R = Izz1 + L1^2 m2 + Ia1, Izz2, mcx2, mcy2, Ia2,
    and with in-plane gravity MX1R = mcx1 + L1 m2 and mcy1; the rest (m1, mcz, Ixx, Iyy, Ixy,
    Ixz, Iyz: only moments about x and y, which the joints do not see) never shows. Per joint
    fv, fc and offset are independent: 11 base parameters, 13 with in-plane gravity (Khalil &
    Dombre 2002, sec. 12.4: ZZ1R, ZZ2, MX2, MY2 (+ MX1R, MY1), Ia2, friction and offsets).
    """
    ix = {n: i for i, n in enumerate(names)}

    def row(**coefs):
        r = np.zeros(len(names))
        for key, c in coefs.items():
            r[ix[key.replace("__", ".")]] = c
        return r

    rows = [
        row(link1__Izz=1.0, link2__m=L1**2, joint1__Ia=1.0),
        row(link2__Izz=1.0),
        row(link2__mcx=1.0),
        row(link2__mcy=1.0),
        row(joint2__Ia=1.0),
    ]
    if in_plane_gravity:
        rows += [row(link1__mcx=1.0, link2__m=L1), row(link1__mcy=1.0)]
    for j in ("joint1", "joint2"):
        rows += [row(**{f"{j}__{k}": 1.0}) for k in ("fv", "fc", "offset")]
    return np.array(rows)


@pytest.mark.parametrize("in_plane", [True, False], ids=["gravity-in-plane", "gravity-along-z"])
def test_planar_2r_matches_closed_form(in_plane):
    model = _planar_2r((0.0, -9.81, 0.0) if in_plane else (0.0, 0.0, -9.81))
    base = base_parameters(model)
    names = ad.dynamic_parameter_names(model)
    c = _closed_form_2r(names, in_plane)
    assert base.rank == len(c) == (13 if in_plane else 11)
    # the same row space: the unique combination of the closed-form rows with the identity on
    # the chosen independent columns is base.matrix
    c_ind = c[:, base.independent]
    assert np.linalg.cond(c_ind) < 1e6
    np.testing.assert_allclose(base.matrix, np.linalg.solve(c_ind, c), rtol=0, atol=1e-9)
    # the textbook choice (the first in pi's order of proportional columns): ZZ1R named after Izz1
    assert f"link1.Izz + {L1**2:.6g} link2.m + joint1.Ia" in base.names
    if in_plane:
        assert f"link1.mcx + {L1:.6g} link2.m" in base.names


def test_options_drop_friction_and_offsets():
    model = _planar_2r((0.0, -9.81, 0.0))
    names = ad.dynamic_parameter_names(model)
    full = base_parameters(model)
    lean = base_parameters(model, friction=False, offsets=False)
    assert lean.rank == full.rank - 6
    kept = [names[i] for i in lean.independent]
    assert not any(n.endswith((".fv", ".fc", ".offset")) for n in kept)
    assert base_parameters(model, offsets=False).rank == full.rank - 2
    dropped = [i for i, n in enumerate(names) if n.endswith((".fv", ".fc", ".offset"))]
    assert np.all(lean.matrix[:, dropped] == 0.0)


@needs_robots
@pytest.mark.parametrize(
    ("urdf", "fixed"),
    [
        ("ur_description/urdf/ur5_robot.urdf", True),
        ("panda_description/urdf/panda.urdf", True),
        ("solo_description/robots/solo12.urdf", False),
    ],
    ids=["ur5", "panda", "solo12-floating"],
)
def test_rank_equals_svd_rank_and_is_stable(urdf, fixed):
    """The rank (QR with pivoting on unit-norm columns) equals an independent SVD rank of the
    raw stacked regressor, for several seeds and sample counts (from the fewest allowed, rows =
    parameters, to 6x that; the default 200 in test_ur5_base_count), with a wide gap: the
    singular values fall from > 1e-6 to < 1e-12 of the largest at the rank."""
    model = ad.load_urdf(str(ROBOTS / urdf), fixed_base=fixed)
    p = len(ad.dynamic_parameter_names(model))
    least = -(-p // model.n_dofs)
    ranks = {
        base_parameters(model, seed=s, samples=n).rank
        for s, n in [(0, least), (1, 2 * least), (7, 6 * least)]
    }
    assert len(ranks) == 1
    rank = ranks.pop()
    q, qd, qdd = random_states(model, 2 * least, np.random.default_rng(11))
    y = ad.joint_torque_regressor(model, q, qd, qdd).reshape(-1, p)
    s = np.linalg.svd(y, compute_uv=False)  # raw columns: the SVD rank is unit dependent,
    assert np.sum(s > 1e-9 * s[0]) == rank  # but the gap here is wide enough for both
    assert s[rank - 1] > 1e-6 * s[0] and s[rank] < 1e-12 * s[0]


@needs_robots
def test_ur5_base_count():
    """The UR5's 58 base parameters: 6 joints x (fv, fc, offset) = 18, the rotor inertias Ia of
    joints 3-6 alone (4; Ia1 regroups with shoulder_link.Izz, Ia2 with upper_arm_link.Iyy, both
    axes being fixed relative to the link before), and 36 groups of link inertial parameters.
    No literature value was verified for this URDF's frames: the total is checked against the
    SVD rank in test_rank_equals_svd_rank_and_is_stable."""
    model = ad.load_urdf(str(ROBOTS / "ur_description/urdf/ur5_robot.urdf"))
    base = base_parameters(model)
    names = ad.dynamic_parameter_names(model)
    kept = [names[i] for i in base.independent]
    assert sum(n.endswith((".fv", ".fc", ".offset")) for n in kept) == 18
    assert [n for n in kept if n.endswith(".Ia")] == [
        "elbow_joint.Ia",
        "wrist_1_joint.Ia",
        "wrist_2_joint.Ia",
        "wrist_3_joint.Ia",
    ]
    iyy = [n for n in base.names if n.startswith("upper_arm_link.Iyy ")]
    assert len(iyy) == 1 and iyy[0].endswith(" + shoulder_lift_joint.Ia")
    assert "shoulder_link.Izz + 0.0184552 upper_arm_link.m" in base.names[0]
    assert base.names[0].endswith(" + shoulder_pan_joint.Ia")
    assert base.rank == 58


def _rotated(moments, rng):
    """R diag(moments) R^T for a random rotation R: products of inertia in every axis."""
    r = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return r @ np.diag(moments) @ r.T


def _perturbed(urdf, rng):
    """The robot with a payload welded to every link at a random point (a changed mass, first
    moment and inertia of each link), joint friction and gear-reduced actuators on every joint:
    the 'true' model, its torques from inverse_dynamics (not the regressor)."""
    b = ad.urdf_builder(str(ROBOTS / urdf))
    m0 = b.finalize()
    joints = [n for n in m0.coord_names if "finger" not in n]
    for j in joints:
        b.add_joint_friction(j, rng.uniform(0.1, 1.0), rng.uniform(0.1, 2.0))
        b.add_actuator(j, rng.choice([-1.0, 1.0]) * rng.uniform(50.0, 120.0), 3e-5)
    model = b.finalize()
    links = [n for n in model.body_names if not n.endswith("_armature")][: len(joints)]
    return model.with_payloads(
        [
            {
                "at": link,
                "mass": rng.uniform(0.1, 1.0),
                "com": rng.uniform(-0.1, 0.1, 3),
                "inertia": _rotated(rng.uniform(2e-3, 3e-3, 3), rng),
                "name": f"extra{i}",
            }
            for i, link in enumerate(links)
        ]
    )


@needs_robots
@pytest.mark.parametrize(
    "urdf",
    ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf"],
    ids=["ur5", "panda"],
)
def test_noise_free_recovery(urdf):
    """Y @ pi == Y_b @ beta at fresh states (1e-10), and beta from noise-free torques
    (inverse_dynamics of the perturbed model, lstsq on Y_b) equals base.beta(pi_true) to 1e-8
    relative, entry by entry."""
    rng = np.random.default_rng(5)
    model = _perturbed(urdf, rng)
    pi = ad.dynamic_parameters(model)
    base = base_parameters(model, offsets=False, seed=3)
    q, qd, qdd = random_states(model, 60, np.random.default_rng(21))
    y = ad.joint_torque_regressor(model, q, qd, qdd)
    tau = ad.inverse_dynamics(model, q, qd, qdd)
    np.testing.assert_allclose(
        base.regressor(y) @ base.beta(pi), tau, rtol=0, atol=1e-10 * np.abs(tau).max()
    )
    est = np.linalg.lstsq(base.regressor(y).reshape(-1, base.rank), tau.reshape(-1), rcond=None)[0]
    true = base.beta(pi)
    zero = np.abs(true) < 1e-14 * np.abs(true).max()  # exact identities of the welded payloads
    assert zero.sum() <= 4
    np.testing.assert_allclose(est[~zero], true[~zero], rtol=1e-8, atol=0)
    np.testing.assert_allclose(est[zero], 0.0, rtol=0, atol=1e-8 * np.abs(true).max())


def test_complete_is_least_norm_correction():
    model = _planar_2r((0.0, -9.81, 0.0))
    base = base_parameters(model)
    rng = np.random.default_rng(3)
    pi_ref = ad.dynamic_parameters(model)
    beta = base.beta(pi_ref) + rng.normal(size=base.rank)
    pi = base.complete(beta, pi_ref)
    np.testing.assert_allclose(base.matrix @ pi, beta, rtol=0, atol=1e-12)
    # least norm: the correction is orthogonal to the null space of matrix (a second method:
    # the projection onto the row space of the identity-on-independent rows)
    null = np.linalg.svd(base.matrix)[2][base.rank :]
    np.testing.assert_allclose(null @ (pi - pi_ref), 0.0, atol=1e-12)
    np.testing.assert_allclose(base.complete(base.beta(pi_ref), pi_ref), pi_ref, atol=1e-14)


def test_regressor_selects_columns_on_batches():
    model = _planar_2r((0.0, -9.81, 0.0))
    base = base_parameters(model)
    q, qd, qdd = random_states(model, 4, np.random.default_rng(0))
    y = ad.joint_torque_regressor(model, q, qd, qdd)
    assert base.regressor(y).shape == (4, 2, base.rank)
    np.testing.assert_array_equal(base.regressor(y[0]), y[0][:, base.independent])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"samples": 0}, "samples"),
        ({"samples": 13}, "26 regressor rows for 28 parameters: the rank needs at least 14"),
        ({"samples": 2.5}, "samples"),
        ({"seed": -1}, "seed"),
        ({"tol": 0.0}, "tol"),
        ({"tol": float("nan")}, "tol"),
        ({"friction": "no"}, "friction"),
        ({"offsets": None}, "offsets"),
    ],
)
def test_bad_arguments(kwargs, match):
    model = _planar_2r((0.0, -9.81, 0.0))
    with pytest.raises(ad.ModelError, match=match):
        base_parameters(model, **kwargs)


def test_bad_models_and_vectors():
    with pytest.raises(ad.ModelError, match=r"model must be an armdyn\.Model"):
        base_parameters("ur5.urdf")
    b = ad.ModelBuilder()
    b.add_body("lone", 1.0, (1.0, 1.0, 1.0))
    b.add_fixed("weld", "ground", "lone")
    with pytest.raises(ad.ModelError, match="no joint"):
        base_parameters(b.finalize())
    base = base_parameters(_planar_2r((0.0, -9.81, 0.0)))
    with pytest.raises(ad.ModelError, match="pi must have shape"):
        base.beta(np.ones(3))
    with pytest.raises(ad.ModelError, match="pi_ref"):
        base.complete(np.zeros(base.rank), np.full(len(base.param_names), np.nan))
    with pytest.raises(ad.ModelError, match="beta must have shape"):
        base.complete(np.zeros(base.rank + 1), np.zeros(len(base.param_names)))
    with pytest.raises(ad.ModelError, match="columns"):
        base.regressor(np.zeros((2, 3)))


@needs_robots
def test_floating_base_accepted():
    model = ad.load_urdf(str(ROBOTS / "solo_description/robots/solo12.urdf"), fixed_base=False)
    base = base_parameters(model, samples=30)
    q, qd, qdd = random_states(model, 5, np.random.default_rng(4))
    np.testing.assert_allclose(np.linalg.norm(q[:, 3:7], axis=1), 1.0)
    y = ad.joint_torque_regressor(model, q, qd, qdd)
    pi = ad.dynamic_parameters(model)
    tau = ad.inverse_dynamics(model, q, qd, qdd)
    np.testing.assert_allclose(
        base.regressor(y) @ base.beta(pi), tau, rtol=0, atol=1e-10 * np.abs(tau).max()
    )
