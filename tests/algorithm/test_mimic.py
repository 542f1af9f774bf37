"""Couplings q_follower = multiplier * q_leader + offset (ModelBuilder.add_coupling, URDF
<mimic>): the joint-space functions of a coupled model take the independent coordinates, as
Pinocchio's ``mimic=True`` models do. Checked against Pinocchio 4.1 (PR2 with its grippers'
mimic joints, Panda with its fingers), against closed forms (three sliders coupled in a
chain), between the joint-space and Cartesian paths, in simulations, and on bad input."""

import re
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

pin = pytest.importorskip("pinocchio")

PR2 = "pr2_description/urdf/pr2.urdf"


def urdf_path(rel):
    root = common.robot_urdf("panda").parents[2]  # .../example-robot-data/robots
    path = root / rel
    assert path.is_file(), path
    return str(path)


def rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def without_joint_dynamics(path, tmp_dir):
    """A copy of the URDF without its ``<dynamics damping friction>`` elements: armdyn imports
    them as joint friction, which Pinocchio's rnea, crba and aba leave out (the subject here is
    the mimic joints)."""
    text = re.sub(r"<dynamics\b[^>]*/>", "", Path(path).read_text())
    out = Path(tmp_dir) / Path(path).name
    out.write_text(text)
    return str(out)


class MimicPair:
    """A URDF in armdyn (load_urdf, mimic by default) and in Pinocchio with mimic=True, with the
    map between armdyn's independent coordinates and Pinocchio's q (continuous joints as
    (cos, sin)) and v."""

    def __init__(self, path):
        self.pm = pin.buildModelFromUrdf(path, mimic=True)
        self.pd = self.pm.createData()
        self.am = ad.load_urdf(path)
        names = list(self.am.coord_names)
        self.entries = []  # (armdyn index, idx_q, nq, idx_v)
        for i in range(1, self.pm.njoints):
            j = self.pm.joints[i]
            if j.shortname() == "JointModelMimic":
                continue
            self.entries.append((names.index(self.pm.names[i]), j.idx_q, j.nq, j.idx_v))
        assert len(self.entries) == self.am.n_coords == self.pm.nv
        self.perm = np.array([k for k, _, _, iv in sorted(self.entries, key=lambda e: e[3])])

    def pin_q(self, qa):
        q = np.zeros(self.pm.nq)
        for k, iq, nq, _ in self.entries:
            if nq == 2:  # continuous: (cos, sin)
                q[iq], q[iq + 1] = np.cos(qa[k]), np.sin(qa[k])
            else:
                q[iq] = qa[k]
        return q

    def pin_v(self, xa):
        """armdyn's independent coordinates -> Pinocchio's velocity order."""
        return np.asarray(xa)[self.perm]


@pytest.fixture(scope="module", params=["panda", "pr2"])
def pair(request, tmp_path_factory):
    path = str(common.robot_urdf("panda")) if request.param == "panda" else urdf_path(PR2)
    return MimicPair(without_joint_dynamics(path, tmp_path_factory.mktemp(request.param)))


def test_coordinate_counts_equal_pinocchio_mimic_models(pair):
    am, pm = pair.am, pair.pm
    mimics = [
        pm.names[i] for i in range(1, pm.njoints) if pm.joints[i].shortname() == "JointModelMimic"
    ]
    # every mimic joint is a coupling, the others are the independent coordinates
    assert sorted(c["follower"] for c in am.couplings) == sorted(mimics)
    assert am.n_coords == pm.nv
    assert am.n_joint_coords == am.n_coords + len(mimics)
    assert [am.joint_coord_names[c] for c in am.independent_coords] == list(am.coord_names)
    assert not set(am.coord_names) & set(mimics)
    # PR2: 20 independent coordinates of 30 joints (issue 21); Panda 8 of 9
    assert (am.n_coords, am.n_joint_coords) in ((20, 30), (8, 9))


def test_rnea_crba_and_forward_dynamics_equal_pinocchio_mimic(pair):
    am, pm, pd = pair.am, pair.pm, pair.pd
    rng = np.random.default_rng(21)
    worst = dict.fromkeys(("rnea", "rnea_cartesian", "crba", "fd", "fd_cartesian"), 0.0)
    for _ in range(20):
        qa, va, aa, ta = rng.uniform(-np.pi, np.pi, size=(4, am.n_coords))
        q, v, a, tau = pair.pin_q(qa), pair.pin_v(va), pair.pin_v(aa), pair.pin_v(ta)
        tau_ref = pin.rnea(pm, pd, q, v, a)
        worst["rnea"] = max(
            worst["rnea"], rel(pair.pin_v(ad.inverse_dynamics(am, qa, va, aa)), tau_ref)
        )
        tau_kkt = ad.inverse_dynamics(am, qa, va, aa, method="cartesian")
        worst["rnea_cartesian"] = max(worst["rnea_cartesian"], rel(pair.pin_v(tau_kkt), tau_ref))
        m_ref = pin.crba(pm, pd, q)
        m_ref = np.triu(m_ref) + np.triu(m_ref, 1).T
        m_ad = ad.mass_matrix(am, qa)
        np.testing.assert_array_equal(m_ad, m_ad.T)
        worst["crba"] = max(worst["crba"], rel(m_ad[np.ix_(pair.perm, pair.perm)], m_ref))
        # forward dynamics: M^-1 (tau - nle) of Pinocchio's mimic model
        nle = pin.rnea(pm, pd, q, v, np.zeros(pm.nv))
        a_ref = np.linalg.solve(m_ref, tau - nle)
        worst["fd"] = max(worst["fd"], rel(pair.pin_v(ad.forward_dynamics(am, qa, va, ta)), a_ref))
        a_kkt = ad.forward_dynamics(am, qa, va, ta, method="cartesian")
        worst["fd_cartesian"] = max(worst["fd_cartesian"], rel(pair.pin_v(a_kkt), a_ref))
    assert max(worst["rnea"], worst["crba"], worst["fd"]) <= 1e-10, worst
    # the Cartesian KKT path with the couplings' rows, an independent formulation
    assert max(worst["rnea_cartesian"], worst["fd_cartesian"]) <= 1e-9, worst


def test_batch_calls_take_independent_coordinates(pair):
    am = pair.am
    rng = np.random.default_rng(5)
    q, qd, x = rng.uniform(-1, 1, size=(3, 4, am.n_coords))
    tau = ad.inverse_dynamics(am, q, qd, x)
    acc = ad.forward_dynamics(am, q, qd, x)
    mm = ad.mass_matrix(am, q)
    assert tau.shape == acc.shape == (4, am.n_coords) and mm.shape == (4, am.n_coords, am.n_coords)
    for i in range(4):
        np.testing.assert_array_equal(tau[i], ad.inverse_dynamics(am, q[i], qd[i], x[i]))
        np.testing.assert_array_equal(mm[i], ad.mass_matrix(am, q[i]))
    # forward and inverse dynamics are each other's inverse
    assert rel(ad.inverse_dynamics(am, q[0], qd[0], acc[0]), x[0]) <= 1e-10
    expected = rf"q: expected shape \({am.n_coords},\), got \({am.n_joint_coords},\)"
    with pytest.raises(ad.ModelError, match=expected):
        ad.mass_matrix(am, np.zeros(am.n_joint_coords))


def test_state_from_joints_sets_followers_and_round_trips():
    am = ad.load_urdf(str(common.robot_urdf("panda")))
    q = np.array([0.1, -0.4, 0.2, -1.9, 0.3, 1.6, 0.5, 0.02])
    qd = np.linspace(-0.5, 0.5, 8)
    u, v = ad.state_from_joints(am, q, qd)
    qb, qdb = ad.joint_coordinates(am, u, v)
    np.testing.assert_allclose(qb, q, atol=1e-13)
    np.testing.assert_allclose(qdb, qd, atol=1e-13)
    # both fingers open by 0.02 m: the Cartesian constraint rows (the coupling's included) hold
    f = ad.evaluate_constraints(am, u, v)["f"]
    assert np.abs(f).max() <= 1e-13
    ua, _ = ad.state_from_joints(
        ad.load_urdf(str(common.robot_urdf("panda")), mimic=False),
        np.r_[q, 0.02],
        np.r_[qd, qd[-1]],
    )
    np.testing.assert_allclose(u, ua, atol=1e-14)


def sliders(m2=-2.0, o2=0.05, m3=0.5, o3=-0.02):
    """Three sliders on ground: a along x, b and c along z; b follows a (m2, o2), c follows b
    (m3, o3): a chain, q_c = m3 (m2 q_a + o2) + o3."""
    b = ad.ModelBuilder()
    b.add_body("a", 2.0, [0.01, 0.02, 0.03], position=(0, 0, 0))
    b.add_body("b", 3.0, [0.02, 0.01, 0.03], position=(1, 0, 0))
    b.add_body("c", 0.5, [0.01, 0.01, 0.01], position=(2, 0, 0))
    b.add_prismatic("ja", "ground", "a", point=(0, 0, 0), axis=(1, 0, 0))
    b.add_prismatic("jb", "ground", "b", point=(1, 0, 0), axis=(0, 0, 1))
    b.add_prismatic("jc", "ground", "c", point=(2, 0, 0), axis=(0, 0, 1))
    b.add_coupling("cb", "jb", "ja", m2, o2)
    b.add_coupling("cc", "jc", "jb", m3, o3)
    return b


def test_prismatic_chain_equals_closed_form():
    m2, o2, m3, o3 = -2.0, 0.05, 0.5, -0.02
    model = sliders(m2, o2, m3, o3).finalize()
    assert model.n_coords == 1 and list(model.coord_names) == ["ja"]
    ma, mb, mc, g = 2.0, 3.0, 0.5, 9.81
    sb, sc = m2, m3 * m2  # dq_b/dq_a, dq_c/dq_a
    mass = ma + mb * sb**2 + mc * sc**2
    np.testing.assert_allclose(ad.mass_matrix(model, [0.3]), [[mass]], rtol=1e-15)
    for q, qd, qdd in [(0.0, 0.0, 0.0), (0.3, -1.2, 2.5), (-0.7, 0.4, -1.0)]:
        tau = ma * qdd + sb * mb * (sb * qdd + g) + sc * mc * (sc * qdd + g)
        for method in ("joint", "cartesian"):
            got = ad.inverse_dynamics(model, [q], [qd], [qdd], method=method)
            np.testing.assert_allclose(got, [tau], rtol=1e-13, atol=1e-13)
        for method in ("crba", "cartesian"):
            acc = ad.forward_dynamics(model, [q], [qd], [tau], method=method)
            np.testing.assert_allclose(acc, [qdd], rtol=1e-12, atol=1e-12)
    # the assembly satisfies the offsets: at q_a = 0, b is raised by o2 and c by m3 o2 + o3
    u0 = np.asarray(model.u0)
    np.testing.assert_allclose(u0[[0, 7 + 2, 14 + 2]], [0.0, o2, m3 * o2 + o3], atol=1e-14)
    # and state_from_joints puts every slider where its coupling says
    u, _ = ad.state_from_joints(model, [0.25])
    qb = m2 * 0.25 + o2
    np.testing.assert_allclose(u[[0, 9, 16]], [0.25, qb, m3 * qb + o3], atol=1e-15)


def test_ideal_gear_is_the_coupling_without_offset():
    # the gear r_a q_a + r_b q_b = 0 and the coupling q_b = -(r_a / r_b) q_a are the same row:
    # the same Cartesian run
    def arm(kind):
        b = ad.ModelBuilder()
        b.add_body("a", 1.0, [0.01, 0.01, 0.02], position=(0.2, 0, 0))
        b.add_body("b", 0.5, [0.005, 0.005, 0.01], position=(0.6, 0, 0.1))
        b.add_revolute("ja", "ground", "a", point=(0, 0, 0), axis=(0, 1, 0))
        b.add_revolute("jb", "ground", "b", point=(0.5, 0, 0.1), axis=(0, 1, 0))
        if kind == "gear":
            b.add_gear("g", "ja", "jb", 0.04, 0.1)
        else:
            b.add_coupling("g", "jb", "ja", -0.4)
        return b.finalize()

    runs = [
        ad.simulate(arm(k), 0.5, rtol=1e-10, atol=1e-12, output_dt=0.05)
        for k in ("gear", "coupling")
    ]
    np.testing.assert_allclose(runs[0].q, runs[1].q, atol=1e-12)
    np.testing.assert_allclose(runs[1].q[:, 1], -0.4 * runs[1].q[:, 0], atol=1e-12)


def coupled_arm():
    """A planar two-link arm whose elbow follows the shoulder, q2 = 0.5 q1 + 0.3, with a third
    free link at the tip and a prismatic slider coupled to nothing."""
    b = ad.ModelBuilder()
    b.add_body("l1", 1.0, [0.01, 0.01, 0.01], position=(0.25, 0, 0))
    b.add_body("l2", 0.8, [0.008, 0.008, 0.008], position=(0.75, 0, 0))
    b.add_body("l3", 0.3, [0.002, 0.002, 0.002], position=(1.15, 0, 0))
    b.add_revolute("shoulder", "ground", "l1", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_revolute("elbow", "l1", "l2", point=(0.5, 0, 0), axis=(0, 1, 0))
    b.add_revolute("wrist", "l2", "l3", point=(1.0, 0, 0), axis=(0, 1, 0))
    b.add_coupling("elbow_follows", "elbow", "shoulder", 0.5, 0.3)
    b.add_joint_spring_damper("wrist", stiffness=0.5, damping=0.01, rest=0.0)
    return b.finalize()


@pytest.mark.parametrize("coordinates", ["joint", "cartesian"])
def test_simulation_keeps_the_coupling_and_the_formulations_agree(coordinates):
    model = coupled_arm()
    assert list(model.coord_names) == ["shoulder", "wrist"]
    assert list(model.joint_coord_names) == ["shoulder", "elbow", "wrist"]
    q0, qd0 = [0.4, -0.2], [0.5, 1.0]
    run = ad.simulate(
        model, 1.0, q0=q0, qd0=qd0, rtol=1e-10, atol=1e-12, output_dt=0.05, coordinates=coordinates
    )
    assert run.q.shape == (21, 3)
    np.testing.assert_allclose(run.q[0], [0.4, 0.5 * 0.4 + 0.3, -0.2], atol=1e-12)
    np.testing.assert_allclose(run.qd[0], [0.5, 0.25, 1.0], atol=1e-12)
    # the coupling holds to round-off along the run, at position, velocity and acceleration level
    assert np.abs(run.q[:, 1] - (0.5 * run.q[:, 0] + 0.3)).max() <= 1e-10
    assert np.abs(run.qd[:, 1] - 0.5 * run.qd[:, 0]).max() <= 1e-10
    assert np.abs(run.qdd[:, 1] - 0.5 * run.qdd[:, 0]).max() <= 1e-8
    # the shoulder swings far: more than a radian over the run
    assert np.ptp(run.q[:, 0]) > 1.0
    # the accelerations at each output are the public forward dynamics' in independent coordinates
    for k in (0, 10, 20):
        acc = ad.forward_dynamics(model, run.q[k, [0, 2]], run.qd[k, [0, 2]], np.zeros(2))
        np.testing.assert_allclose(run.qdd[k, [0, 2]], acc, rtol=1e-8, atol=1e-8)
    # energy is conserved but for the wrist damper's loss (small): within 1 %
    e = run.total_energy
    assert np.abs(e - e[0]).max() <= 1e-2 * np.abs(e).max()


def test_joint_and_cartesian_runs_match():
    model = coupled_arm()
    kw = dict(q0=[0.4, -0.2], qd0=[0.5, 1.0], rtol=1e-11, atol=1e-13, output_dt=0.1)
    joint = ad.simulate(model, 1.0, coordinates="joint", **kw)
    cart = ad.simulate(model, 1.0, coordinates="cartesian", **kw)
    assert "coupling" in joint.stats["formulation"]
    assert np.abs(joint.q - cart.q).max() <= 1e-8
    assert np.abs(joint.qd - cart.qd).max() <= 1e-7


def test_lagrange_validator_takes_the_independent_coordinates(pair):
    # an independent derivation (Euler-Lagrange by automatic differentiation of the composed
    # joint transforms, every joint) reduced by the couplings: G^T tau_full, G^T M G
    am = pair.am
    lv = ad.LagrangeValidator(am)
    rng = np.random.default_rng(13)
    for _ in range(3):
        q, v, a = rng.uniform(-1.0, 1.0, size=(3, am.n_coords))
        tau = ad.inverse_dynamics(am, q, v, a)
        assert np.abs(lv.torques(q, v, a) - tau).max() <= 1e-12 * max(1.0, np.abs(tau).max())
        np.testing.assert_allclose(lv.mass_matrix(q), ad.mass_matrix(am, q), rtol=0, atol=1e-12)


def test_aba_refuses_coupled_models_naming_why():
    model = coupled_arm()
    assert not model.joint_space
    with pytest.raises(
        ad.ModelError, match="method 'aba' does not apply to a model with couplings"
    ):
        ad.forward_dynamics(model, [0, 0], [0, 0], [0, 0], method="aba")


# --- bad input -----------------------------------------------------------------------------


def builder():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.01, 0.01, 0.01], position=(0, 0, 0))
    b.add_body("b", 1.0, [0.01, 0.01, 0.01], position=(1, 0, 0))
    b.add_body("c", 1.0, [0.01, 0.01, 0.01], position=(2, 0, 0))
    b.add_body("d", 1.0, [0.01, 0.01, 0.01], position=(3, 0, 0))
    b.add_revolute("ra", "ground", "a", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("rb", "a", "b", point=(1, 0, 0), axis=(0, 0, 1))
    b.add_prismatic("pc", "b", "c", point=(2, 0, 0), axis=(1, 0, 0))
    b.add_spherical("sd", "c", "d", point=(3, 0, 0))
    return b


@pytest.mark.parametrize(
    "args, message",
    [
        (("k", "nope", "ra", 1.0), "coupling 'k': unknown follower joint 'nope'"),
        (("k", "rb", "nope", 1.0), "coupling 'k': unknown leader joint 'nope'"),
        (("k", "ra", "ra", 1.0), "coupling 'k': joint 'ra' cannot follow itself"),
        (
            ("k", "sd", "ra", 1.0),
            r"coupling 'k': follower joint 'sd' is spherical \(no joint coordinate\)",
        ),
        (
            ("k", "pc", "ra", 1.0),
            "coupling 'k': follower joint 'pc' is prismatic but leader joint 'ra' is revolute",
        ),
        (("k", "rb", "ra", 0.0), "coupling 'k': multiplier must be finite and nonzero, got 0"),
        (
            ("k", "rb", "ra", float("nan")),
            "coupling 'k': multiplier must be finite and nonzero, got nan",
        ),
        (
            ("k", "rb", "ra", float("inf")),
            "coupling 'k': multiplier must be finite and nonzero, got inf",
        ),
        (("k", "rb", "ra", 1.0, float("nan")), "coupling 'k': offset must be finite"),
        (("", "rb", "ra", 1.0), "coupling: empty name"),
    ],
)
def test_add_coupling_refuses_bad_input(args, message):
    b = builder()
    with pytest.raises(ad.ModelError, match=message):
        b.add_coupling(*args)
    assert b.finalize().n_coords == 3  # the builder is unchanged


def test_add_coupling_refuses_a_second_leader_cycles_and_duplicates():
    b = builder()
    b.add_coupling("k1", "rb", "ra", 2.0)
    with pytest.raises(
        ad.ModelError,
        match="coupling 'k2': joint 'rb' already follows joint 'ra' \\(coupling 'k1'\\)",
    ):
        b.add_coupling("k2", "rb", "ra", 3.0)
    with pytest.raises(
        ad.ModelError, match="coupling 'k3': the couplings would form a cycle 'ra' -> 'rb' -> 'ra'"
    ):
        b.add_coupling("k3", "ra", "rb", 0.5)
    with pytest.raises(ad.ModelError, match="coupling 'k1': duplicate name"):
        b.add_coupling("k1", "ra", "rb", 0.5)
    m = b.finalize()
    assert m.n_coords == 2 and [c["name"] for c in m.couplings] == ["k1"]


def test_three_joint_cycle_is_refused():
    b = ad.ModelBuilder()
    for i, name in enumerate("xyz"):
        b.add_body(name, 1.0, [0.01, 0.01, 0.01], position=(i, 0, 0))
        b.add_prismatic("p" + name, "ground", name, point=(i, 0, 0), axis=(0, 0, 1))
    b.add_coupling("k1", "py", "px", 1.0)
    b.add_coupling("k2", "pz", "py", 1.0)
    with pytest.raises(ad.ModelError, match="cycle 'px' -> 'pz' -> 'py' -> 'px'"):
        b.add_coupling("k3", "px", "pz", 1.0)


INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
)
URDF = """<robot name="r">
  <link name="base"/>
  <link name="l1">{inertial}</link>
  <link name="l2">{inertial}</link>
  <link name="tip"/>
  <joint name="j1" type="{t1}"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/>{lim}</joint>
  <joint name="j2" type="{t2}"><parent link="l1"/><child link="l2"/><origin xyz="1 0 0"/>
    <axis xyz="0 0 1"/>{lim}{mimic}</joint>
  <joint name="fix" type="fixed"><parent link="l2"/><child link="tip"/></joint>
</robot>"""
LIM = '<limit lower="-2" upper="2" effort="1" velocity="1"/>'


def urdf(t1="revolute", t2="revolute", mimic='<mimic joint="j1" multiplier="2" offset="0.1"/>'):
    return URDF.format(inertial=INERTIAL, t1=t1, t2=t2, lim=LIM, mimic=mimic)


def test_urdf_mimic_becomes_a_coupling_and_mimic_false_keeps_it_free():
    m = ad.load_urdf(urdf())
    assert m.couplings == [
        {"name": "j2", "follower": "j2", "leader": "j1", "multiplier": 2.0, "offset": 0.1}
    ]
    assert m.n_coords == 1
    u, _ = ad.state_from_joints(m, [0.3])
    q, _ = ad.joint_coordinates(ad.load_urdf(urdf(), mimic=False), u, np.zeros(12))
    np.testing.assert_allclose(q, [0.3, 0.7], atol=1e-14)
    assert ad.load_urdf(urdf(), mimic=False).n_coords == 2
    # prismatic pairs too
    assert ad.load_urdf(urdf("prismatic", "prismatic")).n_coords == 1


@pytest.mark.parametrize(
    "kw, message",
    [
        (
            dict(mimic='<mimic joint="ghost"/>'),
            "URDF joint 'j2': <mimic> names unknown joint 'ghost'",
        ),
        (dict(mimic='<mimic joint="fix"/>'), "URDF joint 'j2': <mimic> names fixed joint 'fix'"),
        (
            dict(t2="prismatic", mimic='<mimic joint="j1"/>'),
            "URDF joint 'j2' <mimic joint='j1'>: coupling 'j2': follower joint 'j2' is "
            "prismatic but leader joint 'j1' is revolute",
        ),
        (
            dict(mimic='<mimic joint="j1" multiplier="0"/>'),
            "URDF joint 'j2' <mimic joint='j1'>: .*multiplier must be finite and nonzero",
        ),
        (
            dict(mimic='<mimic joint="j2"/>'),
            "URDF joint 'j2' <mimic joint='j2'>: .*cannot follow itself",
        ),
    ],
)
def test_urdf_bad_mimic_is_refused_naming_both_joints(kw, message):
    with pytest.raises(ad.UrdfError, match=message):
        ad.load_urdf(urdf(**kw))


def test_welded_run_keeps_the_coupling():
    # a fixed joint merged by the welded run (merge_welded): the coupling's coordinates and
    # offset survive the weld, the run equals the unmerged one
    b = ad.ModelBuilder()
    b.add_body("l1", 1.0, [0.01, 0.01, 0.01], position=(0.25, 0, 0))
    b.add_body("l1b", 0.2, [0.001, 0.001, 0.001], position=(0.5, 0, 0.05))
    b.add_body("l2", 0.8, [0.008, 0.008, 0.008], position=(0.75, 0, 0))
    b.add_revolute("shoulder", "ground", "l1", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_fixed("weld", "l1", "l1b", point=(0.5, 0, 0))
    b.add_revolute("elbow", "l1b", "l2", point=(0.5, 0, 0), axis=(0, 1, 0))
    b.add_coupling("k", "elbow", "shoulder", -1.5, 0.2)
    model = b.finalize()
    assert "coupling k: elbow = -1.5 shoulder + 0.2" in model.summary()
    kw = dict(q0=[0.3], rtol=1e-11, atol=1e-13, output_dt=0.1)
    merged = ad.simulate(model, 0.5, merge_welded=True, **kw)
    full = ad.simulate(model, 0.5, merge_welded=False, **kw)
    assert merged.stats["solver_bodies"] == 2
    np.testing.assert_allclose(merged.q, full.q, atol=1e-9)
    assert np.abs(merged.q[:, 1] - (-1.5 * merged.q[:, 0] + 0.2)).max() <= 1e-10


def test_q0_keeps_the_turns_of_leaders_and_followers():
    # shoulder 3.5 rad is the pose of 3.5 - 2 pi, but with the multiplier 0.5 the elbow's pose
    # differs by half a turn: the run starts from q0's turns (armdyn passes them to the tracking)
    model = coupled_arm()
    for coordinates in ("cartesian", "joint"):
        run = ad.simulate(model, 0.2, q0=[3.5, 0.0], output_dt=0.1, coordinates=coordinates)
        np.testing.assert_allclose(run.q[0], [3.5, 0.5 * 3.5 + 0.3, 0.0], atol=1e-12)
        assert np.abs(run.q[:, 1] - (0.5 * run.q[:, 0] + 0.3)).max() <= 1e-10


def test_floating_base_with_mimic_equals_pinocchio_free_flyer_mimic(tmp_path):
    # the floating base's block leads q (7) and qd (6) and passes the couplings' map unchanged
    path = without_joint_dynamics(common.robot_urdf("panda"), tmp_path)
    am = ad.load_urdf(path, fixed_base=False)
    pm = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer(), mimic=True)
    pd = pm.createData()
    assert (am.n_coords, am.n_dofs, am.n_free) == (pm.nq, pm.nv, 1) == (15, 14, 1)
    assert (am.n_joint_coords, am.n_joint_dofs) == (16, 15)
    names = am.coord_names[7:]
    iq = np.array([pm.idx_qs[pm.getJointId(n)] for n in names])
    iv = np.array([pm.idx_vs[pm.getJointId(n)] for n in names])
    perm = np.concatenate([np.arange(6), iv])
    rng = np.random.default_rng(8)
    worst = dict.fromkeys(("rnea", "crba", "fd", "fd_cartesian"), 0.0)
    for _ in range(10):
        e = rng.normal(size=4)
        e /= np.linalg.norm(e)
        q = np.concatenate([rng.normal(size=3), e, rng.uniform(-2, 2, am.n_coords - 7)])
        v, a, tau = rng.normal(size=(3, am.n_dofs))
        qp = np.zeros(pm.nq)
        qp[:3], qp[3:6], qp[6], qp[iq] = q[:3], q[4:7], q[3], q[7:]
        vp, ap, tp = (np.zeros(pm.nv) for _ in range(3))
        vp[perm], ap[perm], tp[perm] = v, a, tau
        tau_ref = pin.rnea(pm, pd, qp, vp, ap)[perm]
        worst["rnea"] = max(worst["rnea"], rel(ad.inverse_dynamics(am, q, v, a), tau_ref))
        m_ref = pin.crba(pm, pd, qp)
        m_ref = (np.triu(m_ref) + np.triu(m_ref, 1).T)[np.ix_(perm, perm)]
        worst["crba"] = max(worst["crba"], rel(ad.mass_matrix(am, q), m_ref))
        nle = pin.rnea(pm, pd, qp, vp, np.zeros(pm.nv))[perm]
        a_ref = np.linalg.solve(m_ref, tau - nle)
        worst["fd"] = max(worst["fd"], rel(ad.forward_dynamics(am, q, v, tau), a_ref))
        a_kkt = ad.forward_dynamics(am, q, v, tau, method="cartesian")
        worst["fd_cartesian"] = max(worst["fd_cartesian"], rel(a_kkt, a_ref))
    assert max(worst.values()) <= 1e-10, worst


def test_frames_of_a_coupled_model_equal_pinocchio_mimic_model(pair):
    # frame_pose and frame_jacobian take the independent coordinates; the Jacobian is J G (a
    # follower's column added to its leader's), as Pinocchio's mimic=True model's
    am, pm, pd = pair.am, pair.pm, pair.pd
    frames = [f for f in am.frame_names if pm.existFrame(f)]
    assert len(frames) >= 10
    rng = np.random.default_rng(12)
    for _ in range(3):
        qa = rng.uniform(-1.0, 1.0, am.n_coords)
        q = pair.pin_q(qa)
        pin.framesForwardKinematics(pm, pd, q)
        pin.computeJointJacobians(pm, pd, q)
        for f in frames:
            fid = pm.getFrameId(f)
            np.testing.assert_allclose(
                ad.frame_pose(am, qa, f), pd.oMf[fid].homogeneous, rtol=0, atol=1e-12, err_msg=f
            )
            J = ad.frame_jacobian(am, qa, f)
            Jp = pin.getFrameJacobian(pm, pd, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(J[:, pair.perm], Jp, rtol=0, atol=1e-12, err_msg=f)
