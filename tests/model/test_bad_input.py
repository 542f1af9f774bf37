"""Bad input: one test per case, checking the exception type and that the message names the
culprit (matched loosely: the offending name, not the wording).

Exception contract (docs/api.md): ad.ModelError (a ValueError) for model and array problems,
ad.UrdfError (a ModelError) for URDF problems, ad.SolverError (a RuntimeError) for numerical
failures. Bad simulate() arguments are only required to be ValueErrors. Every failed builder call
must leave the builder unchanged.
"""

import armdyn as ad
import numpy as np
import pytest
from conftest import GRAVITY, name_regex, simple_pendulum

I3 = np.diag([0.01, 0.02, 0.025])


def builder_with_body(name="body1"):
    b = ad.ModelBuilder(gravity=GRAVITY)
    b.add_body(name, 1.0, I3, position=(0.0, 0.0, -0.5))
    return b


def connected_builder():
    b = builder_with_body("body1")
    b.add_revolute("hinge", "ground", "body1", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    return b


def test_exception_hierarchy():
    assert issubclass(ad.ModelError, ValueError)
    assert issubclass(ad.UrdfError, ad.ModelError)
    assert issubclass(ad.SolverError, RuntimeError)


# ----------------------------------------------------------------------------------------------
# bodies
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("mass", [-1.0, float("nan"), float("inf")], ids=["negative", "nan", "inf"])
def test_bad_mass(mass):
    # (mass 0 is a massless body: tests/model/test_massless_and_inertia.py)
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match="heavy_link"):
        b.add_body("heavy_link", mass, I3)


@pytest.mark.parametrize("bad", [np.inf, -np.inf, np.nan])
def test_non_finite_position(bad):
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match="lost_link"):
        b.add_body("lost_link", 1.0, I3, position=(0.0, bad, 0.0))


def test_non_symmetric_inertia():
    b = ad.ModelBuilder()
    inertia = np.array([[0.1, 0.01, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]])
    with pytest.raises(ad.ModelError, match="skew_link"):
        b.add_body("skew_link", 1.0, inertia)


@pytest.mark.parametrize(
    "inertia",
    [
        np.diag([0.1, 0.1, -0.05]),
        np.array([[0.1, 0.2, 0], [0.2, 0.1, 0], [0, 0, 0.1]]),
        np.diag([0.1, -1e-9, 0.1]),
    ],
    ids=["negative_eig", "indefinite_offdiag", "slightly_negative"],
)
def test_inertia_not_positive_semidefinite(inertia):
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match=r"flat_link.*positive semidefinite"):
        b.add_body("flat_link", 1.0, inertia)


def test_thin_rod_and_point_mass_inertias_are_physical():
    # a zero principal moment is a thin rod (about its axis) and three are a point mass: both
    # are accepted (light bodies: tests/algorithm/test_light_bodies.py simulates them)
    b = ad.ModelBuilder()
    assert b.add_body("rod", 1.0, np.diag([0.1, 0.0, 0.1])) == 0
    assert b.add_body("point", 1.0, np.zeros((3, 3))) == 1


def test_inertia_triangle_inequality():
    # positive-definite, but I1 + I2 < I3 (no physical mass distribution has it)
    b = ad.ModelBuilder()
    r = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # rotated: still caught
    for inertia in (np.diag([0.1, 0.1, 0.3]), r @ np.diag([0.1, 0.1, 0.3]) @ r.T):
        with pytest.raises(ad.ModelError, match="weird_link"):
            b.add_body("weird_link", 1.0, inertia)


def test_non_unit_quaternion():
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match="spun_link"):
        b.add_body("spun_link", 1.0, I3, orientation=(2.0, 0.0, 0.0, 0.0))


def test_nan_quaternion():
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match="spun_link"):
        b.add_body("spun_link", 1.0, I3, orientation=(np.nan, 0.0, 0.0, 1.0))


def test_duplicate_body_name():
    b = builder_with_body("dup_body")
    with pytest.raises(ad.ModelError, match="dup_body"):
        b.add_body("dup_body", 2.0, I3)


def test_ground_is_reserved():
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match="ground"):
        b.add_body("ground", 1.0, I3)


@pytest.mark.parametrize("shape", [(2, 2), (3, 2), (4,), (2,)])
def test_inertia_wrong_shape(shape):
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match=name_regex("shape_link", "inertia")):
        b.add_body("shape_link", 1.0, np.full(shape, 0.1))


@pytest.mark.parametrize(
    "arg, value",
    [("position", (0.0, 1.0)), ("orientation", (1.0, 0.0, 0.0)), ("position", np.zeros((3, 3)))],
)
def test_pose_wrong_shape(arg, value):
    b = ad.ModelBuilder()
    with pytest.raises(ad.ModelError, match=name_regex("shape_link", arg)):
        b.add_body("shape_link", 1.0, I3, **{arg: value})


# ----------------------------------------------------------------------------------------------
# joints and drives
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["revolute", "prismatic", "cylindrical"])
def test_zero_length_axis(kind):
    b = builder_with_body()
    add = getattr(b, f"add_{kind}")
    with pytest.raises(ad.ModelError, match="axisless"):
        add("axisless", "ground", "body1", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def test_universal_axes_not_perpendicular():
    b = builder_with_body()
    with pytest.raises(ad.ModelError, match="cardan"):
        b.add_universal(
            "cardan", "ground", "body1", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0)
        )


def test_unknown_body_in_joint():
    b = builder_with_body()
    with pytest.raises(ad.ModelError, match="no_such_body"):
        b.add_revolute("hinge", "ground", "no_such_body", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    with pytest.raises(ad.ModelError, match="no_such_body"):
        b.add_spherical("ball", "no_such_body", "body1", (0.0, 0.0, 0.0))


def test_duplicate_joint_name():
    b = builder_with_body()
    b.add_body("body2", 1.0, I3, position=(0.0, 0.0, -1.0))
    b.add_revolute("dup_joint", "ground", "body1", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    with pytest.raises(ad.ModelError, match="dup_joint"):
        b.add_revolute("dup_joint", "body1", "body2", (0.0, 0.0, -0.7), (0.0, 1.0, 0.0))


def test_joint_linking_body_to_itself():
    b = builder_with_body("lonely_body")
    with pytest.raises(ad.ModelError, match=name_regex("self_joint", "lonely_body")):
        b.add_revolute("self_joint", "lonely_body", "lonely_body", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))


def test_body_not_connected_to_ground():
    b = connected_builder()
    b.add_body("floating_body", 1.0, I3, position=(1.0, 0.0, 0.0))
    with pytest.raises(ad.ModelError, match="floating_body"):
        b.finalize()
    # the builder is unchanged by the failed finalize and can be completed
    b.add_spherical("catch", "body1", "floating_body", (1.0, 0.0, 0.0))
    model = b.finalize()
    assert model.nb == 2


def test_drive_on_spherical_joint():
    b = builder_with_body()
    b.add_spherical("ball_joint", "ground", "body1", (0.0, 0.0, 0.0))
    with pytest.raises(ad.ModelError, match="ball_joint"):
        b.add_drive("ball_joint", ad.profiles.constant(0.0))


def test_drive_on_unknown_joint():
    b = connected_builder()
    with pytest.raises(ad.ModelError, match="no_such_joint"):
        b.add_drive("no_such_joint", ad.profiles.constant(0.0))


def test_drive_coordinate_out_of_range():
    b = connected_builder()
    with pytest.raises(ad.ModelError, match="hinge"):
        b.add_drive("hinge", ad.profiles.constant(0.0), coord=1)


# ----------------------------------------------------------------------------------------------
# a failed call leaves the builder unchanged
# ----------------------------------------------------------------------------------------------


def test_failed_calls_leave_builder_unchanged():
    b = connected_builder()
    with pytest.raises(ad.ModelError):
        b.add_body("late_body", -1.0, I3)
    with pytest.raises(ad.ModelError):
        b.add_body("late_body", 1.0, np.diag([0.1, 0.1, -0.1]))
    with pytest.raises(ad.ModelError):
        b.add_revolute("late_joint", "body1", "no_such_body", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    with pytest.raises(ad.ModelError):
        b.add_drive("no_such_joint", ad.profiles.constant(0.0))
    model = b.finalize()
    assert model.nb == 1
    assert list(model.body_names) == ["body1"]
    assert list(model.joint_names) == ["hinge"]
    assert len(model.drive_names) == 0
    # the names of the failed calls are still free
    b.add_body("late_body", 1.0, I3, position=(0.0, 0.0, -1.0))
    b.add_revolute("late_joint", "body1", "late_body", (0.0, 0.0, -0.7), (0.0, 1.0, 0.0))
    model = b.finalize()
    assert model.nb == 2 and list(model.joint_names) == ["hinge", "late_joint"]


# ----------------------------------------------------------------------------------------------
# joint-space functions
# ----------------------------------------------------------------------------------------------


@pytest.fixture
def pendulum():
    return simple_pendulum(L=1.0, m=1.0, theta0=0.3).model


def test_forward_dynamics_q_wrong_length(pendulum):
    with pytest.raises(ad.ModelError, match=r"\bq\b"):
        ad.forward_dynamics(pendulum, np.zeros(2), np.zeros(1), np.zeros(1))


def test_forward_dynamics_qd_wrong_length(pendulum):
    with pytest.raises(ad.ModelError, match=r"\bqd\b"):
        ad.forward_dynamics(pendulum, np.zeros(1), np.zeros(3), np.zeros(1))


def test_forward_dynamics_tau_wrong_length(pendulum):
    with pytest.raises(ad.ModelError, match=r"\btau\b"):
        ad.forward_dynamics(pendulum, np.zeros(1), np.zeros(1), np.zeros(4))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_forward_dynamics_non_finite_q(pendulum, bad):
    with pytest.raises(ad.ModelError, match=r"\bq\b"):
        ad.forward_dynamics(pendulum, np.array([bad]), np.zeros(1), np.zeros(1))


def test_state_from_joints_wrong_length(pendulum):
    with pytest.raises(ad.ModelError, match=r"\bq\b"):
        ad.state_from_joints(pendulum, np.zeros(3), np.zeros(1))


def test_accelerations_wrong_state_length(pendulum):
    with pytest.raises(ad.ModelError, match=r"\bu\b"):
        ad.body_accelerations(pendulum, np.zeros(5), np.zeros(6))
    with pytest.raises(ad.ModelError, match=r"\bv\b"):
        ad.body_accelerations(pendulum, np.asarray(pendulum.u0), np.zeros(5))


# ----------------------------------------------------------------------------------------------
# URDF
# ----------------------------------------------------------------------------------------------

URDF_OK_LINKS = """
  <link name="base"/>
  <link name="arm"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
"""


def test_urdf_minimal_is_accepted():
    text = f"""<robot name="ok">{URDF_OK_LINKS}
      <joint name="j" type="continuous"><parent link="base"/><child link="arm"/>
        <axis xyz="0 0 1"/></joint></robot>"""
    model = ad.load_urdf(text)
    assert model.n_coords == 1


@pytest.mark.parametrize(
    "text",
    [
        "<robot name='broken'><link name='a'>",  # unterminated
        "this is not xml at all",
        "<robot name='x'><link name='a'/><joint name='j' type='revolute'>"
        "<parent link='a'/></robot>",  # mismatched tags
    ],
    ids=["unterminated", "not_xml", "mismatched"],
)
def test_malformed_urdf(text):
    with pytest.raises(ad.UrdfError, match=r"(?i)urdf|xml|pars|malformed|syntax"):
        ad.load_urdf(text)


def test_urdf_floating_joint():
    text = f"""<robot name="floaty">{URDF_OK_LINKS}
      <joint name="float_joint" type="floating"><parent link="base"/><child link="arm"/>
      </joint></robot>"""
    with pytest.raises(ad.UrdfError, match=name_regex("float_joint", "floating")):
        ad.load_urdf(text)


def test_urdf_missing_file(tmp_path):
    path = tmp_path / "no_such_robot.urdf"
    with pytest.raises(ad.UrdfError, match="no_such_robot"):
        ad.load_urdf(str(path))


# ----------------------------------------------------------------------------------------------
# simulate arguments
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("t_end", [0.0, -1.0, float("nan")])
def test_simulate_bad_t_end(pendulum, t_end):
    with pytest.raises(ValueError, match="t_end"):
        ad.simulate(pendulum, t_end)


@pytest.mark.parametrize("kw", ["rtol", "atol"])
def test_simulate_negative_tolerance(pendulum, kw):
    with pytest.raises(ValueError, match=kw):
        ad.simulate(pendulum, 1.0, **{kw: -1e-6})


def test_simulate_unknown_integrator(pendulum):
    with pytest.raises(ValueError, match=name_regex("euler_bogus", "integrator")):
        ad.simulate(pendulum, 1.0, integrator="euler_bogus")


def test_simulate_unknown_projection(pendulum):
    with pytest.raises(ValueError, match=name_regex("sideways", "projection")):
        ad.simulate(pendulum, 1.0, projection="sideways")


def test_simulate_rk4_bad_dt(pendulum):
    with pytest.raises(ValueError, match=r"\bdt\b"):
        ad.simulate(pendulum, 1.0, integrator="rk4", dt=-1e-3)


# ----------------------------------------------------------------------------------------------
# assembly that cannot converge
# ----------------------------------------------------------------------------------------------


def test_assembly_cannot_converge():
    """A rod of length 1 hangs between a ground point and a slider; the slider's drive puts it
    3 m away from that ground point at t = 0: no configuration satisfies the constraints.

    (With joint points given in world coordinates at assembly the joints alone are always
    consistent; the inconsistency is brought in by the drive.) The failure may surface at
    finalize (assembly) or when the simulation starts (initial projection); the header
    documents ModelError for a failed assembly and SolverError for non-convergence, so either
    is accepted, but it must be raised and name the problem."""
    b = ad.ModelBuilder(gravity=GRAVITY)
    b.add_body("slider", 1.0, I3, position=(0.0, 0.0, 0.0))
    b.add_body("rod", 1.0, I3, position=(0.5, 0.0, 0.0))
    b.add_prismatic("rail", "ground", "slider", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    b.add_spherical("s_slider", "slider", "rod", (0.0, 0.0, 0.0))
    b.add_spherical("s_ground", "rod", "ground", (1.0, 0.0, 0.0))
    b.add_drive("rail", ad.profiles.constant(-3.0), name="rail_drive")
    with pytest.raises(
        (ad.ModelError, ad.SolverError),
        match=r"(?i)assembl|converge|rail|s_slider|s_ground|rod|slider",
    ):
        model = b.finalize()
        ad.simulate(model, 0.1)
