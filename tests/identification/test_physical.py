"""armdyn.identification.physical: pseudo-inertia and physical consistency against closed-form
rigid bodies (issue 35)."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.identification import is_physical, physical_violations, pseudo_inertia
from armdyn.identification.physical import parameter_layout, pi10_from_pseudo_inertia

from benchmarks import common


def _pi10(m, com, inertia_about_origin):
    i = np.asarray(inertia_about_origin, dtype=float)
    h = m * np.asarray(com, dtype=float)
    return np.array([m, *h, i[0, 0], i[0, 1], i[1, 1], i[0, 2], i[1, 2], i[2, 2]])


def _shift(m, com, i_c):
    """Inertia about the origin of a body with inertia i_c about its centre of mass com."""
    c = np.asarray(com, dtype=float)
    return np.asarray(i_c) + m * (c @ c * np.eye(3) - np.outer(c, c))


def _box(m, a, b, c, com=(0.0, 0.0, 0.0)):
    i_c = m / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    return _pi10(m, com, _shift(m, com, i_c))


def test_box_pseudo_inertia_is_its_second_moments():
    # a solid box a x b x c about its centre: int x^2 dm = m a^2 / 12, ...; moved to p:
    # [[S + m p p^T, m p], [m p^T, m]]
    m, (a, b, c), p = 2.0, (0.3, 0.2, 0.1), np.array([0.1, -0.05, 0.2])
    j = pseudo_inertia(_box(m, a, b, c, p))
    s = m * np.diag([a * a, b * b, c * c]) / 12.0 + m * np.outer(p, p)
    expected = np.block([[s, m * p[:, None]], [m * p[None, :], np.array([[m]])]])
    np.testing.assert_allclose(j, expected, rtol=0, atol=1e-15)
    np.testing.assert_allclose(pi10_from_pseudo_inertia(j), _box(m, a, b, c, p), atol=1e-15)


def test_point_cloud_pseudo_inertia_is_the_sum_of_its_points():
    # an independent reference: J = sum_i m_i [x_i; 1][x_i; 1]^T for point masses m_i at x_i
    rng = np.random.default_rng(3)
    ms, xs = rng.uniform(0.1, 1.0, 20), rng.normal(size=(20, 3))
    m = ms.sum()
    i_o = sum(mi * (x @ x * np.eye(3) - np.outer(x, x)) for mi, x in zip(ms, xs, strict=True))
    pi10 = _pi10(m, (ms[:, None] * xs).sum(0) / m, i_o)
    xh = np.hstack([xs, np.ones((20, 1))])
    ref = (ms[:, None, None] * xh[:, :, None] * xh[:, None, :]).sum(0)
    np.testing.assert_allclose(pseudo_inertia(pi10), ref, rtol=1e-13, atol=1e-13)


def _two_links():
    b = ad.ModelBuilder()
    b.add_body("upper", 1.0, np.diag([0.01, 0.02, 0.025]), position=(0.0, 0.0, -0.5))
    b.add_body("lower", 1.0, np.diag([0.01, 0.02, 0.025]), position=(0.0, 0.0, -1.5))
    b.add_revolute("shoulder", "ground", "upper", (0, 0, 0), (0, 1, 0))
    b.add_revolute("elbow", "upper", "lower", (0, 0, -1.0), (0, 1, 0))
    return b.finalize()


def _model_pi(upper, lower, coords=(0.1, 0.2, 0.0, 0.01, 0.1, 0.2, 0.0, 0.01)):
    return np.concatenate([upper, lower, coords])


def test_layout_of_a_builder_model():
    model = _two_links()
    bodies, coords = parameter_layout(list(ad.dynamic_parameter_names(model)))
    assert bodies == ["upper", "lower"]
    assert coords == ["shoulder", "elbow"]
    assert ad.dynamic_parameters(model).size == 2 * 10 + 2 * 4


@pytest.mark.parametrize(
    "body",
    [
        _box(2.0, 0.3, 0.2, 0.1, (0.05, 0.0, 0.1)),
        # a thin rod along x: I_c = diag(0, m L^2/12, m L^2/12), J = diag(m L^2/12, 0, 0, m)
        _pi10(1.5, (0.0, 0.0, 0.3), _shift(1.5, (0.0, 0.0, 0.3), np.diag([0.0, 0.125, 0.125]))),
        # a point mass at p: J = m [p; 1][p; 1]^T, rank one
        _pi10(0.7, (0.1, 0.2, -0.3), _shift(0.7, (0.1, 0.2, -0.3), np.zeros((3, 3)))),
    ],
    ids=["box", "rod", "point-mass"],
)
def test_real_bodies_are_physical(body):
    model = _two_links()
    assert np.linalg.eigvalsh(pseudo_inertia(body))[0] >= -1e-15
    pi = _model_pi(body, _box(1.0, 0.1, 0.1, 0.4))
    assert physical_violations(model, pi) == []
    assert is_physical(model, pi)


def test_triangle_inequality_violator_named():
    model = _two_links()
    # principal moments about the centre of mass 1, 1, 3: 1 + 1 < 3; Sigma = 2.5 - I has -0.5
    bad = _pi10(2.0, (0.0, 0.1, 0.0), _shift(2.0, (0.0, 0.1, 0.0), np.diag([1.0, 1.0, 3.0])))
    assert np.linalg.eigvalsh(pseudo_inertia(bad))[0] == pytest.approx(-0.5, rel=1e-12)
    v = physical_violations(model, _model_pi(_box(1.0, 0.1, 0.1, 0.4), bad))
    assert len(v) == 2
    assert v[0].startswith("lower: triangle inequality fails") and "1 + 1 < 3" in v[0]
    assert v[1].startswith("lower: pseudo-inertia not positive semidefinite (eigenvalue -0.5")
    assert not is_physical(model, _model_pi(_box(1.0, 0.1, 0.1, 0.4), bad))


def test_mass_and_friction_violations_named():
    model = _two_links()
    neg = _box(1.0, 0.1, 0.1, 0.4)
    neg[0] = -1.0
    coords = (0.1, -0.2, 5.0, 0.01, -0.1, 0.2, -3.0, -0.01)  # offsets may be negative
    v = physical_violations(model, _model_pi(_box(1.0, 0.1, 0.1, 0.4), neg, coords))
    assert v[0] == "lower: mass -1 kg is not positive"
    assert "lower: pseudo-inertia not positive semidefinite" in v[1]
    assert v[2:] == [
        "shoulder.fc = -0.2 is negative",
        "elbow.fv = -0.1 is negative",
        "elbow.Ia = -0.01 is negative",
    ]


def test_bad_pi_refused():
    model = _two_links()
    with pytest.raises(ad.ModelError, match=r"pi must have shape \(28,\)"):
        physical_violations(model, np.zeros(27))
    pi = _model_pi(_box(1.0, 0.1, 0.1, 0.4), _box(1.0, 0.1, 0.1, 0.4))
    pi[11] = np.nan
    with pytest.raises(ad.ModelError, match=r"pi\[11\] \(lower.mcx\) is not finite"):
        is_physical(model, pi)
    with pytest.raises(ad.ModelError, match=r"pi10 must have shape \(10,\)"):
        pseudo_inertia(np.zeros(9))


@pytest.mark.skipif(common.robots_dir() is None, reason="example-robot-data not installed")
@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_urdf_models_are_physical(name):
    model = ad.load_urdf(str(common.robot_urdf(name)))
    assert physical_violations(model, ad.dynamic_parameters(model)) == []
