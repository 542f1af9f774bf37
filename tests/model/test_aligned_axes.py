"""Axes aligned to round-off: two bearings of one shaft whose axes differ by CAD round-off
(1e-9 rad) made finalize() report mobility 0 (an immobile shaft). Rows that are dependent to
within 1e-6 are now taken as dependent, with a warning naming them, and the shaft turns as the
closed form says."""

import warnings

import armdyn as ad
import numpy as np
import pytest

TAU, I_Z = 0.5, 0.002 + 0.01 + 1.0 * 0.3**2  # torque; shaft + arm about the axis (Steiner)


def shaft(misalignment: float):
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("shaft", 2.0, [0.01, 0.01, 0.002], position=(0.0, 0.0, 0.0))
    b.add_body("arm", 1.0, [0.001, 0.01, 0.01], position=(0.3, 0.0, 0.0))
    b.add_revolute("bearing_a", "ground", "shaft", point=(0, 0, -0.2), axis=(0, 0, 1))
    axis = (np.sin(misalignment), 0.0, np.cos(misalignment))
    b.add_revolute("bearing_b", "ground", "shaft", point=(0, 0, 0.2), axis=axis)
    b.add_fixed("hub", "shaft", "arm", point=(0, 0, 0))
    b.add_joint_torque("bearing_a", TAU)
    return b


@pytest.mark.parametrize("misalignment", [1e-9, 1e-7])
def test_bearings_aligned_to_round_off_turn_with_a_warning(misalignment):
    with pytest.warns(UserWarning, match=r"treated as dependent: joint 'bearing_[ab]' row 4"):
        model = shaft(misalignment).finalize()
    assert model.mobility == 1 and len(model.redundant_rows) == 5
    res = ad.simulate(model, 1.0, output_dt=0.25, rtol=1e-10, atol=1e-12)
    theta = 0.5 * TAU / I_Z * res.t**2  # constant torque about a fixed axis
    assert np.abs(res.q[:, 0] - theta).max() <= 10 * misalignment
    # the residual left is the misalignment's, and reported
    assert res.position_residual.max() <= 10 * misalignment


def test_exactly_aligned_bearings_do_not_warn_and_a_real_misalignment_locks():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert shaft(0.0).finalize().mobility == 1
    # 1e-4 rad is a real misalignment: the shaft cannot turn (mobility 0), no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert shaft(1e-4).finalize().mobility == 0
