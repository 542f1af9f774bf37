"""The fields of a run's result and of driven inverse dynamics, and their statistics, are declared
once: the field lists of the C++ headers (``ARMDYN_SIM_TABLES``, ``ARMDYN_SIM_STATS``, ... in
cpp/include/armdyn/simulate/result.hpp; ``ARMDYN_DRIVEN_ID_TABLES``, ... in
algorithm/driven_inverse_dynamics.hpp), from which the C++ structs and the bindings' result
dicts expand, exported as ``armdyn._core._SIM_FIELDS``, ``_SIM_STATS``, ``_DRIVEN_ID_FIELDS``
and ``_DRIVEN_ID_STATS`` ((name, doc) tuples, in order). The Python side follows them: the
dataclasses' fields and docstrings, the dicts a run returns, the zero-body result and the
work-precision counters are checked against these lists here."""

import dataclasses

import armdyn as ad
import numpy as np
from armdyn import _core, workprecision
from armdyn.dynamics import InverseDynamicsResult
from armdyn.simulation import SimulationResult, _zero_dof_result

#: the fields the Python dataclasses add to the C++ result (computed or kept in Python)
PYTHON_ONLY = {"actuators", "model"}


def _names(fields) -> list[str]:
    assert all(isinstance(n, str) and isinstance(doc, str) and doc for n, doc in fields)
    return [n for n, _ in fields]


def _required(cls) -> list[str]:
    """The dataclass fields without a default (the tables), in order."""
    return [
        f.name
        for f in dataclasses.fields(cls)
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]


def _rotor():
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("arm", 1.0, [0.01, 0.02, 0.03], position=(0.3, 0, 0))
    b.add_revolute("spin", "ground", "arm", point=(0, 0, 0), axis=(0, 1, 0))
    return b


def test_the_exported_lists_have_unique_names():
    for fields in (_core._SIM_FIELDS, _core._SIM_STATS, _core._DRIVEN_ID_FIELDS):
        assert len(set(_names(fields))) == len(fields)
    assert len(set(_names(_core._DRIVEN_ID_STATS))) == len(_core._DRIVEN_ID_STATS)


def test_simulation_result_fields_are_the_cpp_list():
    cpp = _names(_core._SIM_FIELDS)
    fields = [f.name for f in dataclasses.fields(SimulationResult)]
    assert set(fields) - PYTHON_ONLY == set(cpp)
    required = _required(SimulationResult)
    assert required == cpp[: len(required)]  # the tables first, in the C++ order
    for name in cpp:  # each documented
        assert f"{name}:" in SimulationResult.__doc__ or f" {name}," in SimulationResult.__doc__


def test_inverse_dynamics_result_fields_are_the_cpp_list():
    cpp = _names(_core._DRIVEN_ID_FIELDS)
    fields = [f.name for f in dataclasses.fields(InverseDynamicsResult)]
    assert set(fields) - PYTHON_ONLY == set(cpp)
    required = _required(InverseDynamicsResult)
    assert required == cpp[: len(required)]
    for name in cpp:
        assert name in InverseDynamicsResult.__doc__


def test_a_run_has_every_field_and_stat_of_the_lists():
    model = _rotor().finalize()
    r = ad.simulate(model, 0.2, output_dt=0.1)
    assert list(r.stats) == _names(_core._SIM_STATS)
    n = len(r.t)
    assert n == 3
    for name in _names(_core._SIM_FIELDS):
        value = getattr(r, name)
        if isinstance(value, np.ndarray):
            assert value.shape[0] == n, name
    assert r.error is None and set(r.gear_forces) == {"names", "force"}
    assert set(r.limit_forces) == {"names", "force"} and set(r.events) >= {"t", "limits"}


def test_driven_inverse_dynamics_has_every_field_and_stat():
    b = _rotor()
    b.add_drive("spin", ad.profiles.sine(0.3, 1.0))
    model = b.finalize()
    r = ad.driven_inverse_dynamics(model, np.linspace(0.0, 0.5, 4))
    assert list(r.stats) == _names(_core._DRIVEN_ID_STATS)
    for name in _names(_core._DRIVEN_ID_FIELDS):
        value = getattr(r, name)
        if isinstance(value, np.ndarray):
            assert value.shape[0] == 4, name


def test_the_zero_body_result_and_the_work_precision_counters_use_the_listed_stats():
    stats = _names(_core._SIM_STATS)
    model = ad.ModelBuilder().finalize()
    empty = _zero_dof_result(model, 1.0, None)
    assert set(empty.stats) <= set(stats)
    assert set(workprecision._COUNTERS) <= set(stats)
    assert set(workprecision._COUNTERS) <= set(workprecision.COLUMNS)
