"""Joint-space interface against the independent numpy recursive Newton-Euler reference.

- ad.forward_dynamics of random 6-DOF spatial arms (full inertia tensors; all-revolute and a
  variant with prismatic joints) = M^-1 (tau - bias) from tests/oracles/numpy_rne.py;
- ad.state_from_joints = the reference forward kinematics (CoM, orientation, CoM velocity,
  body-frame angular velocity), and ad.joint_coordinates inverts it;
- a URDF arm (tests/data/urdf/arm6.urdf) loaded with ad.load_urdf equals the same arm built by
  hand through the builder from a geometry this test extracts itself with xml.etree (origins
  composed with rpy = Rz(y) Ry(p) Rx(r), fixed links merged by hand), and both equal the numpy
  reference.
"""

import xml.etree.ElementTree as ET
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest
from conftest import (
    GRAVITY,
    coord_index,
    from_armdyn,
    quat_to_rot,
    rel_err,
    rot_to_quat,
    spatial_arm,
    to_armdyn,
    tol,
)
from oracles.numpy_rne import SerialChain, rot_axis_angle, rpy_to_rot

URDF_PATH = Path(__file__).resolve().parents[1] / "data" / "urdf" / "arm6.urdf"
REL = 1e-10


def random_joint_state(rng, n):
    return rng.uniform(-2.0, 2.0, n), rng.normal(size=n), rng.normal(scale=5.0, size=n)


@pytest.mark.parametrize("prismatic", [False, True], ids=["revolute", "with_prismatic"])
def test_forward_dynamics_random_arm(rng, prismatic):
    arm = spatial_arm(rng, n=6, prismatic=prismatic)
    assert arm.model.n_coords == 6
    assert arm.model.nb == 6 and arm.model.nv == 36 and arm.model.nq == 42
    for _ in range(4):
        q, qd, tau = random_joint_state(rng, arm.n)
        qdd_ref = arm.chain.forward(q, qd, tau)
        qdd = ad.forward_dynamics(
            arm.model, to_armdyn(arm.perm, q), to_armdyn(arm.perm, qd), to_armdyn(arm.perm, tau)
        )
        assert rel_err(from_armdyn(arm.perm, qdd), qdd_ref) <= tol(REL)
    # gravity alone at rest (a pure function of q; sensitive to the sign conventions)
    q = rng.uniform(-2.0, 2.0, arm.n)
    qdd = ad.forward_dynamics(arm.model, to_armdyn(arm.perm, q), np.zeros(arm.n), np.zeros(arm.n))
    assert rel_err(
        from_armdyn(arm.perm, qdd), arm.chain.forward(q, np.zeros(arm.n), np.zeros(arm.n))
    ) <= tol(REL)


@pytest.mark.parametrize("prismatic", [False, True], ids=["revolute", "with_prismatic"])
def test_state_from_joints_and_back(rng, prismatic):
    arm = spatial_arm(rng, n=6, prismatic=prismatic)
    model = arm.model
    # q = 0 is the assembly pose
    u0, v0 = ad.state_from_joints(model, np.zeros(arm.n), np.zeros(arm.n))
    np.testing.assert_allclose(u0[0::7][: arm.n], arm.coms[:, 0], atol=1e-12)
    q0, qd0 = ad.joint_coordinates(model, model.u0, model.v0)
    np.testing.assert_allclose(q0, 0.0, atol=1e-12)
    np.testing.assert_allclose(qd0, 0.0, atol=1e-12)
    for _ in range(4):
        q, qd, _ = random_joint_state(rng, arm.n)
        q[[i for i, t in enumerate(arm.types) if t == "R"]] %= 2 * np.pi  # keep in (-pi, pi)
        q = np.where(q > np.pi, q - 2 * np.pi, q)
        u, v = ad.state_from_joints(model, to_armdyn(arm.perm, q), to_armdyn(arm.perm, qd))
        u, v = np.asarray(u), np.asarray(v)
        c, r, vc, wb = arm.chain.body_states(q, qd)
        for k in range(arm.n):
            kb = list(model.body_names).index(arm.body_names[k])
            np.testing.assert_allclose(u[7 * kb : 7 * kb + 3], c[k], rtol=0, atol=1e-12)
            e = u[7 * kb + 3 : 7 * kb + 7]
            assert abs(np.linalg.norm(e) - 1.0) <= 1e-12
            np.testing.assert_allclose(quat_to_rot(e), r[k], rtol=0, atol=1e-12)
            np.testing.assert_allclose(v[6 * kb : 6 * kb + 3], vc[k], rtol=0, atol=1e-12)
            np.testing.assert_allclose(v[6 * kb + 3 : 6 * kb + 6], wb[k], rtol=0, atol=1e-12)
        q_back, qd_back = ad.joint_coordinates(model, u, v)
        np.testing.assert_allclose(from_armdyn(arm.perm, q_back), q, rtol=0, atol=1e-12)
        np.testing.assert_allclose(from_armdyn(arm.perm, qd_back), qd, rtol=0, atol=1e-12)
        # energies of the joint state = the reference's
        ke, pe = ad.energy(model, u, v)
        assert ke == pytest.approx(arm.chain.kinetic_energy(q, qd), rel=1e-12)
        _, pe0 = ad.energy(model, u0, v0)
        assert pe - pe0 == pytest.approx(
            arm.chain.potential_energy(q) - arm.chain.potential_energy(np.zeros(arm.n)),
            rel=1e-10,
            abs=1e-12,
        )


def test_principal_inertia_vector(rng):
    """inertia given as (3,) principal moments == the (3,3) diagonal matrix."""
    models = []
    for inertia in ([0.1, 0.2, 0.25], np.diag([0.1, 0.2, 0.25])):
        b = ad.ModelBuilder(gravity=GRAVITY)
        b.add_body("b", 1.5, inertia, position=(0.3, 0.0, -0.2), orientation=random_quat_fixed())
        b.add_revolute("hinge", "ground", "b", (0.0, 0.0, 0.0), (0.3, 1.0, 0.1))
        models.append(b.finalize())
    np.testing.assert_array_equal(ad.body_mass_matrix(models[0]), ad.body_mass_matrix(models[1]))
    np.testing.assert_allclose(
        np.diag(ad.body_mass_matrix(models[0]))[3:], [0.1, 0.2, 0.25], atol=0
    )


def random_quat_fixed():
    e = np.array([0.9, 0.1, -0.3, 0.2])
    return e / np.linalg.norm(e)


# ----------------------------------------------------------------------------------------------
# URDF
# ----------------------------------------------------------------------------------------------


def _floats(text, default):
    return np.array([float(x) for x in text.split()]) if text is not None else np.array(default)


def _origin(el):
    o = el.find("origin") if el is not None else None
    if o is None:
        return np.zeros(3), np.eye(3)
    return _floats(o.get("xyz"), [0, 0, 0]), rpy_to_rot(_floats(o.get("rpy"), [0, 0, 0]))


def urdf_geometry(path):
    """World-frame geometry at q = 0 of a fixed-base URDF tree, fixed links merged by hand.

    Returns (bodies, joints): bodies = {name: dict(m, c, R, I_world)} for every link that is the
    child of a movable joint (with all links rigidly attached to it merged in); joints = list of
    dict(name, type 'R'/'P', parent (body name or 'ground'), child, point, axis) in
    parent-before-child order. The joint frame of a URDF joint is the child link frame."""
    root = ET.parse(path).getroot()
    links = {el.get("name"): el for el in root.findall("link")}
    jels = root.findall("joint")
    children = {}
    child_links = set()
    for j in jels:
        children.setdefault(j.find("parent").get("link"), []).append(j)
        child_links.add(j.find("child").get("link"))
    roots = [n for n in links if n not in child_links]
    assert len(roots) == 1, f"URDF must be a tree with one root, roots: {roots}"

    world = {roots[0]: (np.zeros(3), np.eye(3))}  # link frame origin and rotation in world
    owner = {roots[0]: "ground"}
    joints = []
    order = [roots[0]]
    stack = [roots[0]]
    while stack:
        parent = stack.pop(0)
        for j in children.get(parent, []):
            child = j.find("child").get("link")
            p_par, r_par = world[parent]
            xyz, rot = _origin(j)
            world[child] = (p_par + r_par @ xyz, r_par @ rot)
            jtype = j.get("type")
            if jtype == "fixed":
                owner[child] = owner[parent]
            elif jtype in ("revolute", "continuous", "prismatic"):
                owner[child] = child
                axis = _floats(
                    j.find("axis").get("xyz") if j.find("axis") is not None else None,
                    [1.0, 0.0, 0.0],
                )
                dyn = j.find("dynamics")
                joints.append(
                    dict(
                        name=j.get("name"),
                        type="P" if jtype == "prismatic" else "R",
                        parent=owner[parent],
                        child=child,
                        point=world[child][0],
                        axis=world[child][1] @ axis,
                        damping=float(dyn.get("damping", 0.0)) if dyn is not None else 0.0,
                        friction=float(dyn.get("friction", 0.0)) if dyn is not None else 0.0,
                    )
                )
            else:
                raise AssertionError(f"unsupported joint type {jtype} in the test URDF")
            order.append(child)
            stack.append(child)

    bodies = {}
    parts = {}
    for name in order:
        el = links[name].find("inertial")
        if el is None:
            continue
        mass = float(el.find("mass").get("value"))
        ie = el.find("inertia")
        ixx, ixy, ixz, iyy, iyz, izz = (
            float(ie.get(k, 0.0)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        )
        i_inertial = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        xyz, rot = _origin(el)
        p_link, r_link = world[name]
        c = p_link + r_link @ xyz
        r = r_link @ rot
        parts.setdefault(owner[name], []).append((mass, c, r @ i_inertial @ r.T))
    for name in order[1:]:
        if owner[name] != name:
            continue
        plist = parts.get(name, [])
        m = sum(p[0] for p in plist)
        assert m > 0, f"movable link {name} has no mass in the URDF"
        c = sum(p[0] * p[1] for p in plist) / m
        i_world = np.zeros((3, 3))
        for mk, ck, ik in plist:
            d = ck - c
            i_world += ik + mk * (d @ d * np.eye(3) - np.outer(d, d))
        bodies[name] = dict(m=m, c=c, R=world[name][1], I_world=0.5 * (i_world + i_world.T))
    return bodies, joints


def build_by_hand(bodies, joints):
    b = ad.ModelBuilder(gravity=GRAVITY)
    for name, g in bodies.items():
        b.add_body(
            name,
            g["m"],
            g["R"].T @ g["I_world"] @ g["R"],
            position=g["c"],
            orientation=rot_to_quat(g["R"]),
        )
    for j in joints:
        add = b.add_revolute if j["type"] == "R" else b.add_prismatic
        add(j["name"], j["parent"], j["child"], j["point"], j["axis"])
        if j["damping"] or j["friction"]:
            b.add_joint_friction(
                j["name"], j["damping"], j["friction"], ad._core.URDF_COULOMB_SMOOTHING
            )
    return b.finalize()


def joint_friction(joints, qd):
    """The URDF's <dynamics> torques at rates qd: -damping qd - friction tanh(qd / v_s)."""
    c = np.array([j["damping"] for j in joints])
    f = np.array([j["friction"] for j in joints])
    return -c * qd - f * np.tanh(qd / ad._core.URDF_COULOMB_SMOOTHING)


def reference_chain(bodies, joints):
    index = {j["child"]: i for i, j in enumerate(joints)}
    parents = [index[j["parent"]] if j["parent"] != "ground" else -1 for j in joints]
    ch = [bodies[j["child"]] for j in joints]
    return SerialChain(
        [j["type"] for j in joints],
        parents,
        [j["point"] for j in joints],
        [j["axis"] for j in joints],
        [g["c"] for g in ch],
        [g["m"] for g in ch],
        [g["I_world"] for g in ch],
        rotations=[g["R"] for g in ch],
        gravity=GRAVITY,
    )


def test_urdf_arm_matches_hand_built(rng):
    assert URDF_PATH.exists(), f"missing test asset {URDF_PATH}"
    bodies, joints = urdf_geometry(URDF_PATH)
    assert len(joints) >= 1
    loaded = ad.load_urdf(str(URDF_PATH))
    by_hand = build_by_hand(bodies, joints)
    chain = reference_chain(bodies, joints)
    n = len(joints)
    assert loaded.n_coords == by_hand.n_coords == n
    perm_l = np.array([coord_index(loaded, j["name"]) for j in joints])
    perm_h = np.array([coord_index(by_hand, j["name"]) for j in joints])
    moving_mass = sum(g["m"] for g in bodies.values())

    for _ in range(5):
        q, qd, tau = random_joint_state(rng, n)
        qdd_l = from_armdyn(
            perm_l,
            ad.forward_dynamics(
                loaded, to_armdyn(perm_l, q), to_armdyn(perm_l, qd), to_armdyn(perm_l, tau)
            ),
        )
        qdd_h = from_armdyn(
            perm_h,
            ad.forward_dynamics(
                by_hand, to_armdyn(perm_h, q), to_armdyn(perm_h, qd), to_armdyn(perm_h, tau)
            ),
        )
        qdd_ref = chain.forward(q, qd, tau + joint_friction(joints, qd))
        # same model through two input paths: agreement at round-off level
        assert rel_err(qdd_l, qdd_h) <= tol(1e-12)
        assert rel_err(qdd_l, qdd_ref) <= tol(REL)

        # merging-independent invariants of the loaded model's Cartesian state
        u_l, v_l = ad.state_from_joints(loaded, to_armdyn(perm_l, q), to_armdyn(perm_l, qd))
        u_0, _ = ad.state_from_joints(loaded, np.zeros(n), np.zeros(n))
        masses = np.array([_body_mass(loaded, k) for k in range(loaded.nb)])
        first_moment = sum(
            masses[k] * (np.asarray(u_l)[7 * k : 7 * k + 3] - np.asarray(u_0)[7 * k : 7 * k + 3])
            for k in range(loaded.nb)
        )
        kin = chain.kinematics(q)
        kin0 = chain.kinematics(np.zeros(n))
        ref_moment = sum(chain.masses[i] * (kin["c"][i] - kin0["c"][i]) for i in range(n))
        np.testing.assert_allclose(first_moment, ref_moment, rtol=0, atol=1e-12 * moving_mass)
        ke, _ = ad.energy(loaded, u_l, v_l)
        assert ke == pytest.approx(chain.kinetic_energy(q, qd), rel=1e-11)


def _body_mass(model, k):
    """Mass of body k from the mass matrix (Gamma = blockdiag(m I, J))."""
    return float(np.asarray(ad.body_mass_matrix(model))[6 * k, 6 * k])


def test_urdf_parser_of_this_test(tmp_path):
    """Self-check of urdf_geometry on a small inline URDF with rpy origins, an inertial frame
    with rpy, a fixed link to merge and a prismatic joint: the product-of-exponentials chain
    built from it must reproduce the URDF-style forward kinematics (chained transforms)."""
    text = """<robot name="t">
      <link name="base"/>
      <link name="a"><inertial><origin xyz="0.1 0.02 0.3" rpy="0.3 -0.2 0.5"/><mass value="2"/>
        <inertia ixx="0.03" ixy="0.001" ixz="-0.002" iyy="0.04" iyz="0.003" izz="0.05"/>
      </inertial></link>
      <link name="a_tool"><inertial><origin xyz="0 0.1 0"/><mass value="0.5"/>
        <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.002"/></inertial></link>
      <link name="b"><inertial><origin xyz="0 0 0.2"/><mass value="1"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.012" iyz="0" izz="0.005"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
        <origin xyz="0 0 0.4" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
      <joint name="fix" type="fixed"><parent link="a"/><child link="a_tool"/>
        <origin xyz="0.2 0 0.1" rpy="0 1.0 0"/></joint>
      <joint name="j2" type="prismatic"><parent link="a_tool"/><child link="b"/>
        <origin xyz="0 0.3 0" rpy="-0.4 0 0.2"/><axis xyz="0 1 0"/>
        <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
    </robot>"""
    path = tmp_path / "t.urdf"
    path.write_text(text)
    bodies, joints = urdf_geometry(path)
    assert [j["name"] for j in joints] == ["j1", "j2"]
    assert set(bodies) == {"a", "b"}
    assert bodies["a"]["m"] == pytest.approx(2.5)
    chain = reference_chain(bodies, joints)
    q = np.array([0.7, 0.15])
    # URDF-style FK: T_a = T(j1 origin) Rz(q1); T_tool = T_a T(fix); T_b = T_tool T(j2) trans(q2 y)
    r1 = rpy_to_rot([0.1, 0.2, 0.3]) @ rot_axis_angle([0, 0, 1], q[0])
    p1 = np.array([0, 0, 0.4])
    r_tool = r1 @ rpy_to_rot([0, 1.0, 0])
    p_tool = p1 + r1 @ np.array([0.2, 0, 0.1])
    r2 = r_tool @ rpy_to_rot([-0.4, 0, 0.2])
    p2 = p_tool + r_tool @ np.array([0, 0.3, 0]) + r2 @ np.array([0, q[1], 0])
    c_a_link = p1 + r1 @ np.array([0.1, 0.02, 0.3])
    c_tool = p_tool + r_tool @ np.array([0, 0.1, 0])
    c_a = (2.0 * c_a_link + 0.5 * c_tool) / 2.5
    c_b = p2 + r2 @ np.array([0, 0, 0.2])
    kin = chain.kinematics(q)
    np.testing.assert_allclose(kin["c"][0], c_a, atol=1e-14)
    np.testing.assert_allclose(kin["c"][1], c_b, atol=1e-14)
    np.testing.assert_allclose(kin["R"][0], r1, atol=1e-14)
    np.testing.assert_allclose(kin["R"][1], r2, atol=1e-14)
    # merged inertia of "a" about its CoM, in world axes at q = 0 (parallel-axis theorem)
    ra = rpy_to_rot([0.1, 0.2, 0.3]) @ rpy_to_rot([0.3, -0.2, 0.5])
    ia = ra @ np.array([[0.03, 0.001, -0.002], [0.001, 0.04, 0.003], [-0.002, 0.003, 0.05]]) @ ra.T
    rt = rpy_to_rot([0.1, 0.2, 0.3]) @ rpy_to_rot([0, 1.0, 0])
    it = rt @ np.diag([0.002, 0.001, 0.002]) @ rt.T
    ca0 = np.array([0, 0, 0.4]) + rpy_to_rot([0.1, 0.2, 0.3]) @ np.array([0.1, 0.02, 0.3])
    ct0 = (
        np.array([0, 0, 0.4])
        + rpy_to_rot([0.1, 0.2, 0.3]) @ np.array([0.2, 0, 0.1])
        + rt @ np.array([0, 0.1, 0])
    )
    cm = (2.0 * ca0 + 0.5 * ct0) / 2.5
    steiner = sum(
        m * ((d @ d) * np.eye(3) - np.outer(d, d)) for m, d in ((2.0, ca0 - cm), (0.5, ct0 - cm))
    )
    np.testing.assert_allclose(bodies["a"]["I_world"], ia + it + steiner, atol=1e-15)
