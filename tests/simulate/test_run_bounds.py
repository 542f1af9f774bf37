"""Runs bounded before they start: ``dt`` must advance time, the outputs' memory (rows times the
bytes of a row) is checked against ``max_output_bytes`` with and without ``output_dt``, for
simulate and rollout; a progress callable that raises propagates with ``.result``."""

from __future__ import annotations

import re

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core

from benchmarks import common


def pendulum():
    b = ad.ModelBuilder()
    b.add_body("bob", 1.0, np.diag([1e-3, 1e-3, 1e-3]), position=(0.0, 0.0, -1.0))
    b.add_revolute("hinge", "ground", "bob", (0, 0, 0), (0, 1, 0))
    return b.finalize()


def ur5():
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return ad.load_urdf(path)


@pytest.mark.parametrize("integrator", ["rk4", "dopri5"])
@pytest.mark.parametrize("dt", [1e-300, 1e-17, 5e-15])
def test_dt_that_does_not_advance_time_is_refused(integrator, dt):
    """t_end = 1: 1e-300 and 1e-17 leave t + dt == t near t_end; 5e-15 moves t by a few
    units of its last place only (the minimum is 64 eps t_end = 1.42e-14)."""
    assert (1.0 + 1e-17 == 1.0) and (1.0 + 5e-15 > 1.0)
    with pytest.raises(ad.ModelError, match=r"simulate: dt=.* does not advance time"):
        ad.simulate(pendulum(), 1.0, integrator=integrator, dt=dt, output_dt=0.1)
    with pytest.raises(ad.ModelError, match=r"rollout: dt=.* does not advance time"):
        ad.rollout(pendulum(), [[0.1]], t_end=1.0, integrator=integrator, dt=dt, output_dt=0.1)


def test_the_smallest_dt_that_advances_time_runs():
    """dt = 64 eps t_end exactly is accepted (DOPRI5's first step, which then grows), and
    the same run gives the run without dt to the tolerance; just below is refused."""
    dt = 64 * np.finfo(float).eps * 1.0
    res = ad.simulate(pendulum(), 1.0, dt=dt, q0=[0.2], output_dt=0.5, rtol=1e-10, atol=1e-12)
    ref = ad.simulate(pendulum(), 1.0, q0=[0.2], output_dt=0.5, rtol=1e-10, atol=1e-12)
    assert res.t[-1] == 1.0
    np.testing.assert_allclose(res.q, ref.q, rtol=0, atol=1e-8)
    with pytest.raises(ad.ModelError, match=r"dt=1.42109e-14 does not advance time"):
        ad.simulate(pendulum(), 1.0, dt=np.nextafter(dt, 0), q0=[0.2], output_dt=0.5)


def test_rk4_without_output_dt_is_refused_before_it_starts_naming_dt():
    """The issue's case: RK4 on the UR5 with a tiny dt and no output_dt grew to 4.3 GiB and
    died in bad_alloc. Now its rows (t_end / dt + 2, one per step) times the row's bytes are
    checked first."""
    model = ur5()
    row = _core._output_row_bytes(model)
    dt, t_end = 1e-9, 1.0
    gib = (np.ceil(t_end / dt) + 2) * row / 1024**3
    assert gib > 2.0  # the default bound
    pattern = r"simulate: dt=1e-09 .* " + re.escape(f"{gib:.3g} GiB")
    with pytest.raises(ad.ModelError, match=pattern) as err:
        ad.simulate(model, t_end, integrator="rk4", dt=dt, q0=common.UR5_Q0)
    assert "output_dt" in str(err.value)
    # within the bound it runs
    res = ad.simulate(model, 0.01, integrator="rk4", dt=1e-3, q0=common.UR5_Q0)
    assert len(res.t) == 11


def test_adaptive_run_without_output_dt_stops_at_the_bound_with_its_result():
    """Without output_dt an adaptive run has one row per step: its max_steps is lowered to
    what max_output_bytes holds, and a run reaching it stops with a SolverError saying so, its
    outputs so far in .result (never more rows than the bound)."""
    model = pendulum()
    row = _core._output_row_bytes(model)
    bound = 40 * row
    with pytest.raises(ad.SolverError, match="max_output_bytes") as err:
        ad.simulate(model, 10.0, q0=[1.0], rtol=1e-10, atol=1e-12, max_output_bytes=bound)
    res = err.value.result
    assert 2 <= len(res.t) <= 40
    assert res.t[-1] < 10.0
    assert "max_steps was lowered from 10000000 to 38" in str(err.value)
    # the same run with output_dt fits the bound and completes
    ok = ad.simulate(model, 1.0, q0=[1.0], output_dt=0.05, max_output_bytes=bound)
    assert ok.t[-1] == 1.0


def test_rollout_outputs_are_bounded_over_all_runs():
    model = pendulum()
    row = _core._output_row_bytes(model)
    rows = 1.0 / 0.01 + 2
    bound = 3 * rows * row  # three runs fit, four do not
    ok = ad.rollout(model, [[0.1]] * 3, t_end=1.0, output_dt=0.01, max_output_bytes=bound)
    assert [r.status for r in ok] == ["ok"] * 3
    with pytest.raises(ad.ModelError, match=r"rollout: output_dt=0.01 .* for each of 4 runs"):
        ad.rollout(model, [[0.1]] * 4, t_end=1.0, output_dt=0.01, max_output_bytes=bound)
    with pytest.raises(ad.ModelError, match=r"rollout: max_output_bytes must be"):
        ad.rollout(model, [[0.1]], t_end=1.0, max_output_bytes=-1)


class Stop(Exception):
    pass


def raise_at_once(*args):
    raise Stop(f"progress called with {args}")


def test_a_progress_callable_raising_on_its_first_call_keeps_the_result():
    """A short run ends before the first 0.1 s report: the first call is the final one, with
    t = t_end; its exception propagates as itself with the complete result."""
    model = pendulum()
    with pytest.raises(Stop, match=r"progress called with \(0.5, 0.5\)") as err:
        ad.simulate(model, 0.5, q0=[0.3], output_dt=0.1, progress=raise_at_once)
    res = err.value.result
    assert isinstance(res, ad.SimulationResult)
    np.testing.assert_allclose(res.t, np.linspace(0.0, 0.5, 6), rtol=0, atol=1e-15)
    ref = ad.simulate(model, 0.5, q0=[0.3], output_dt=0.1)
    np.testing.assert_array_equal(res.q, ref.q)


def test_a_progress_callable_raising_in_rollout_keeps_the_results():
    model = pendulum()
    with pytest.raises(Stop, match=r"progress called with \(2, 2\)") as err:
        ad.rollout(model, [[0.1], [0.2]], t_end=0.5, output_dt=0.1, progress=raise_at_once)
    results = err.value.result
    assert [r.status for r in results] == ["ok", "ok"]
    ref = ad.simulate(model, 0.5, q0=[0.2], output_dt=0.1)
    np.testing.assert_array_equal(results[1].q, ref.q)


def test_a_progress_callable_raising_during_a_long_run_keeps_the_partial_result():
    """A run longer than 0.1 s: the callable's first call comes from the stepping loop, which
    stops the run; the outputs so far are in .result."""
    model = ur5()
    with pytest.raises(Stop) as err:
        ad.simulate(
            model, 1e3, q0=common.UR5_Q0, output_dt=0.01, limits="ignore", progress=raise_at_once
        )
    res = err.value.result
    assert 1 <= len(res.t) and res.t[-1] < 1e3
