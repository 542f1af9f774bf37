"""Keyword arguments of the compiled functions (cpp/bindings/fast_keywords.cpp).

The module-level functions match keywords themselves and call pybind11's dispatcher with
positional arguments: every way of passing the same arguments gives the same answer, bit for bit,
and what the fast path does not take (unknown, repeated or missing arguments) raises pybind11's
own TypeError naming the function.
"""

from __future__ import annotations

import inspect
import itertools
import pickle

import armdyn as ad
import armdyn._core as core
import numpy as np
import pytest


@pytest.fixture(scope="module")
def model():
    """Three links with skew hinge axes: the methods differ in the last bits."""
    b = ad.ModelBuilder()
    parent = "ground"
    for i, axis in enumerate([(0, 0, 1), (0, 1, 0), (1, 0, 1)]):
        b.add_body(f"l{i}", 1.0 + i, np.diag([0.01, 0.02, 0.03]), position=(0.3 * i + 0.15, 0, 0))
        b.add_revolute(f"j{i}", parent, f"l{i}", (0.3 * i, 0, 0), axis)
        parent = f"l{i}"
    return b.finalize()


def _state(model, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1, 1, size=(3, model.n_coords))


def _all_spellings(fn, required: dict, optional: dict):
    """Every split of the arguments into a positional prefix and keywords in any order (the
    optional ones present or left to their defaults)."""
    names = list(inspect.signature(fn).parameters)
    given = {**required, **optional}
    order = [n for n in names if n in given]
    for k in range(len(order) + 1):
        pos = order[:k]
        if any(n not in given for n in names[:k]) or names[:k] != pos:
            continue
        rest = order[k:]
        for perm in itertools.permutations(rest):
            yield [given[n] for n in pos], {n: given[n] for n in perm}


@pytest.mark.parametrize("method", ["cartesian", "crba", "aba"])
def test_forward_dynamics_any_spelling_same_answer(model, method):
    q, qd, tau = _state(model)
    ref = ad.forward_dynamics(model, q, qd, tau, 0.25, method, None)
    data = ad.Data(model)
    count = 0
    for args, kw in _all_spellings(
        ad.forward_dynamics,
        {"model": model, "q": q, "qd": qd, "tau": tau},
        {"t": 0.25, "method": method, "data": data},
    ):
        np.testing.assert_array_equal(ad.forward_dynamics(*args, **kw), ref)
        count += 1
    assert count > 100  # 7! / ... spellings: the keywords really vary


def test_defaults_fill_the_gaps(model):
    q, qd, tau = _state(model, 1)
    ref = ad.forward_dynamics(model, q, qd, tau, 0.0, "cartesian", None)
    # method given, t and data left to their defaults (a gap before the keyword)
    np.testing.assert_array_equal(ad.forward_dynamics(model, q, qd, tau, method="cartesian"), ref)
    np.testing.assert_array_equal(
        ad.forward_dynamics(model, q, qd, tau=tau, data=None, method="cartesian"), ref
    )
    # the default method differs from an explicit one where it matters: the keyword is used
    aba = ad.forward_dynamics(model, q, qd, tau, method="aba")
    np.testing.assert_allclose(aba, ref, rtol=1e-10, atol=1e-12)


def test_other_functions_take_keywords(model):
    q, qd, qdd = _state(model, 2)
    ref = ad.inverse_dynamics(model, q, qd, qdd)
    np.testing.assert_array_equal(ad.inverse_dynamics(model=model, qdd=qdd, qd=qd, q=q), ref)
    np.testing.assert_array_equal(ad.mass_matrix(q=q, model=model), ad.mass_matrix(model, q))
    data = ad.Data(model)
    np.testing.assert_array_equal(
        ad.mass_matrix(model, q, data=data), ad.mass_matrix(model, q, data=None)
    )


@pytest.mark.parametrize(
    "kwargs, culprit",
    [
        ({"metod": "aba"}, "metod='aba'"),  # unknown
        ({"q": 0.0}, "q=0.0"),  # given twice
        ({"t": 0.0, "data": None, "extra": 1}, "extra=1"),
    ],
)
def test_bad_keywords_raise_pybind11s_type_error(model, kwargs, culprit):
    q, qd, tau = _state(model)
    with pytest.raises(TypeError, match="forward_dynamics") as e:
        ad.forward_dynamics(model, q, qd, tau, **kwargs)
    assert "incompatible function arguments" in str(e.value)
    assert culprit in str(e.value)


def test_missing_argument_with_keywords_raises(model):
    q, qd, _ = _state(model)
    with pytest.raises(TypeError, match="incompatible function arguments"):
        ad.forward_dynamics(model, q, qd, method="cartesian")  # tau missing, no default
    with pytest.raises(TypeError, match="incompatible function arguments"):
        ad.forward_dynamics(model, q, qd, 0.0, 0.0, "aba", None, "one too many")


def test_bad_values_by_keyword_keep_armdyns_messages(model):
    q, qd, tau = _state(model)
    with pytest.raises(ad.ModelError, match="method must be"):
        ad.forward_dynamics(model, q, qd, tau, method="nope")
    with pytest.raises(ad.ModelError, match="t is not finite"):
        ad.forward_dynamics(model, q, qd, tau=tau, t=float("nan"))
    with pytest.raises(ad.ModelError, match="tau"):
        ad.forward_dynamics(model, q, qd, tau=np.zeros(model.n_coords + 1))


def test_functions_stay_builtins_that_pickle_and_introspect():
    f = core.forward_dynamics
    assert type(f).__name__ == "builtin_function_or_method"
    assert pickle.loads(pickle.dumps(f)) is f
    assert list(inspect.signature(f).parameters) == [
        "model",
        "q",
        "qd",
        "tau",
        "t",
        "method",
        "data",
    ]
    assert f.__doc__.startswith("forward_dynamics(model: ")


class _Name(str):
    """A str subclass as a keyword name (allowed by CPython in **kwargs)."""


def test_hostile_keyword_names(model):
    q, qd, tau = _state(model)
    ref = ad.forward_dynamics(model, q, qd, tau, 0.0, "aba")
    # a str subclass naming a real parameter is that parameter
    np.testing.assert_array_equal(
        ad.forward_dynamics(model, q, qd, tau, **{_Name("method"): "aba"}), ref
    )
    bad = [
        {"méthode": "aba"},  # non-ASCII
        {"method" * 10_000: "aba"},  # huge
        {"meth\x00od": "aba"},  # an embedded NUL: not "method"
        {"t\x00x": 0.0},  # nor "t" (a C-string comparison would stop at the NUL)
        {f"k{i}": i for i in range(1000)},  # many unknown keywords
        {"": 1},  # empty
    ]
    for kw in bad:
        with pytest.raises(TypeError, match="incompatible function arguments"):
            ad.forward_dynamics(model, q, qd, tau, **kw)
    # every parameter by keyword, and one too many
    full = {"model": model, "q": q, "qd": qd, "tau": tau, "t": 0.0, "method": "aba", "data": None}
    np.testing.assert_array_equal(ad.forward_dynamics(**full), ref)
    with pytest.raises(TypeError, match="incompatible function arguments"):
        ad.forward_dynamics(**full, extra=1)
