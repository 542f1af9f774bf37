"""`benchmarks.peers.pinocchio.pinocchio_tree` (an armdyn tree rebuilt in Pinocchio from the model's
masses, inertias and joint frames) and the geared-arm reference built on it
(`benchmarks.references.GearedArmReference`, the `geared_arm` work-precision problem).

* The converter against Pinocchio's own URDF parser: the UR5 and the Panda loaded by armdyn
  (urdfdom) and converted must give Pinocchio's mass matrix and RNEA torques of the URDF loaded
  by Pinocchio, at random states (the URDFs have fixed joints, joint-frame rotations and
  inertial-frame offsets).
* The reference's tree equations (Pinocchio CRBA/RNEA and the PD motor law written out in
  Python) against armdyn's Lagrange validator (Euler–Lagrange by automatic differentiation) on
  the open tree of the geared arm.
* armdyn's run of the 44-body geared arm (Cartesian coordinates, ideal gears as constraint rows)
  against the reference integrated in the six gear-reduced arm angles.
"""

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

pin = pytest.importorskip("pinocchio")

from armdyn.papers.geared_arm import geared_arm_6dof  # noqa: E402

from benchmarks.peers.pinocchio import PinPair, mass_matrix, pinocchio_tree  # noqa: E402
from benchmarks.references import GearedArmReference  # noqa: E402
from benchmarks.workprecision import _Geared  # noqa: E402


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_tree_conversion_equals_pinocchios_urdf_parser(robot):
    pair = PinPair(common.robot_urdf(robot))
    conv, idx = pinocchio_tree(pair.am)
    cd = conv.createData()
    rng = np.random.default_rng(11)
    worst_m = worst_tau = 0.0
    for _ in range(20):
        q, v, a = rng.uniform(-np.pi, np.pi, size=(3, pair.pm.nq))  # Pinocchio's joint order
        qa, va, aa = (pair.to_armdyn(x) for x in (q, v, a))  # armdyn's coordinate order
        qc, vc, ac = (np.zeros(conv.nq) for _ in range(3))
        qc[idx], vc[idx], ac[idx] = qa, va, aa
        m_ref = mass_matrix(pin, pair.pm, pair.pd, q)
        m_conv = mass_matrix(pin, conv, cd, qc)[np.ix_(idx, idx)][np.ix_(pair.perm, pair.perm)]
        worst_m = max(worst_m, np.abs(m_conv - m_ref).max() / np.abs(m_ref).max())
        tau_ref = pin.rnea(pair.pm, pair.pd, q, v, a)
        tau_conv = pin.rnea(conv, cd, qc, vc, ac)[idx][pair.perm]
        worst_tau = max(worst_tau, np.abs(tau_conv - tau_ref).max() / np.abs(tau_ref).max())
    # measured: UR5 5.0e-16 and 4.8e-16, Panda 7.0e-16 and 7.0e-16
    assert worst_m <= 1e-12 and worst_tau <= 1e-12, (worst_m, worst_tau)


def test_tree_conversion_refuses_loops():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.01, 0.01, 0.01], position=(0, 0, 0))
    b.add_body("b", 1.0, [0.01, 0.01, 0.01], position=(1, 0, 0))
    b.add_revolute("ja", "ground", "a", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jb", "ground", "b", point=(1, 0, 0), axis=(0, 0, 1))
    b.add_gear("g", "ja", "jb", 0.1, 0.2)
    with pytest.raises(ad.ModelError, match="pinocchio_tree: the model is not a tree"):
        pinocchio_tree(b.finalize())


@pytest.fixture(scope="module")
def geared_ref():
    return GearedArmReference()


def test_geared_reference_equations_equal_the_lagrange_validator(geared_ref):
    # before, during and after the reference motion (the same check on other states is
    # geared_arm.json's reference_check: 3.8e-16)
    assert geared_ref.lagrange_check((0.2, 1.1, 2.5, 4.0), seed=3) <= 1e-12


def test_geared_arm_run_equals_the_pinocchio_reference():
    # the scene with its quintic move from 0.1 s (default 0.5 s): in 0.3 s the arm sags onto its
    # motors and starts the move (the default's 1.5 s run took 88 s of the suite, most of it
    # the reference's Python right-hand side)
    scene = {"t_start": 0.1, "t_end": 1.1}
    t = np.linspace(0.0, 0.3, 7)
    # Radau (stiff: the rotors' damping) at 1e-12: 1.0e-14 from DOP853 at 1e-11, in a quarter
    # of the time (measured)
    ref = GearedArmReference(**scene).angles(t, rtol=1e-12, method="Radau")
    model = geared_arm_6dof(backlash=0.0, **scene)
    res = ad.simulate(model, 0.3, integrator="dopri5", rtol=1e-8, atol=1e-8, output_dt=0.05)
    assert np.abs(ref).max() > 0.01  # the arm really moves
    assert np.abs(_Geared.observe(model, res) - ref).max() <= 2e-12  # measured 3.8e-13
