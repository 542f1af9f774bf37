"""A joint held on its stop is released when its load reverses, however long the step before.

Issue 36 follow-up: a mechanism held still on a stop has a zero error estimate (nothing moves),
so the adaptive steps grew without bound (the first one 0 -> 1.6 s in joint space) and stepped
over an interval where the holding force (the held stop's event function) turned negative and
back: the release never happened. A pendulum held under a sine joint torque kept its stop in
joint space at the default tolerance, and in Cartesian coordinates too (the Cartesian run caught
it only at tight tolerances, where the projection's round-off kept its steps short). While a
stop is held the steps are now bounded by the applied loads' time scales and land on their
breakpoints (LimitStops::step_bound).

References: the closed-form release time, where the static torque at the limit (gravity's
-m g L sin q plus the applied torque) changes sign, found with scipy's brentq; the holding force
X - tau(t) of the static balance before it.
"""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest
from scipy.optimize import brentq

G = 9.81
Q_LIM = 0.5
X = G * np.sin(Q_LIM)  # gravity's torque into the lower stop, m g L sin q (m = L = 1)
COORDINATES = ["cartesian", "joint"]
TIGHT = dict(rtol=1e-10, atol=1e-12)


def held_pendulum(*torques):
    """A 1 kg bob on a massless 1 m arm hinged about +y, resting on its lower stop at 0.5 rad
    (gravity loads it with X = g sin 0.5), with the joint torques given."""
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("bob", 1.0, np.eye(3) * 1e-4, position=(0, 0, -1.0))
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.set_joint_limits("hinge", Q_LIM, 2.0)
    for p in torques:
        b.add_joint_torque("hinge", p)
    return b.finalize()


def _first_release(r):
    ev = r.events["limits"]
    kinds = list(ev["kind"])
    assert kinds[0] == "rest" and ev["t"][0] == 0.0
    assert "release" in kinds, kinds
    k = kinds.index("release")
    assert k == 1 and ev["joint"][k] == "hinge" and ev["side"][k] == "lower"
    return ev["t"][k]


def _quintic(s):
    return 10 * s**3 - 15 * s**4 + 6 * s**5


@pytest.mark.parametrize("coordinates", COORDINATES)
@pytest.mark.parametrize("tol", ["default", "tight"])
@pytest.mark.parametrize("integrator", ["dopri5", "dop853", "trbdf2"])
def test_a_sine_torque_releases_the_held_pendulum_at_the_closed_form_time(
    coordinates, tol, integrator
):
    """tau(t) = 1.3 X sin(2 pi 0.8 t): the holding force X - tau(t) turns negative where
    sin(2 pi 0.8 t) = 1 / 1.3, at about 0.176 s; before the fix the still, held state let the
    first steps grow past the whole negative interval (joint space, default tolerance: no
    release). Until the release the stop holds with X - tau(t)."""
    amp, f = 1.3 * X, 0.8
    model = held_pendulum(ad.profiles.sine(amp, f))
    kw = TIGHT if tol == "tight" else {}
    r = ad.simulate(
        model, 1.0, q0=[Q_LIM], qd0=[0.0], coordinates=coordinates, integrator=integrator, **kw
    )
    assert r.error is None
    t_star = brentq(lambda t: X - amp * np.sin(2 * np.pi * f * t), 0.0, 1 / (4 * f), xtol=1e-15)
    np.testing.assert_allclose(_first_release(r), t_star, rtol=1e-9)
    before = r.t < t_star
    np.testing.assert_allclose(r.q[before, 0], Q_LIM, atol=1e-12)
    np.testing.assert_allclose(
        r.limit_forces["force"][before, 0],
        X - amp * np.sin(2 * np.pi * f * r.t[before]),
        rtol=1e-9,
        atol=1e-9,
    )


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_a_short_pulse_after_a_long_hold_releases_the_joint(coordinates):
    """Held by gravity alone for 2 s (the steps grow long: longer than the pulse), then a
    torque pulse of 20 ms, up to 1.5 X along a quintic over [2, 2.01] and back down over
    [2.01, 2.02]: the holding force X - 1.5 X s((t - 2) / 0.01) turns negative where s = 2/3
    and the joint leaves its stop there."""
    up = ad.profiles.quintic(0.0, 1.5 * X, 2.0, 2.01)
    down = ad.profiles.quintic(0.0, -1.5 * X, 2.01, 2.02)
    model = held_pendulum(up, down)
    r = ad.simulate(model, 3.0, q0=[Q_LIM], qd0=[0.0], coordinates=coordinates, **TIGHT)
    assert r.error is None
    # (an output at every accepted step: the premise, a step before the pulse longer than it)
    hold = r.t <= 2.0
    assert np.diff(r.t[hold]).max() > 0.02
    t_star = 2.0 + 0.01 * brentq(lambda s: X - 1.5 * X * _quintic(s), 0.0, 1.0, xtol=1e-15)
    np.testing.assert_allclose(_first_release(r), t_star, rtol=1e-10)
    assert r.q[:, 0].max() > Q_LIM + 1e-6  # it left the stop
    assert r.q[:, 0].min() >= Q_LIM - 1e-9


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_a_long_hold_under_a_constant_load_never_releases_and_takes_few_steps(coordinates):
    """10 s held under gravity and a constant 0.4 X torque off the stop: no time scale to
    sample, so no bound on the steps (a few dozen), no release; the stop holds with 0.6 X
    throughout."""
    model = held_pendulum(ad.profiles.constant(0.4 * X))
    r = ad.simulate(
        model, 10.0, q0=[Q_LIM], qd0=[0.0], output_dt=0.1, coordinates=coordinates, **TIGHT
    )
    assert r.error is None
    assert list(r.events["limits"]["kind"]) == ["rest"]
    assert r.stats["steps"] < 40
    np.testing.assert_allclose(r.q[:, 0], Q_LIM, atol=1e-12)
    np.testing.assert_allclose(r.limit_forces["force"][:, 0], 0.6 * X, rtol=1e-10)


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_a_held_joint_under_a_ramp_that_stays_below_the_hold_is_sampled_only_on_the_ramp(
    coordinates,
):
    """10 s held while a torque ramps from 0 to 0.8 X along a quintic over [4, 5] (never enough
    to lift the joint): the steps land on the ramp's start and end, take at most 1/16 of its
    duration on it, and grow again after it; no release, the force X - 0.8 X s(t - 4)."""
    model = held_pendulum(ad.profiles.quintic(0.0, 0.8 * X, 4.0, 5.0))
    r = ad.simulate(model, 10.0, q0=[Q_LIM], qd0=[0.0], coordinates=coordinates, **TIGHT)
    assert r.error is None
    assert list(r.events["limits"]["kind"]) == ["rest"]
    assert np.any(r.t == 4.0) and np.any(r.t == 5.0)
    on = (r.t > 4.0) & (r.t <= 5.0)
    assert np.diff(r.t)[on[1:]].max() <= 1 / 16 + 1e-12
    # 16 steps on the ramp, and after it the steps grow again at once (the start's own
    # step-size ramp-up from rest, which differs between the formulations, is not the point)
    assert np.count_nonzero(on) == 16
    assert np.count_nonzero(r.t > 5.0) <= 4
    s = _quintic(np.clip(r.t - 4.0, 0.0, 1.0))
    np.testing.assert_allclose(r.limit_forces["force"][:, 0], X - 0.8 * X * s, rtol=1e-9)
