"""Analytic derivatives of the force elements' generalised force (issue 34, part forcederiv).

``armdyn._core._force_element_derivatives(model, q, qd, t)`` returns dF/dq and dF/dqd of

    F(q, qd, t) = inverse_dynamics(model without the elements) - inverse_dynamics(model with them)

(the elements' J^T eta + Q), q-derivatives along the rates: a coordinate's own, a floating base's
along qd's base-frame velocity (its origin moved along its frame's axes, its frame turned about
them: Pinocchio's free-flyer tangent). The reference is an independent one: central finite
differences (Richardson-extrapolated) of F computed through the public ``inverse_dynamics`` on
two models built with ModelBuilder, identical but for the elements. Each element type on a
branched tree of every joint type, on a fixed and on a floating base, to 1e-7 relative; and
the one-sided choices at the nonsmooth points (a motor's torque limit, a gear pair's backlash
edge and Hunt-Crossley clamp), against one-sided differences from the side the law evaluates.
"""

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core
from conftest import G, random_inertia, random_quat, random_unit, rel_err, tol
from oracles.numpy_rne import quat_exp, quat_mul

ELEMENTS = ("loads", "springs", "coordinate", "gears")
SINE = ad.profiles.sine(0.7, 1.3, 0.2, 0.4)


def _add_elements(b, kinds, floating):
    base = "base" if floating else "ground"
    if "loads" in kinds:
        # a force at a point and a torque, scaled by a profile in t; one unscaled, on a leaf
        b.add_body_force("b2", (3.0, -2.0, 1.5), (0.4, 0.1, -0.3), (0.2, -0.1, 0.3), SINE)
        b.add_body_force("b4", force=(-1.0, 2.5, 4.0), torque=(0.2, -0.5, 0.1))
        b.add_body_force("b0", force=(0.5, 0.0, -2.0), point=(0.1, 0.4, -0.2))
        if floating:
            b.add_body_force("base", (1.0, 2.0, -3.0), (0.3, -0.2, 0.5), (0.3, 0.1, 0.2), SINE)
    if "springs" in kinds:
        # across two branches, to ground, along one chain, to the floating base
        b.add_spring_damper("s1", "b2", (0.4, 0.2, 0.1), "b4", (-0.3, 0.5, 0.2), 80.0, 3.0, 0.4)
        b.add_spring_damper("s2", "ground", (1.0, -1.0, 0.5), "b5", (0.2, 0.3, -0.4), 50.0, 2.0)
        b.add_spring_damper("s3", "b0", (0.1, -0.4, 0.0), "b2", (0.5, 0.1, 0.6), 120.0, 0.0, 0.2)
        b.add_spring_damper("s4", base, (-0.5, 0.3, 0.9), "b1", (0.0, 0.0, 0.0), 30.0, 5.0, 1.5)
        # b3 hangs on b1 by a fixed joint: the chains meet at a joint without coordinates
        b.add_spring_damper("s5", "b3", (0.3, -0.2, 0.1), "b4", (0.6, 0.4, -0.3), 70.0, 4.0, 0.1)
    if "coordinate" in kinds:
        b.add_joint_spring_damper("j0", stiffness=30.0, damping=2.0, rest=0.3)
        b.add_joint_spring_damper("j1", stiffness=50.0, damping=1.0, rest=-0.1, coord=1)
        b.add_joint_friction("j2", viscous=3.0, coulomb=1.5, smoothing_velocity=0.5)
        b.add_joint_friction("j1", coulomb=0.8, smoothing_velocity=0.3, coord=0)
        b.add_motor("j4", SINE, kp=80.0, kd=4.0, torque_limit=1e3, feedforward=2.0, ki=5.0)
        b.add_motor("j5", SINE, kp=40.0, kd=3.0, torque_limit=1e3)
        b.add_joint_torque("j1", SINE, coord=0)
    if "gears" in kinds:
        b.add_gear_pair("g", "j0", "j5", 0.3, 0.2, 0.05, 800.0, 1.5, 0.4)


def branched_tree(kinds=(), floating=False, seed=7, coupled=False):
    """A branched tree of every joint-space joint type (random points, axes, full inertias) on
    ground or on a floating base, with the force elements `kinds` (a subset of ELEMENTS).
    coupled: j5 follows j0 (a coupling) and j4 and j2 carry actuators (their rotors' couplings;
    with "coordinate" in kinds, their motor-side friction on the rotors' coordinates)."""
    rng = np.random.default_rng(seed)
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    names = ["base"] if floating else []
    names += [f"b{i}" for i in range(6)]
    for n in names:
        m = rng.uniform(0.5, 3.0)
        b.add_body(
            n,
            m,
            random_inertia(rng, m),
            position=rng.normal(scale=0.6, size=3),
            orientation=random_quat(rng),
        )
    root = "ground"
    if floating:
        b.add_free("free", "base", origin=(0.1, -0.2, 0.3))
        root = "base"
    # root - b0 - b1 - b2, b1 - b3 - b4 (branch), root - b5
    tree = [
        ("j0", root, "b0", "revolute"),
        ("j1", "b0", "b1", "cylindrical"),
        ("j2", "b1", "b2", "prismatic"),
        ("j3", "b1", "b3", "fixed"),
        ("j4", "b3", "b4", "revolute"),
        ("j5", root, "b5", "revolute"),
    ]
    for name, parent, child, kind in tree:
        point = rng.normal(scale=0.5, size=3)
        if kind == "fixed":
            b.add_fixed(name, parent, child, point)
        else:
            getattr(b, f"add_{kind}")(name, parent, child, point, random_unit(rng))
    if coupled:
        b.add_coupling("c", "j5", "j0", 0.5, 0.1)
        fric = 1.0 if "coordinate" in kinds else 0.0
        b.add_actuator("j4", 30.0, 2e-4, friction_viscous=1e-3 * fric, gyroscopic=True)
        b.add_actuator(
            "j2", 200.0, 1e-5, friction_viscous=2e-5 * fric, friction_coulomb=0.01 * fric
        )
    _add_elements(b, kinds, floating)
    return b.finalize()


def _retract(model, q, k, h):
    """q moved by h along rate k: a coordinate's own step; a floating base's origin along its
    frame's axis k, or its frame turned about its axis k - 3 (the base-frame tangent)."""
    q = np.array(q, dtype=float)
    if model.n_coords == model.n_dofs:
        q[k] += h
        return q
    if k >= 6:
        q[k + 1] += h
        return q
    e = q[3:7]
    if k < 3:
        R = _rot(e)
        q[:3] += h * R[:, k]
    else:
        w = np.zeros(3)
        w[k - 3] = h
        q[3:7] = quat_mul(e, quat_exp(w))
    return q


def _rot(e):
    w, x, y, z = e
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def element_force(bare, full, q, qd, t):
    """F = inverse_dynamics(bare) - inverse_dynamics(full) at qdd = 0, one row per state."""
    q, qd = np.atleast_2d(q), np.atleast_2d(qd)
    qdd = np.zeros_like(qd)
    return ad.inverse_dynamics(bare, q, qd, qdd, t) - ad.inverse_dynamics(full, q, qd, qdd, t)


def finite_differences(bare, full, q, qd, t, h=1e-3, side=0):
    """(dF/dq, dF/dqd) by differences of F: central, Richardson-extrapolated (side 0), or
    one-sided forward (side +1) / backward (side -1) with step h."""
    n = full.n_dofs
    steps = [h, h / 2] if side == 0 else [h]
    qs, qds = [], []
    for s in steps:
        for k in range(n):
            for sign in (1.0, -1.0) if side == 0 else (float(side), 0.0):
                qs.append(_retract(full, q, k, sign * s))
                qds.append(qd)
                qs.append(q)
                qds.append(qd + sign * s * np.eye(n)[k])
    F = element_force(bare, full, np.array(qs), np.array(qds), t)
    F = F.reshape(len(steps), n, 2, 2, n)  # step, k, sign, (q, qd), row
    if side == 0:
        D = (F[:, :, 0] - F[:, :, 1]) / (2 * np.array(steps))[:, None, None, None]
        D = (4.0 * D[1] - D[0]) / 3.0
    else:
        D = side * (F[0, :, 0] - F[0, :, 1]) / h
    return D[:, 0].T, D[:, 1].T  # rows: F's entries, columns: k


def _random_state(model, rng, floating):
    nc = model.n_coords - (7 if floating else 0)
    q = rng.uniform(-1.2, 1.2, size=nc)
    if floating:
        q = np.concatenate([rng.normal(scale=0.5, size=3), random_quat(rng), q])
    return q, rng.normal(size=model.n_dofs)


def _check(bare, full, q, qd, t, h=1e-3, floor=1e-300):
    """The analytic derivatives at one state against finite differences; floor: the scale of
    the comparison where both are zero (a saturated motor's)."""
    dq, dqd = _core._force_element_derivatives(full, q, qd, t)
    fq, fqd = finite_differences(bare, full, q, qd, t, h)
    assert dq.shape == dqd.shape == (full.n_dofs, full.n_dofs)
    # relative to the whole Jacobian [dF/dq, dF/dqd] (one of them may be zero: loads)
    err = rel_err(np.hstack([dq, dqd]), np.hstack([fq, fqd]), floor)
    assert err <= tol(1e-7), err
    return dq, dqd


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("kind", ELEMENTS)
def test_element_derivatives_equal_finite_differences(kind, floating, rng):
    bare = branched_tree(floating=floating)
    full = branched_tree((kind,), floating=floating)
    assert full.n_dofs == bare.n_dofs == (12 if floating else 6)
    seen = np.zeros((2, full.n_dofs, full.n_dofs), dtype=bool)
    for _ in range(4):
        q, qd = _random_state(full, rng, floating)
        dq, dqd = _check(bare, full, q, qd, rng.uniform(0.0, 2.0))
        seen |= np.abs(np.array([dq, dqd])) > 1e-9
    # the elements reach what they should: every loaded or sprung chain, both base blocks
    if kind in ("loads", "springs"):
        assert seen[0].sum() > full.n_dofs * 2
    if floating and kind in ("loads", "springs"):
        assert seen[0][:6, :6].any() and seen[0][6:, :6].any()
    if kind == "springs":
        assert seen[1].sum() > full.n_dofs * 2  # the dampers
    if kind in ("coordinate", "gears"):
        off = 6 if floating else 0
        assert seen[1][off:, off:].any() and not seen[:, :off].any()


def test_all_elements_together_on_a_floating_base(rng):
    bare = branched_tree(floating=True)
    full = branched_tree(ELEMENTS, floating=True)
    for _ in range(2):
        q, qd = _random_state(full, rng, True)
        _check(bare, full, q, qd, 0.7)


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_coupled_actuated_model_in_independent_coordinates(floating, rng):
    """A coupling (j5 follows j0) and two actuators (rotor bodies on follower coordinates, their
    motor-side friction there): the derivatives in the independent coordinates inverse_dynamics
    takes, G^T dF G, every element acting, some on followers (j5's spring, motor and gear pair
    with j0, the rotors' friction, the spring to b5)."""
    kinds = ("loads", "springs", "coordinate")
    bare = branched_tree(floating=floating, coupled=True)
    full = branched_tree(kinds, floating=floating, coupled=True)
    assert full.n_dofs == (11 if floating else 5)
    for _ in range(2):
        q, qd = _random_state(full, rng, floating)
        _check(bare, full, q, qd, 0.3)


def test_gear_pair_both_mesh_directions(rng):
    """The mesh displacement s = r_a q_a + r_b q_b beyond the backlash on either side (the
    force pushes back either way), with Hunt-Crossley damping; and inside the gap, none."""
    bare = branched_tree()
    full = branched_tree(("gears",))
    q, qd = _random_state(full, rng, False)
    i0, i5 = full.coord_names.index("j0"), full.coord_names.index("j5")
    for s, sd in [(0.2, 0.3), (-0.2, 0.3), (0.2, -0.1), (-0.3, -0.4), (0.01, 0.5)]:
        q[i0], q[i5] = s / 0.3, 0.0
        qd[i0], qd[i5] = sd / 0.3, 0.0
        dq, dqd = _check(bare, full, q, qd, 0.0)
        gap = abs(s) <= 0.025
        assert (dq[i0, i0] == 0.0) == gap and (dqd[i5, i0] == 0.0) == gap


def _one_motor(limit, kp=2.0, kd=0.5, ref=0.75):
    def build(with_motor):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
        b.add_body("arm", 1.0, np.diag([0.01, 0.02, 0.02]), position=(0.3, 0.0, 0.0))
        b.add_revolute("j", "ground", "arm", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
        if with_motor:
            b.add_motor("j", ref, kp=kp, kd=kd, torque_limit=limit)
        return b.finalize()

    return build(False), build(True)


def test_motor_saturation_one_sided_choice():
    """At the torque limit exactly (u = kp (0.75 - 0.25) = 1 = limit) the derivative is the
    linear band's (-kp, -kd): the one-sided difference into the band, not the saturated side's
    zero. Inside the band and in saturation, central differences."""
    bare, full = _one_motor(limit=1.0)
    q, qd = np.array([0.25]), np.array([0.0])
    dq, dqd = _core._force_element_derivatives(full, q, qd)
    assert dq[0, 0] == -2.0 and dqd[0, 0] == -0.5
    # q + h, qd + h reduce u below the limit: the band's side
    fq, fqd = finite_differences(bare, full, q, qd, 0.0, h=1e-6, side=+1)
    assert rel_err(dq, fq) <= tol(1e-7) and rel_err(dqd, fqd) <= tol(1e-7)
    bq, bqd = finite_differences(bare, full, q, qd, 0.0, h=1e-6, side=-1)
    assert np.abs(bq).max() < 1e-9 and np.abs(bqd).max() < 1e-9  # the saturated side
    # in the band and saturated (either sign): central differences (zero to 1e-7 of kp)
    for qv, slope in [(0.4, -2.0), (-1.0, 0.0), (2.5, 0.0)]:
        q = np.array([qv])
        dq, dqd = _check(bare, full, q, qd, 0.0, floor=2.0)
        assert dq[0, 0] == slope


def test_backlash_edge_one_sided_choice():
    """At the backlash edge exactly (|s| = backlash / 2, s = 0.5 * 0.5 + 0.25 * 0 = 0.25) the
    derivative is the gap's (zero): the one-sided difference into the gap; the contact side's
    slope (exponent 1: k r_a^2) differs."""

    def build(with_pair):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
        for n, x in (("a", 0.0), ("b", 1.0)):
            b.add_body(n, 1.0, np.diag([0.01, 0.01, 0.02]), position=(x, 0.0, 0.0))
            b.add_revolute(f"j{n}", "ground", n, (x, 0.0, 0.0), (0.0, 0.0, 1.0))
        if with_pair:
            b.add_gear_pair("g", "ja", "jb", 0.5, 0.25, 0.5, 400.0, 1.0, 0.2)
        return b.finalize()

    bare, full = build(False), build(True)
    q, qd = np.array([0.5, 0.0]), np.array([0.3, -0.2])
    dq, dqd = _core._force_element_derivatives(full, q, qd)
    assert not dq.any() and not dqd.any()
    # q_a - h opens the gap; q_a + h closes it (its column: -k r_a (r_a, r_b))
    bq, _ = finite_differences(bare, full, q, qd, 0.0, h=1e-7, side=-1)
    fq, _ = finite_differences(bare, full, q, qd, 0.0, h=1e-7, side=+1)
    assert np.abs(bq[:, 0]).max() < 1e-9
    rate = 0.5 * qd[0] + 0.25 * qd[1]
    contact = -400.0 * 0.5 * np.array([0.5, 0.25]) * (1.0 + 0.2 * rate)
    assert fq[:, 0] == pytest.approx(contact, rel=1e-6)
    # in contact: the contact law's slopes, central differences
    for qa in (0.7, -0.9):
        _check(bare, full, np.array([qa, 0.1]), qd, 0.0)


def test_hunt_crossley_clamp():
    """Separating fast, 1 + alpha d' < 0: the force is clamped at zero, and so are its slopes;
    just inside the contact law, its slopes; at the clamp's start, the contact law's."""

    def build(with_pair):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
        for n, x in (("a", 0.0), ("b", 1.0)):
            b.add_body(n, 1.0, np.diag([0.01, 0.01, 0.02]), position=(x, 0.0, 0.0))
            b.add_revolute(f"j{n}", "ground", n, (x, 0.0, 0.0), (0.0, 0.0, 1.0))
        if with_pair:
            b.add_gear_pair("g", "ja", "jb", 0.5, 0.25, 0.1, 400.0, 1.5, 2.0)
        return b.finalize()

    bare, full = build(False), build(True)
    q = np.array([0.4, 0.0])  # s = 0.2, penetration 0.15
    for sd, clamped in [(-0.6, True), (-0.4, False), (0.5, False)]:
        qd = np.array([sd / 0.5, 0.0])
        dq, dqd = _check(bare, full, q, qd, 0.0)
        assert (not dq.any() and not dqd.any()) == clamped
    # where the clamp starts, 1 + alpha s' = 1 + 2 (0.5 * -1) = 0 exactly: the contact law's
    # slopes (the one-sided difference towards contact), not the clamped side's zero
    qd = np.array([-1.0, 0.0])
    dq, dqd = _core._force_element_derivatives(full, q, qd)
    _, fqd = finite_differences(bare, full, q, qd, 0.0, h=1e-7, side=+1)
    _, bqd = finite_differences(bare, full, q, qd, 0.0, h=1e-7, side=-1)
    assert not dq.any() and dqd[0, 0] < 0 and not bqd.any()
    assert rel_err(dqd, fqd) <= 1e-6


def test_coulomb_at_rest_is_smooth():
    """The smoothed Coulomb friction -F_c tanh(qd / v_s) at qd = 0: slope -F_c / v_s, both sides
    alike (central differences)."""

    def build(with_friction):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
        b.add_body("arm", 1.0, np.diag([0.01, 0.02, 0.02]), position=(0.3, 0.0, 0.0))
        b.add_revolute("j", "ground", "arm", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
        if with_friction:
            b.add_joint_friction("j", viscous=0.2, coulomb=1.5, smoothing_velocity=0.01)
        return b.finalize()

    bare, full = build(False), build(True)
    dq, dqd = _check(bare, full, np.array([0.3]), np.array([0.0]), 0.0, h=1e-5)
    assert dq[0, 0] == 0.0 and dqd[0, 0] == pytest.approx(-0.2 - 150.0, rel=1e-15)


def test_bad_input():
    full = branched_tree(("loads",), floating=True)
    q, qd = _random_state(full, np.random.default_rng(1), True)
    f = _core._force_element_derivatives
    with pytest.raises(ad.ModelError, match="q: expected shape"):
        f(full, q[:-1], qd)
    with pytest.raises(ad.ModelError, match="qd contains NaN"):
        f(full, q, np.full_like(qd, np.nan))
    with pytest.raises(ad.ModelError, match="quaternion"):
        f(full, np.concatenate([q[:3], 2 * q[3:7], q[7:]]), qd)
    with pytest.raises(ad.ModelError, match="t is not finite"):
        f(full, q, qd, np.inf)
    with pytest.raises(ad.ModelError, match=r"model must be an armdyn\.Model"):
        f(None, q, qd)


def test_failing_elements_are_named():
    """A load's profile that fails or is not finite, a motor's reference that fails, a
    spring-damper of zero length: SolverError naming the element, as inverse_dynamics."""

    def build(element):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
        b.add_body("slider", 1.0, np.diag([0.01, 0.02, 0.02]))
        b.add_prismatic("j", "ground", "slider", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
        element(b)
        return b.finalize()

    def fails(t):
        raise ValueError("no value")

    cases = [
        (lambda b: b.add_body_force("slider", (1.0, 0, 0), profile=fails), "load on body 'slider'"),
        (
            lambda b: b.add_body_force("slider", (1.0, 0, 0), profile=lambda t: (np.nan, 0, 0)),
            "load on body 'slider'",
        ),
        (lambda b: b.add_motor("j", fails, kp=1.0, kd=0.1), "joint coordinate 'j'"),
        (
            lambda b: b.add_spring_damper("s", "ground", (1.0, 0, 0), "slider", (0, 0, 0), 5.0),
            "spring-damper 's'",
        ),
    ]
    q, qd = np.array([1.0]), np.array([0.2])
    for element, name in cases:
        model = build(element)
        with pytest.raises(ad.SolverError, match=name):
            ad.inverse_dynamics(model, q, qd, [0.0])
        with pytest.raises(ad.SolverError, match=name):
            _core._force_element_derivatives(model, q, qd)


@pytest.mark.parametrize(
    "rel, fixed_base",
    [("panda_description/urdf/panda.urdf", True), ("solo_description/robots/solo12.urdf", False)],
    ids=["panda", "solo12"],
)
def test_urdf_joint_friction(rel, fixed_base, rng):
    """The URDF's <dynamics damping friction> (joint friction) on the Panda (its mimicking
    fingers: a coupled model) and on a floating solo12 (given damping and friction here: its
    file has zeros); the bare model is the same file without its <dynamics> tags."""
    import re

    from benchmarks import common

    ur5 = common.robot_urdf("ur5")
    assert ur5 is not None, "example-robot-data is part of the test extra"
    robots = next(p for p in ur5.parents if p.name == "robots")
    xml = (robots / rel).read_text()
    xml = xml.replace('damping="0.0" friction="0.0"', 'damping="0.05" friction="0.2"')
    bare = ad.load_urdf(re.sub(r"<dynamics[^>]*/>", "", xml), fixed_base=fixed_base)
    full = ad.load_urdf(xml, fixed_base=fixed_base)
    assert full.n_dofs == bare.n_dofs == (8 if fixed_base else 18)
    vs = _core.URDF_COULOMB_SMOOTHING
    for _ in range(2):
        q, qd = _random_state(full, rng, not fixed_base)
        qd[rng.uniform(size=qd.size) < 0.3] = 0.2 * vs  # inside the Coulomb smoothing too
        dq, dqd = _check(bare, full, q, qd, 0.0, h=1e-3 * vs)
        assert not dq.any() and np.abs(np.diag(dqd)[6 if not fixed_base else 0 :]).min() > 0


def random_tree(seed, floating, with_elements):
    """A random tree (each body on a random earlier one or the root, random joint types,
    fixed joints included) with loads and spring-dampers between random bodies (ground too)."""
    rng = np.random.default_rng(seed)
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    names = [f"r{i}" for i in range(7)]
    for n in names:
        m = rng.uniform(0.5, 2.0)
        b.add_body(n, m, random_inertia(rng, m), rng.normal(scale=0.6, size=3), random_quat(rng))
    if floating:
        b.add_free("free", "r0")
    else:
        b.add_revolute("j0", "ground", "r0", rng.normal(scale=0.3, size=3), random_unit(rng))
    for i in range(1, len(names)):
        parent = names[rng.integers(0, i)]
        kind = ("revolute", "prismatic", "cylindrical", "fixed")[rng.integers(0, 4)]
        point = rng.normal(scale=0.5, size=3)
        if kind == "fixed":
            b.add_fixed(f"j{i}", parent, names[i], point)
        else:
            getattr(b, f"add_{kind}")(f"j{i}", parent, names[i], point, random_unit(rng))
    # the elements' random draws happen either way: the two models share their tree
    loads = [(names[rng.integers(0, 7)], rng.normal(size=(3, 3))) for _ in range(3)]
    pairs = [rng.choice(["ground", *names], size=2, replace=False) for _ in range(4)]
    ends = rng.normal(scale=0.5, size=(4, 2, 3))
    if with_elements:
        for body, (f, tau, p) in loads:
            b.add_body_force(body, f, tau, p, SINE)
        for i, ((a, c), (pa, pc)) in enumerate(zip(pairs, ends, strict=True)):
            b.add_spring_damper(f"s{i}", a, pa, c, pc, 60.0, 2.0, 0.3)
    return b.finalize()


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_random_trees(floating, rng):
    """Loads and spring-dampers on random tree shapes (chains meeting anywhere, at fixed
    joints too, or only at ground)."""
    for seed in range(6):
        bare, full = random_tree(seed, floating, False), random_tree(seed, floating, True)
        q, qd = _random_state(full, rng, floating)
        _check(bare, full, q, qd, 0.4)
