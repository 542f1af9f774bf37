"""finalize() refuses a model whose scales overflow the dynamics (issue 31): masses, squared
lengths and inertias about the world origin up to 1e150 (the products of two of them stay
finite), naming the body or joint and the quantity; models at large but representable scales
load and give finite, exact answers."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest

I3 = np.diag([0.01, 0.01, 0.01])


def _hinge(point=(0.0, 0.0, 0.0), position=(0.5, 0.0, 0.0), mass=1.0, inertia=I3):
    b = ad.ModelBuilder()
    b.add_body("arm", mass, inertia, position=position)
    b.add_revolute("shoulder", "ground", "arm", point, (0, 0, 1))
    return b


def _urdf(mass: str = "1", com: str = "0.5 0 0", joint: str = "0 0 0") -> str:
    return f"""<robot name="r"><link name="base"/>
<link name="arm"><inertial><origin xyz="{com}"/><mass value="{mass}"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
<joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
<origin xyz="{joint}"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
</joint></robot>"""


def test_a_joint_point_of_1e100_is_refused_naming_the_joint():
    # before: accepted, with a mass matrix of 1e200 and simulate's "initial state contains NaN"
    b = _hinge(point=(1e100, 0.0, 0.0))
    with pytest.raises(
        ad.ModelError,
        match=r"joint 'shoulder': squared distance of its point .* = 1e\+200 m\^2.*exceeds 1e\+150",
    ):
        b.finalize()


def test_urdf_origins_of_1e100_and_1e300_are_refused_naming_the_link():
    # the joint's origin places the link (its body) 1e100 m out; an inertial origin of 1e300 m
    # places its centre of mass there
    with pytest.raises(ad.ModelError, match=r"body 'arm': squared distance .* = 1e\+200 m\^2"):
        ad.load_urdf(_urdf(joint="1e100 0 0"))
    with pytest.raises(ad.ModelError, match=r"body 'arm': squared distance .* = inf m\^2"):
        ad.load_urdf(_urdf(com="1e300 0 0"))


def test_a_body_at_1e300_is_refused_naming_the_body():
    # before: accepted, with a NaN mass matrix
    with pytest.raises(ad.ModelError, match=r"body 'arm': squared distance .* = inf m\^2"):
        _hinge(position=(1e300, 0.0, 0.0)).finalize()
    with pytest.raises(ad.ModelError, match=r"body 'arm'.*mass x distance\^2"):
        _hinge(position=(1e71, 0.0, 0.0), mass=1e10).finalize()


def test_a_mass_of_1e300_is_refused_naming_the_body():
    with pytest.raises(ad.ModelError, match=r"body 'arm'.*mass = 1e\+300 kg"):
        _hinge(mass=1e300).finalize()
    with pytest.raises(ad.ModelError, match=r"body 'arm'.*mass = 1e\+300 kg.*exceeds 1e\+150"):
        ad.load_urdf(_urdf(mass="1e300"))
    with pytest.raises(ad.ModelError, match=r"body 'arm'.*trace of the inertia"):
        _hinge(inertia=np.eye(3) * 1e200).finalize()


def test_large_but_representable_scales_load_and_give_exact_dynamics():
    # a 1e60 kg arm 1e40 m long (inertia about the hinge m (L/2)^2 + J = 2.5e139 kg m^2): its
    # mass matrix and gravity-free swing against the closed form
    big = _hinge(mass=1e60, position=(0.5e40, 0.0, 0.0), inertia=I3 * 1e140)
    model = big.finalize()
    m_ref = 1e60 * 0.25e80 + 0.01e140
    np.testing.assert_allclose(ad.mass_matrix(model, [0.3]), [[m_ref]], rtol=1e-14)
    qdd = ad.forward_dynamics(model, [0.3], [0.0], [m_ref * 2.0])
    assert np.all(np.isfinite(qdd))
    # gravity -z acts along the hinge axis z: only the applied torque accelerates
    np.testing.assert_allclose(qdd, [2.0], rtol=1e-12)
