"""Analytical first-order derivatives of the dynamics (issue 34): ``inverse_dynamics_derivatives``
(dtau/dq, dtau/dqd) and ``forward_dynamics_derivatives`` (dqdd/dq, dqdd/dqd, dqdd/dtau), checked
against central finite differences of the public ``inverse_dynamics`` / ``forward_dynamics`` on
the UR5 and the Panda (its fingers coupled: a mimic joint), a floating solo12 (q perturbed along
the base's qd block through the exponential map: Pinocchio's free-flyer convention), arms with
actuators (rotors on follower joints: gear-reduced and gyroscopic) and a cylindrical joint; and
against properties that need no differencing (dtau/dqd vanishes at rest, gravity's dtau/dq is a
symmetric Hessian on a fixed base, dqdd/dtau is the inverse mass matrix)."""

import re
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

EXAMPLE_ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
}


def _urdf(robot, tmp_path):
    """The example-robot-data URDF without its ``<dynamics damping friction>`` (armdyn imports
    them as joint friction: force elements, whose derivatives are part forcederiv's)."""
    ur5 = common.robot_urdf("ur5")
    assert ur5 is not None, "example-robot-data is part of the test extra"
    robots = next(p for p in ur5.parents if p.name == "robots")
    path = robots / EXAMPLE_ROBOTS[robot]
    text = re.sub(r"<dynamics\b[^>]*/>", "", Path(path).read_text())
    out = Path(tmp_path) / Path(path).name
    out.write_text(text)
    return str(out)


def _quat_mul(a, b):
    w1, v1 = a[0], a[1:]
    w2, v2 = b[0], b[1:]
    return np.concatenate([[w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)])


def _rot(e):
    w, x, y, z = e
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _step(model, q, k, eps):
    """q moved by eps along degree of freedom k: a coordinate by eps; a floating base (the
    leading 7 entries of q per base) by the exponential map of eps times its k-th velocity
    (linear in its own axes, or angular in its own axes)."""
    q = np.array(q, dtype=float)
    n_free = _n_free(model)
    if k >= 6 * n_free:
        q[7 * n_free + k - 6 * n_free] += eps
        return q
    b, i = divmod(k, 6)
    e = q[7 * b + 3 : 7 * b + 7]
    if i < 3:
        q[7 * b : 7 * b + 3] += eps * _rot(e)[:, i]
    else:
        axis = np.zeros(3)
        axis[i - 3] = 1.0
        dq = np.concatenate([[np.cos(eps / 2)], np.sin(eps / 2) * axis])
        q[7 * b + 3 : 7 * b + 7] = _quat_mul(e, dq)
    return q


def _n_free(model):
    return model.n_coords - model.n_dofs  # 7 entries of q, 6 of qd per floating base


def _fd(model, f, q, qd, x, h=1e-3):
    """Central differences of f(q, qd, x) (n_dofs,) along each degree of freedom of q and of
    qd, (df/dq, df/dqd), Richardson-extrapolated from steps h and h/2 (error O(h^4): a step
    large against the round-off of f, which a floating robot's light legs make 1e-11 of qdd)."""
    n = model.n_dofs

    def central(k, eps):
        e = np.zeros(n)
        e[k] = eps
        dq = f(_step(model, q, k, eps), qd, x) - f(_step(model, q, k, -eps), qd, x)
        dqd = f(q, qd + e, x) - f(q, qd - e, x)
        return dq / (2 * eps), dqd / (2 * eps)

    dq, dqd = np.empty((n, n)), np.empty((n, n))
    for k in range(n):
        (a, b), (c, d) = central(k, h), central(k, h / 2)
        dq[:, k] = (4 * c - a) / 3
        dqd[:, k] = (4 * d - b) / 3
    return dq, dqd


def _rel(a, b):
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


def _state(model, rng):
    nf = _n_free(model)
    q = rng.uniform(-1.5, 1.5, model.n_coords)
    for b in range(nf):
        e = rng.normal(size=4)
        q[7 * b + 3 : 7 * b + 7] = e / np.linalg.norm(e)
    n = model.n_dofs
    return q, rng.normal(size=n), rng.normal(size=n)


def _check_model(model, seed=3, states=2):
    rng = np.random.default_rng(seed)
    for _ in range(states):
        q, qd, qdd = _state(model, rng)
        dq, dqd = ad.inverse_dynamics_derivatives(model, q, qd, qdd)
        fq, fqd = _fd(model, lambda a, b, c: ad.inverse_dynamics(model, a, b, c), q, qd, qdd)
        assert _rel(dq, fq) <= 1e-7, _rel(dq, fq)
        assert _rel(dqd, fqd) <= 1e-7, _rel(dqd, fqd)
        tau = rng.normal(size=model.n_dofs) * 10
        aq, aqd, atau = ad.forward_dynamics_derivatives(model, q, qd, tau)
        fd = lambda a, b, c: ad.forward_dynamics(model, a, b, c)  # noqa: E731
        gq, gqd = _fd(model, fd, q, qd, tau)
        assert _rel(aq, gq) <= 1e-7, _rel(aq, gq)
        assert _rel(aqd, gqd) <= 1e-7, _rel(aqd, gqd)
        np.testing.assert_allclose(atau @ ad.mass_matrix(model, q), np.eye(model.n_dofs), atol=1e-9)


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_arms_equal_finite_differences(robot, tmp_path):
    model = ad.load_urdf(_urdf(robot, tmp_path))
    if robot == "panda":
        assert len(model.joint_coord_names) == model.n_coords + 1  # the mimic finger
    _check_model(model)


def test_floating_solo12_equals_finite_differences(tmp_path):
    model = ad.load_urdf(_urdf("solo12", tmp_path), fixed_base=False)
    assert model.n_coords == model.n_dofs + 1
    _check_model(model, states=1)


def _box(b, name, mass, position, dims=(0.3, 0.2, 0.1)):
    x, y, z = dims
    inertia = mass / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
    b.add_body(name, mass, inertia, position)


def _mixed(floating, elements=False):
    """A tree with every joint type the joint space takes: a base (floating or on a revolute),
    a revolute, a cylindrical (turn and slide on one line), a prismatic, a fixed joint, and a
    coupling with an offset (follower 'r3' = -0.7 'r1' + 0.2); gravity oblique. elements: with
    force elements of every kind inverse_dynamics includes (a body load scaled in t, a
    spring-damper between two bodies, a joint spring-damper, friction, a PD motor)."""
    b = ad.ModelBuilder(gravity=(1.0, -2.0, -9.0))
    _box(b, "base", 3.0, (0.1, 0.0, 0.5))
    _box(b, "a", 1.2, (0.4, 0.1, 0.6))
    _box(b, "c", 0.8, (0.7, 0.2, 0.5))
    _box(b, "p", 0.5, (0.7, 0.5, 0.3))
    _box(b, "f", 0.3, (0.9, 0.5, 0.3))
    _box(b, "d", 0.6, (0.2, -0.3, 0.7))
    if floating:
        b.add_free("float", "base")
    else:
        b.add_revolute("r0", "ground", "base", (0.0, 0.0, 0.4), (0.2, 0.1, 1.0))
    b.add_revolute("r1", "base", "a", (0.3, 0.05, 0.55), (0.0, 1.0, 0.3))
    b.add_cylindrical("cyl", "a", "c", (0.55, 0.15, 0.55), (1.0, 0.2, -0.1))
    b.add_prismatic("pr", "c", "p", (0.7, 0.35, 0.4), (0.1, 1.0, -0.5))
    b.add_fixed("weld", "p", "f", (0.8, 0.5, 0.3))
    b.add_revolute("r3", "base", "d", (0.15, -0.2, 0.6), (1.0, 0.0, 0.2))
    b.add_coupling("link", "r3", "r1", -0.7, 0.2)
    if elements:
        profile = ad.profiles.sine(0.5, 1.3)
        b.add_body_force("c", (1.0, -2.0, 0.5), (0.1, 0.2, -0.3), (0.75, 0.2, 0.5), profile)
        b.add_spring_damper("sd", "base", (0.0, 0.1, 0.5), "p", (0.7, 0.5, 0.3), 50.0, 2.0)
        b.add_joint_spring_damper("cyl", 3.0, 0.4, 0.1, coord=1)
        b.add_joint_friction("r1", viscous=0.2, coulomb=0.3, smoothing_velocity=0.5)
        b.add_motor("pr", 0.1, 40.0, 3.0)
    return b.finalize()


@pytest.mark.parametrize("floating", [False, True])
def test_every_joint_type_with_a_coupling_equals_finite_differences(floating):
    model = _mixed(floating)
    assert model.n_dofs == (6 if floating else 1) + 4  # r3 follows r1
    _check_model(model, seed=11, states=2)


@pytest.mark.parametrize("gyroscopic", [False, True])
def test_arm_with_actuators_equals_finite_differences(gyroscopic, tmp_path):
    # rotors on follower joints (coupled to their joints: q_rotor = N q), gear-reduced on ground
    # or gyroscopic on the joint's parent body
    b = ad.urdf_builder(_urdf("ur5", tmp_path))
    for name, n, j in zip(
        ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint"],
        [100.0, -100.0, 80.0, 50.0],
        [6e-5, 6e-5, 4e-5, 1.5e-5],
        strict=True,
    ):
        b.add_actuator(name, n, j, gyroscopic=gyroscopic)
    model = b.finalize()
    assert model.n_dofs == 6 and len(model.joint_coord_names) == 10
    _check_model(model, seed=5, states=1)


def test_properties_without_differencing(tmp_path):
    # at rest dtau/dqd vanishes (no velocity terms, no dampers); at rest and without
    # acceleration dtau/dq is the Hessian of the potential energy on a fixed base: symmetric;
    # dqdd/dtau is the inverse of mass_matrix
    model = ad.load_urdf(_urdf("panda", tmp_path))
    rng = np.random.default_rng(2)
    q, _, _ = _state(model, rng)
    zero = np.zeros(model.n_dofs)
    dq, dqd = ad.inverse_dynamics_derivatives(model, q, zero, zero)
    assert np.abs(dqd).max() == 0.0
    assert np.abs(dq).max() > 1.0  # gravity's
    assert _rel(dq, dq.T) <= 1e-13
    _, _, minv = ad.forward_dynamics_derivatives(model, q, zero, rng.normal(size=model.n_dofs))
    np.testing.assert_allclose(minv, np.linalg.inv(ad.mass_matrix(model, q)), rtol=1e-10)
    np.testing.assert_allclose(minv, minv.T, rtol=1e-12)


def test_batch_equals_single_states_and_takes_data_and_times(tmp_path):
    model = ad.load_urdf(_urdf("ur5", tmp_path))
    rng = np.random.default_rng(4)
    rows = [_state(model, rng) for _ in range(3)]
    q, qd, x = (np.array(a) for a in zip(*rows, strict=True))
    data = ad.Data(model)
    t = np.array([0.0, 0.5, 1.0])
    dq, dqd = ad.inverse_dynamics_derivatives(model, q, qd, x, t=t, data=data)
    fq, fqd, ftau = ad.forward_dynamics_derivatives(model, q, qd, x, t=t, data=data)
    assert dq.shape == dqd.shape == fq.shape == ftau.shape == (3, 6, 6)
    for i in range(3):
        one = ad.inverse_dynamics_derivatives(model, q[i], qd[i], x[i], t=t[i])
        np.testing.assert_array_equal(dq[i], one[0])
        np.testing.assert_array_equal(dqd[i], one[1])
        one = ad.forward_dynamics_derivatives(model, q[i], qd[i], x[i])
        for a, b in zip((fq[i], fqd[i], ftau[i]), one, strict=True):
            np.testing.assert_array_equal(a, b)
    # the state's rows keep their order: row 1 differs from row 0
    assert not np.array_equal(dq[0], dq[1])


def test_large_batches_reuse_only_freed_output_buffers(tmp_path):
    """Outputs of >= 1 MB come from the module's buffer pool: a later call never writes into an
    array still alive, and a reused buffer holds the new call's answers (checked row by row
    against single calls)."""
    model = ad.load_urdf(_urdf("ur5", tmp_path))
    rng = np.random.default_rng(5)
    rows = 4000  # 4000 x 6 x 6 doubles: 1.15 MB per output
    q = rng.uniform(-np.pi, np.pi, (rows, 6))
    qd, x = rng.normal(size=(2, rows, 6))
    first = ad.forward_dynamics_derivatives(model, q, qd, x)
    kept = [a.copy() for a in first]
    second = ad.forward_dynamics_derivatives(model, q[::-1].copy(), qd[::-1].copy(), x[::-1].copy())
    for a, b in zip(first, kept, strict=True):
        np.testing.assert_array_equal(a, b)  # the live arrays are untouched
    for a, b in zip(second, kept, strict=True):
        np.testing.assert_array_equal(a, b[::-1])
    del first, second  # their buffers go back to the pool and serve the next calls
    dq, dqd = ad.inverse_dynamics_derivatives(model, q, qd, x)
    third = ad.forward_dynamics_derivatives(model, q, qd, x)
    for a, b in zip(third, kept, strict=True):
        np.testing.assert_array_equal(a, b)
    for i in (0, rows // 2, rows - 1):
        one = ad.inverse_dynamics_derivatives(model, q[i], qd[i], x[i])
        np.testing.assert_array_equal(dq[i], one[0])
        np.testing.assert_array_equal(dqd[i], one[1])
        one = ad.forward_dynamics_derivatives(model, q[i], qd[i], x[i])
        for a, b in zip(third, one, strict=True):
            np.testing.assert_array_equal(a[i], b)
    assert all(a.flags.writeable and a.flags.c_contiguous for a in (dq, dqd, *third))


def _message(f, *args, **kw):
    with pytest.raises(ad.ModelError) as err:
        f(*args, **kw)
    return str(err.value)


def test_bad_inputs_get_the_messages_of_inverse_and_forward_dynamics(tmp_path):
    # the same checks as inverse_dynamics / forward_dynamics, naming the argument (and the row)
    model = ad.load_urdf(_urdf("ur5", tmp_path))
    z, nan, rows = np.zeros(6), np.full(6, np.nan), np.zeros((2, 6))
    bad_row = rows.copy()
    bad_row[1, 2] = np.inf
    cases = [
        ((z[:5], z, z), {}, "has length 5|shape"),
        ((z, nan, z), {}, "qd contains NaN"),
        ((z, z, nan), {}, "contains NaN"),
        ((z, z, z), {"t": np.inf}, "t is not finite"),
        ((rows, bad_row, rows), {}, "row 1: .*qd contains NaN or inf"),
        ((rows, rows, rows[:1]), {}, "must have shape"),
        ((z, z, z), {"data": ad.Data(_mixed(False))}, "made for another model"),
        ((None, z, z), {}, "None|q"),
    ]
    pairs = [
        (ad.inverse_dynamics, ad.inverse_dynamics_derivatives),
        (ad.forward_dynamics, ad.forward_dynamics_derivatives),
    ]
    for plain, deriv in pairs:
        name = plain.__name__
        for args, kw, pattern in cases:
            want = _message(plain, model, *args, **kw)
            got = _message(deriv, model, *args, **kw)
            assert re.search(pattern, got), (got, pattern)
            assert got == want.replace(name, name + "_derivatives"), (got, want)


def test_forward_derivatives_refuse_light_bodies_inverse_take_them():
    # a body of inertia 1e-9 its m l^2: the mass matrix about the world origin loses it
    b = ad.ModelBuilder()
    _box(b, "arm", 1.0, (0.3, 0.0, 0.0))
    b.add_body("tip", 1.0, [1e-9] * 3, (0.6, 0.0, 0.0))
    b.add_revolute("j0", "ground", "arm", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_revolute("j1", "arm", "tip", (0.5, 0.0, 0.0), (0.0, 1.0, 0.0))
    model = b.finalize()
    z = np.array([0.3, -0.2])
    with pytest.raises(ad.ModelError, match=r"light bodies.*'tip'"):
        ad.forward_dynamics_derivatives(model, z, z, z)
    dq, _ = ad.inverse_dynamics_derivatives(model, z, z, z)
    fq, _ = _fd(model, lambda a, b, c: ad.inverse_dynamics(model, a, b, c), z, z, z)
    assert _rel(dq, fq) <= 1e-7


# the force elements' derivatives are part forcederiv's (add_force_element_derivatives); until
# it is merged, its placeholder refuses models with force elements
needs_force_derivatives = pytest.mark.skipif(
    not hasattr(ad._core, "_force_element_derivatives"),
    reason="the force elements' derivatives (branch i34-forcederiv) are not merged",
)


@needs_force_derivatives
@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_arms_with_their_urdf_joint_friction_equal_finite_differences(robot):
    # the URDFs as they are: <dynamics damping friction> imported as joint friction
    ur5 = common.robot_urdf("ur5")
    robots = next(p for p in ur5.parents if p.name == "robots")
    model = ad.load_urdf(str(robots / EXAMPLE_ROBOTS[robot]))
    _check_model(model, seed=8, states=1)


@needs_force_derivatives
@pytest.mark.parametrize("floating", [False, True])
def test_force_elements_of_every_kind_equal_finite_differences(floating):
    model = _mixed(floating, elements=True)
    rng = np.random.default_rng(21)
    q, qd, qdd = _state(model, rng)
    for t in (0.0, 0.4):
        dq, dqd = ad.inverse_dynamics_derivatives(model, q, qd, qdd, t=t)
        fid = lambda a, b, c: ad.inverse_dynamics(model, a, b, c, t=t)  # noqa: B023, E731
        fq, fqd = _fd(model, fid, q, qd, qdd)
        assert _rel(dq, fq) <= 1e-7, _rel(dq, fq)
        assert _rel(dqd, fqd) <= 1e-7, _rel(dqd, fqd)
        aq, aqd, _ = ad.forward_dynamics_derivatives(model, q, qd, qdd, t=t)
        ffd = lambda a, b, c: ad.forward_dynamics(model, a, b, c, t=t)  # noqa: B023, E731
        gq, gqd = _fd(model, ffd, q, qd, qdd)
        assert _rel(aq, gq) <= 1e-7, _rel(aq, gq)
        assert _rel(aqd, gqd) <= 1e-7, _rel(aqd, gqd)
