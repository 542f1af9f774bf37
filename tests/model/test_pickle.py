"""Pickling and copying of Model, ModelBuilder and Profile: the copy simulates bit for bit as the
original (every table), and carries every element (actuators, couplings, frames, limits,
warnings); a Python-callable profile cannot travel and says so."""

from __future__ import annotations

import copy
import multiprocessing
import pickle

import armdyn as ad
import numpy as np
import pytest
from armdyn import profiles
from armdyn.papers.geared_arm import geared_arm_6dof
from conftest import assert_same_run

from benchmarks import common

PROTOCOLS = range(2, pickle.HIGHEST_PROTOCOL + 1)


DESCRIPTION = (
    "nb",
    "nq",
    "nv",
    "nc",
    "n_coords",
    "n_dofs",
    "mobility",
    "joint_names",
    "body_names",
    "coord_names",
    "frame_names",
    "kkt_path",
)


def assert_same_model(a, b):
    for name in DESCRIPTION:
        if hasattr(a, name):
            assert getattr(a, name) == getattr(b, name), name
    for name in ("u0", "v0", "coord_lower", "coord_upper"):
        if hasattr(a, name):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert repr(a.actuators) == repr(b.actuators)


def ur5_path():
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return path


def rich_builder():
    """The UR5 from its URDF plus one of most elements: actuators (one with a motor datasheet,
    one gyroscopic), a coupling, a PI motor, torque input, joint spring, friction, a profiled
    body force, a spring-damper, a frame, limits, and a drive."""
    b = ad.urdf_builder(str(ur5_path()))
    b.add_actuator(
        "shoulder_lift_joint",
        80.0,
        2e-5,
        efficiency=0.9,
        friction_viscous=1e-4,
        motor=ad.Motor(name="m1", torque_constant=0.05, resistance=0.4, voltage=48.0),
    )
    b.add_actuator("elbow_joint", 50.0, 1e-5, gyroscopic=True)
    b.add_coupling("wrist_couple", "wrist_3_joint", "wrist_2_joint", 0.5, 0.1)
    b.add_motor("wrist_1_joint", profiles.quintic(0.0, 0.4, 0.0, 0.1), 60.0, 4.0, 15.0, ki=20.0)
    b.add_joint_torque("wrist_2_joint", profiles.sine(0.3, 3.0, 0.2, 0.05))
    b.add_joint_spring_damper("wrist_2_joint", 1.5, 0.05, 0.1)
    b.add_joint_friction("elbow_joint", 0.2, 0.3)
    b.add_body_force(
        "wrist_3_link",
        force=(0.0, 0.0, -4.0),
        profile=profiles.spline([0.0, 0.05, 0.1, 0.2], [0.0, 1.0, 0.3, 0.8]),
    )
    b.add_spring_damper(
        "tether", "ground", (0.3, 0.3, 0.0), "forearm_link", (0.2, 0.2, 0.5), 30.0, 1.0
    )
    b.add_frame("tool", "wrist_3_link", (0.4, 0.2, 0.6))
    b.set_joint_limits("wrist_1_joint", -0.2, 0.25, 28.0, 3.2)
    b.add_drive("shoulder_pan_joint", profiles.cubic(0.0, 0.3, 0.0, 0.15), name="pan")
    return b


def test_urdf_model_pickles_and_copies_bit_for_bit():
    model = ad.load_urdf(ur5_path())
    ref = ad.simulate(model, 0.3, q0=common.UR5_Q0, qd0=np.full(6, 0.2), output_dt=0.01)
    copies = [pickle.loads(pickle.dumps(model, protocol=p)) for p in PROTOCOLS]
    copies += [copy.deepcopy(model), copy.copy(model)]
    for c in copies:
        assert isinstance(c, ad.Model) and c is not model
        assert_same_model(model, c)
        run = ad.simulate(c, 0.3, q0=common.UR5_Q0, qd0=np.full(6, 0.2), output_dt=0.01)
        assert_same_run(ref, run)


@pytest.mark.parametrize("coordinates", ["cartesian", "joint"])
def test_rich_model_and_builder_pickle_bit_for_bit(coordinates):
    b = rich_builder()
    if coordinates == "joint":  # the joint-space path takes no drives: a builder without one
        b = ad.urdf_builder(str(ur5_path()))
        b.add_actuator("shoulder_lift_joint", 80.0, 2e-5)
        b.add_coupling("wrist_couple", "wrist_3_joint", "wrist_2_joint", 0.5, 0.1)
        b.add_joint_torque("elbow_joint", profiles.sine(2.0, 3.0))
    model = b.finalize()
    kw = dict(output_dt=0.02, coordinates=coordinates)
    ref = ad.simulate(model, 0.2, **kw)
    assert ref.q.shape[0] == 11
    # the model, its copies, and a model finalized from the unpickled builder
    b2 = pickle.loads(pickle.dumps(b, protocol=2))
    assert b2.body_names == b.body_names and b2.frame_names == b.frame_names
    assert b2.physical_inertia == b.physical_inertia
    # every stored field is restored: storing the copy again gives the same bytes
    blob = pickle.dumps(model)
    assert pickle.dumps(pickle.loads(blob)) == blob
    assert pickle.dumps(b2) == pickle.dumps(b)
    others = [pickle.loads(blob), copy.deepcopy(model), b2.finalize()]
    others.append(copy.deepcopy(b).finalize())
    for c in others:
        assert_same_model(model, c)
        assert_same_run(ref, ad.simulate(c, 0.2, **kw))
    # the unpickled builder is a builder: it takes more elements, the original is unchanged
    b2.add_frame("second_tool", "wrist_3_link", (0.4, 0.25, 0.6))
    assert "second_tool" in b2.frame_names and "second_tool" not in b.frame_names


def test_geared_model_with_backlash_pickles():
    model = geared_arm_6dof(backlash=2e-4, t_end=0.03, t_start=0.0)
    ref = ad.simulate(model, 0.02, output_dt=0.002)
    c = pickle.loads(pickle.dumps(model))
    assert_same_model(model, c)
    assert_same_run(ref, ad.simulate(c, 0.02, output_dt=0.002))


def test_kkt_path_choice_travels():
    model = ad.load_urdf(ur5_path()).with_kkt_path("dense")
    c = pickle.loads(pickle.dumps(model))
    assert c.kkt_path == model.kkt_path == "dense"
    assert_same_run(ad.simulate(model, 0.1), ad.simulate(c, 0.1))


def test_builder_notes_travel():
    """A note the builder keeps for finalize (a clamped round-off inertia) survives pickling:
    the unpickled builder's finalize issues the same warning."""
    b = ad.ModelBuilder(physical_inertia=False)
    # a tensor with a negative round-off moment beyond 64 eps: clamped with a warning
    b.add_body("rod", 1.0, np.diag([1.0, 1.0, -1e-13]), (0.0, 0.0, -0.5), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("hinge", "ground", "rod", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    with pytest.warns(UserWarning) as original:
        b.finalize()
    with pytest.warns(UserWarning) as copied:
        pickle.loads(pickle.dumps(b)).finalize()
    assert [str(w.message) for w in copied] == [str(w.message) for w in original]


@pytest.mark.parametrize(
    "profile",
    [
        profiles.constant(1.25),
        profiles.cubic(0.1, 0.9, 0.2, 1.1),
        profiles.quintic(-0.3, 0.7, 0.0, 0.8),
        profiles.sine(0.5, 2.5, 0.3, -0.1),
        profiles.spline([0.0, 0.3, 0.5, 1.2], [0.0, 1.0, -0.5, 0.25]),
    ],
)
def test_profiles_pickle_and_evaluate_bit_for_bit(profile):
    ts = np.linspace(-0.5, 2.0, 101)
    for c in [pickle.loads(pickle.dumps(profile, protocol=p)) for p in PROTOCOLS] + [
        copy.deepcopy(profile)
    ]:
        assert repr(c) == repr(profile)
        assert all(c.eval(t) == profile.eval(t) for t in ts)


def test_callable_profile_cannot_travel_and_is_named():
    def push(t):
        return (t, 1.0, 0.0)

    b = ad.urdf_builder(str(ur5_path()))
    b.add_joint_torque("elbow_joint", push)
    with pytest.raises(ad.ModelError, match=r"torque input of coordinate 'elbow_joint'.*push"):
        pickle.dumps(b)
    model = b.finalize()
    with pytest.raises(ad.ModelError, match=r"user function.*cannot be stored"):
        pickle.dumps(model)
    with pytest.raises(ad.ModelError, match="push"):
        copy.deepcopy(model)
    b = ad.urdf_builder(str(ur5_path()))
    b.add_drive("elbow_joint", push, name="elbow_drive")
    with pytest.raises(ad.ModelError, match="drive 'elbow_drive'"):
        pickle.dumps(b.finalize())


def test_corrupt_state_is_refused():
    model = ad.load_urdf(ur5_path())
    state = model.__getstate__()
    blob = state[0]
    for bad in (blob[:-3], blob[:100], b"XXXX" + blob[4:], blob + b"\0"):
        with pytest.raises(ad.ModelError, match="model data"):
            ad.Model.__new__(ad.Model).__setstate__((bad,))


def test_model_travels_to_a_spawned_process():
    """A model sent to a fresh interpreter (multiprocessing's spawn: pickled both ways) runs
    there exactly as here."""
    model = ad.load_urdf(ur5_path())
    kw = dict(q0=common.UR5_Q0, limits="ignore")
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1) as pool:
        remote = pool.apply(ad.simulate, (model, 0.2), kw)
    assert_same_run(remote, ad.simulate(model, 0.2, **kw))
