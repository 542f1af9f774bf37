"""Light bodies: a link whose own inertia is tiny, down to a point mass, against Pinocchio's
articulated-body algorithm and the joint-space path. The range-space KKT solve forms Gamma^-1 and
lost accuracy like 1/inertia on them (UR5, wrist_1_link inertia x 1e-14: 76 % error, no
message); the dynamics of such a model is now solved in augmented form, and says so."""

import re

import armdyn as ad
import numpy as np
import pytest

pin = pytest.importorskip("pinocchio")
from benchmarks import common  # noqa: E402

UR5 = common.robot_urdf("ur5")
pytestmark = pytest.mark.skipif(UR5 is None, reason="example-robot-data not installed")


def _ur5_light(tmp_path, eps: float, link: str = "wrist_1_link"):
    """The UR5 URDF with a link's rotational inertia scaled by eps (0: a point mass)."""
    text = UR5.read_text()

    def scale(block):
        return re.sub(
            r'(i[xyz]{2})="([^"]+)"',
            lambda m: f'{m.group(1)}="{float(m.group(2)) * eps!r}"',
            block.group(0),
        )

    out = re.sub(rf'<link name="{link}">.*?</link>', scale, text, flags=re.S)
    assert out != text
    path = tmp_path / f"ur5_{link}_{eps:g}.urdf"
    path.write_text(out)
    return path


@pytest.mark.parametrize("eps", [1e-8, 1e-12, 1e-16, 1e-20, 0.0])
def test_forward_dynamics_of_a_light_link_equals_pinocchio(tmp_path, eps):
    path = _ur5_light(tmp_path, eps)
    model = ad.load_urdf(str(path))
    pm = pin.buildModelFromUrdf(str(path))
    pd = pm.createData()
    rng = np.random.default_rng(7)
    worst = {"joint": 0.0, "cartesian": 0.0}
    for _ in range(5):
        q, qd, tau = rng.uniform(-1.5, 1.5, size=(3, 6))
        ref = pin.aba(pm, pd, q, qd, tau)
        for method in worst:
            a = ad.forward_dynamics(model, q, qd, tau, method=method)
            worst[method] = max(worst[method], np.abs(a - ref).max() / np.abs(ref).max())
    # measured: joint <= 2.3e-15, cartesian <= 8.8e-16 (before: cartesian 5e-9 at 1e-8, 0.76 at
    # 1e-14, 1.4e4 at 1e-20, and the point mass refused)
    assert worst["joint"] <= 1e-12 and worst["cartesian"] <= 1e-12


@pytest.mark.parametrize("eps", [1e-8, 1e-12, 1e-16])
def test_a_light_leaf_link_keeps_its_acceleration(tmp_path, eps):
    """wrist_3_link, the leaf, with its inertia scaled (its mass kept, centre of mass on its
    axis): its own axis sees only that inertia. The articulated-body algorithm about each body's
    centre of mass keeps it (about the world origin it lost 6.6e-4 at 1e-12 and failed at
    1e-16); CRBA's composites about the world origin would lose it, so on a model with light
    bodies "joint", "auto" and an explicit "crba" run ABA (documented)."""
    path = _ur5_light(tmp_path, eps, link="wrist_3_link")
    model = ad.load_urdf(str(path))
    cost = ad.dynamics_cost(model)
    assert cost["light"] and cost["joint"] == "aba" and cost["auto"] == "aba"
    pm = pin.buildModelFromUrdf(str(path))
    pd = pm.createData()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd, tau = rng.uniform(-1.0, 1.0, size=(3, 6))
        ref = pin.aba(pm, pd, q, qd, tau)
        for method in ("auto", "joint", "aba", "crba", "cartesian"):
            a = ad.forward_dynamics(model, q, qd, tau, method=method)
            # measured <= 5.4e-16
            assert np.abs(a - ref).max() / np.abs(ref).max() <= 1e-12, method


@pytest.mark.parametrize("eps", [1e-14, 0.0])
def test_cartesian_run_with_a_light_link_follows_the_joint_space_run(tmp_path, eps):
    model = ad.load_urdf(str(_ur5_light(tmp_path, eps)))
    kw = dict(
        q0=[0.3, -1.0, 1.2, -0.5, 0.8, 0.2],
        rtol=1e-10,
        atol=1e-12,
        output_dt=0.05,
        integrator="dop853",
    )
    cart = ad.simulate(model, 0.3, coordinates="cartesian", **kw)
    joint = ad.simulate(model, 0.3, coordinates="joint", **kw)
    assert np.ptp(cart.q[:, 1]) > 0.1  # it falls
    assert np.abs(cart.q - joint.q).max() <= 1e-9  # measured 1.2e-11
    # the switch is stated, naming the link
    assert cart.stats["augmented_solves"] > 0
    assert "wrist_1_link" in cart.stats["augmented_note"]
    assert "augmented" in model.summary()


@pytest.mark.parametrize("coordinates", ["cartesian", "auto"])
def test_point_mass_pendulum_on_the_default_path(coordinates):
    """A point mass on a massless rod (zero rotational inertia) swings as
    phi'' = -(g / L) sin(phi): compared with scipy's integration of that equation, on the
    Cartesian path (its augmented solve) and on the default one (coordinates="auto")."""
    from scipy.integrate import solve_ivp

    g, L, phi0 = 9.81, 0.5, 1.2
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -g))
    b.add_body("bob", 2.0, [0.0, 0.0, 0.0], position=(L * np.sin(phi0), 0.0, -L * np.cos(phi0)))
    b.add_revolute("pivot", "ground", "bob", point=(0, 0, 0), axis=(0, 1, 0))
    model = b.finalize()
    res = ad.simulate(model, 2.0, output_dt=0.1, rtol=1e-11, atol=1e-12, coordinates=coordinates)
    if coordinates == "cartesian":
        assert res.stats["augmented_solves"] > 0
    sol = solve_ivp(
        lambda t, y: [y[1], -g / L * np.sin(y[0])],
        (0, 2.0),
        [phi0, 0.0],
        t_eval=res.t,
        rtol=1e-12,
        atol=1e-12,
    )
    # the joint angle about +y grows as the bob swings from +x towards -z: phi = phi0 - angle
    phi = phi0 - res.q[:, 0]
    assert np.abs(phi - sol.y[0]).max() <= 1e-8
    assert np.ptp(res.total_energy) <= 1e-8 * 2.0 * g * L


def test_a_link_without_inertia_and_no_mass_beyond_it_is_an_error():
    # a point mass on the axis of its own revolute: the joint-space mass matrix is singular, and
    # no path can give the acceleration; finalize refuses the model, naming the joint and body
    # (tests/model/test_massless_and_inertia.py)
    b = ad.ModelBuilder()
    b.add_body("bead", 1.0, [0.0, 0.0, 0.0], position=(0, 0, 0))
    b.add_revolute("spin", "ground", "bead", point=(0, 0, 0), axis=(0, 0, 1))
    with pytest.raises(ad.ModelError, match=r"joint 'spin' carries no inertia.*body 'bead'"):
        b.finalize()


def test_ideal_gears_with_a_light_link_refuse_the_joint_path_and_auto_takes_the_cartesian():
    """With ideal gears the joint-space simulation needs the mass matrix (CRBA about the world
    origin), which would lose a light link's acceleration: refused with the reason, and
    coordinates="auto" takes the Cartesian path, which solves it in augmented form."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("pinion", 0.5, [1e-3, 1e-3, 2e-3], position=(0, 0, 0))
    b.add_body("wheel", 2.0, [8e-3, 8e-3, 1.6e-2], position=(0.3, 0, 0))
    b.add_body("flange", 0.2, [1e-14, 1e-14, 1e-14], position=(0.3, 0.0, -0.1))
    b.add_revolute("pinion_axle", "ground", "pinion", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("wheel_axle", "ground", "wheel", point=(0.3, 0, 0), axis=(0, 0, 1))
    b.add_revolute("flange_pin", "wheel", "flange", point=(0.3, 0.0, -0.1), axis=(1, 0, 0))
    b.add_gear("mesh", "pinion_axle", "wheel_axle", 0.05, 0.2)
    b.add_joint_torque("pinion_axle", 0.3)
    model = b.finalize()
    with pytest.raises(ad.ModelError, match=r"light bodies.*'flange'"):
        ad.simulate(model, 0.1, coordinates="joint")
    res = ad.simulate(model, 0.5, coordinates="auto", output_dt=0.1, rtol=1e-10, atol=1e-12)
    assert res.stats["formulation"].startswith("cartesian")
    assert "flange" in res.stats["augmented_note"]
    # the gear holds: r_a q_a + r_b q_b = 0, the pinion driven by its torque
    q = res.q
    assert np.abs(0.05 * q[:, 0] + 0.2 * q[:, 1]).max() <= 1e-9
    assert q[-1, 0] > 0.1
