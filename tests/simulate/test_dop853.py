"""DOP853 (Dormand–Prince 8(5,3) with 7th-order dense output) against closed forms and a second
method.

* Order: the IFToMM A01 pendulum (a Cartesian body on a revolute joint, projected after every
  step) against its closed form in Jacobi elliptic functions (``benchmarks.references``). With the
  error control switched off (``rtol = atol = 1`` and ``max_step = h``: every step is accepted
  at exactly h) the error at the step ends must fall as h^8, and at output times inside the
  steps (the dense output, whose local error is O(h^8)) at least as h^7. A wrong coefficient in
  the tables drops the order.
* Error control: Andrews' squeezer against the seven-angle index-1 reference (a different
  formulation, ``benchmarks.references.squeezer_angles``): the error follows rtol, and the 8th-order
  pair needs far fewer steps than DOPRI5 at a tight tolerance.
* Events and energy: see ``test_gears.py`` and ``test_conservation.py`` (parametrized over the
  integrators).
"""

import itertools

import armdyn as ad
import numpy as np
import pytest
from armdyn.scenes import standard

from benchmarks import references
from benchmarks.common import error, output_times
from benchmarks.workprecision import PROBLEMS


def _a01_errors(n: int, t_end: float = 2.0):
    model = standard.iftomm_a01_pendulum()
    h = t_end / n
    fixed = dict(integrator="dop853", rtol=1.0, atol=1.0, dt=h, max_step=h)
    steps = ad.simulate(model, t_end, **fixed)
    assert steps.stats["steps"] == n and steps.stats["rejected"] == 0
    dense = ad.simulate(model, t_end, output_dt=0.01, **fixed)
    err = [np.abs(r.u[:, :2] - references.a01_points(r.t)).max() for r in (steps, dense)]
    return err[0], err[1]


def test_dop853_is_eighth_order_against_the_closed_form():
    errs = [_a01_errors(n) for n in (8, 16, 32, 64)]
    step_orders = [np.log2(a[0] / b[0]) for a, b in itertools.pairwise(errs)]
    dense_orders = [np.log2(a[1] / b[1]) for a, b in itertools.pairwise(errs)]
    # measured 8.70, 8.84, 7.93 at the step ends; 7.87, 8.62, 8.01 on the dense output
    assert min(step_orders) >= 7.5, step_orders
    assert min(dense_orders) >= 7.0, dense_orders
    assert errs[-1][0] <= 1e-11 and errs[-1][1] <= 1e-10


@pytest.mark.parametrize("rtol", [1e-6, 1e-8, 1e-10])
def test_dop853_error_follows_rtol_on_the_squeezer(rtol):
    p = PROBLEMS["squeezer"]
    t = output_times(p)
    ref = p.reference(t)
    model = p.build()
    res = ad.simulate(model, p.t_end, integrator="dop853", rtol=rtol, atol=rtol, output_dt=t[1])
    err = error(p, p.observe(model, res), ref)  # angle differences wrapped to (-pi, pi]
    assert err <= 2.0 * rtol  # measured 0.92, 0.82, 0.35 times rtol
    assert res.position_residual.max() <= 1e-12
    if rtol == 1e-10:
        dp5 = ad.simulate(model, p.t_end, integrator="dopri5", rtol=rtol, atol=rtol, output_dt=t[1])
        assert res.stats["steps"] < 0.25 * dp5.stats["steps"]  # measured 142 against 785


def test_a_stage_that_cannot_be_evaluated_rejects_the_step():
    """IFToMM A02 at rtol 1e-4: DOP853's large steps put a stage, off the constraint manifold
    near the singular position, where the accelerations are not finite (before this, the run
    stopped there at t = 0.82 s). The step is rejected and retried smaller, and the run stays on
    the one-DOF branch to within the tolerance's order (measured 6.2e-4 m)."""
    p = PROBLEMS["a02"]
    model = p.build()
    t = output_times(p)
    res = ad.simulate(
        model, p.t_end, integrator="dop853", rtol=1e-4, atol=1e-4, output_dt=t[1], **p.init(model)
    )
    assert res.t[-1] == pytest.approx(p.t_end)
    assert error(p, p.observe(model, res), p.reference(t)) <= 2e-3
