"""The run options of simulate and rollout are declared once (armdyn._run_options.RUN_OPTIONS):
simulate's explicit signature names exactly these options, in this order, with these defaults;
both docstrings document each of them; rollout forwards exactly these, at these defaults; and
each option's check refuses a bad value in both functions with a ModelError naming it."""

import inspect

import armdyn as ad
import numpy as np
import pytest
from armdyn import _run_options

OPTIONS = _run_options.RUN_OPTIONS


def test_simulate_signature_agrees_with_the_declaration():
    params = inspect.signature(ad.simulate).parameters
    names = [n for n in params if n in _run_options.NAMES]
    assert names == list(_run_options.NAMES)  # every option, in the declared order
    for o in OPTIONS:
        p = params[o.name]
        assert p.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD, o.name
        assert p.default == o.default and type(p.default) is type(o.default), o.name
    # the rest of the signature: the run's own arguments, not options
    others = [n for n in params if n not in _run_options.NAMES]
    assert others == ["model", "t_end", "q0", "qd0", "u0", "v0", "progress", "max_output_bytes"]
    assert len(OPTIONS) == 12


def test_docstrings_document_every_option():
    for o in OPTIONS:
        first = o.doc.splitlines()[0]
        assert f"\n        {o.name}: {first}\n" in ad.simulate.__doc__, o.name
    assert _run_options.ENTRIES_MARK not in ad.simulate.__doc__
    tail = ad.rollout.__doc__.split("**simulate_options:", 1)[1].split("Returns:", 1)[0]
    assert " ".join(tail.split()).endswith(", ".join(_run_options.NAMES) + ".")


def test_rollout_forwards_exactly_the_options():
    with pytest.raises(TypeError, match=r"unknown option\(s\) q_start"):
        ad.rollout(ad.scenes.double_pendulum(), [[0.1, 0.2]], t_end=0.1, q_start=1)
    # the defaults are the declared ones: the same run as simulate's, bit for bit
    model = ad.scenes.double_pendulum()
    one = ad.simulate(model, 0.2, q0=[0.3, -0.2], output_dt=0.05)
    (batch,) = ad.rollout(model, [[0.3, -0.2]], t_end=0.2, threads=1, output_dt=0.05)
    np.testing.assert_array_equal(batch.q, one.q)
    np.testing.assert_array_equal(batch.t, one.t)


BAD = {
    "integrator": "rk5",
    "rtol": -1.0,
    "atol": float("nan"),
    "dt": 0.0,
    "output_dt": "0.1",
    "projection": "metric",
    "max_steps": 1.5,
    "max_step": -1.0,
    "merge_welded": 1,
    "coordinates": "polar",
    "limits": "clip",
    "restitution": 1.5,
}


@pytest.mark.parametrize("name", list(_run_options.NAMES))
def test_each_option_refused_naming_it(name):
    assert set(BAD) == set(_run_options.NAMES)
    model = ad.scenes.double_pendulum()
    with pytest.raises(ad.ModelError, match=rf"^simulate: {name} must be"):
        ad.simulate(model, 0.1, **{name: BAD[name]})
    with pytest.raises(ad.ModelError, match=rf"^rollout: {name} must be"):
        ad.rollout(model, [[0.1, 0.2]], t_end=0.1, **{name: BAD[name]})


def test_core_options_are_what_the_run_takes():
    core = _run_options.core_options("simulate", _run_options.DEFAULTS)
    assert core == {
        "integrator": "default",
        "rtol": 1e-6,
        "atol": 1e-8,
        "dt": 0.0,
        "output_dt": 0.0,
        "projection": "mass",
        "max_steps": 10_000_000,
        "max_step": 0.0,
        "merge_welded": True,
        "coordinates": "auto",
        "limits": True,
        "restitution": 0.0,
    }
    ignore = _run_options.core_options("rollout", {**_run_options.DEFAULTS, "limits": "ignore"})
    assert ignore["limits"] is False
