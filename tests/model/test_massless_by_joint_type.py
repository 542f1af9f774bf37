"""finalize() refuses every joint whose motion carries no inertia, whatever its type (issue 31):
a massless leaf body, a mass too small to invert (1e-300 kg), and a point mass on a joint that
only turns it about its centre; and accepts light and point-mass bodies where the motion does
carry their inertia, with the mass matrix of the closed form."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest

TYPES = ("revolute", "prismatic", "cylindrical", "universal", "spherical", "free")
ARM_J = np.diag([0.01, 0.02, 0.02])


def _arm_with_hand(joint_type, mass, inertia):
    """A 1 kg arm on a hinge about z at the origin (centre of mass at x = 0.5), and a hand at
    x = 1 on a `joint_type` joint at its centre of mass (axis x where the joint has one)."""
    b = ad.ModelBuilder()
    b.add_body("arm", 1.0, ARM_J, position=(0.5, 0, 0))
    b.add_revolute("shoulder", "ground", "arm", (0, 0, 0), (0, 0, 1))
    b.add_body("hand", mass, inertia, position=(1.0, 0, 0))
    p, x = (1.0, 0, 0), (1, 0, 0)
    if joint_type == "revolute":
        b.add_revolute("tip", "arm", "hand", p, x)
    elif joint_type == "prismatic":
        b.add_prismatic("tip", "arm", "hand", p, x)
    elif joint_type == "cylindrical":
        b.add_cylindrical("tip", "arm", "hand", p, x)
    elif joint_type == "universal":
        b.add_universal("tip", "arm", "hand", p, x, (0, 1, 0))
    elif joint_type == "spherical":
        b.add_spherical("tip", "arm", "hand", p)
    else:
        b.add_free("tip", "hand")
    return b


@pytest.mark.parametrize("joint_type", TYPES)
def test_a_massless_leaf_is_refused_on_every_joint_type(joint_type):
    b = _arm_with_hand(joint_type, 0.0, np.zeros((3, 3)))
    with pytest.raises(ad.ModelError, match=r"'tip'.* carries no inertia.*body 'hand' \(mass 0"):
        b.finalize()


@pytest.mark.parametrize("joint_type", TYPES)
def test_a_mass_of_1e300_kg_is_refused_as_no_mass_on_every_joint_type(joint_type):
    # mass 1e-300 kg, whose reciprocal (1e300) overflows once squared: before issue 31 the slide
    # of such a body was accepted (its mass matrix [1e-300] is positive definite on its own) and
    # a finite force gave an overflowing acceleration; a massless body has mass 0
    b = _arm_with_hand(joint_type, 1e-300, np.zeros((3, 3)))
    with pytest.raises(ad.ModelError, match=r"body 'hand': mass = 1e-300 kg is below 1e-150"):
        b.finalize()


def test_a_light_body_on_a_slide_keeps_its_mass_exactly():
    # 1e-20 kg with 0.01 kg m^2, sliding along the arm: its slide carries its 1e-20 kg (positive
    # definite, as a light link's spin carries its own small inertia), which ABA keeps exactly
    model = _arm_with_hand("prismatic", 1e-20, np.eye(3) * 0.01).finalize()
    # shoulder: arm 0.02 + 1 * 0.5^2, hand 0.01 + 1e-20 * 1^2; the radial slide does not couple
    np.testing.assert_allclose(
        ad.mass_matrix(model, [0.0, 0.0]), [[0.28, 0.0], [0.0, 1e-20]], rtol=1e-14, atol=0
    )
    qdd = ad.forward_dynamics(model, [0.0, 0.0], [0.0, 0.0], [0.0, 3e-20], method="aba")
    np.testing.assert_allclose(qdd, [0.0, 3.0], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("joint_type", sorted(set(TYPES) - {"prismatic"}))
def test_a_point_mass_turned_about_its_centre_is_refused(joint_type):
    # 2 kg without rotational inertia, its centre of mass on the joint point: every rotation the
    # joint allows carries no inertia
    b = _arm_with_hand(joint_type, 2.0, np.zeros((3, 3)))
    with pytest.raises(ad.ModelError, match=r"'tip'.* carries no inertia.*'hand' \(mass 2 kg"):
        b.finalize()


def test_a_point_mass_on_a_slide_is_accepted_with_the_closed_form_mass_matrix():
    # the hand slides along the arm (x): the slide carries its 2 kg; the shoulder turns the arm
    # (0.02 + 1 * 0.5^2) and the hand at 1 m (2 * 1^2); the slide is radial, so no coupling
    model = _arm_with_hand("prismatic", 2.0, np.zeros((3, 3))).finalize()
    np.testing.assert_allclose(
        ad.mass_matrix(model, [0.4, 0.0]), [[2.27, 0.0], [0.0, 2.0]], rtol=1e-14, atol=1e-15
    )
