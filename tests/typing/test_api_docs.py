"""Every public name of armdyn has a docstring, and inspect.signature works on every public
callable, compiled ones included, with the parameter names the docstrings document."""

from __future__ import annotations

import inspect
import re
import types
from typing import Any

import armdyn as ad
import numpy as np
import pytest
from api_walk import is_compiled, prose, public_api, pybind11_lines

API = public_api()
CALLABLES = [
    (q, o)
    for q, o in API
    if not isinstance(o, (property, types.ModuleType))
    and not inspect.isclass(o)
    and type(o).__name__ != "property"
]


def test_the_walk_sees_the_api():
    names = {q for q, _ in API}
    # a few names from each layer: compiled and Python, functions, classes, methods, properties
    for q in (
        "simulate",
        "ModelBuilder.add_revolute",
        "ModelBuilder.set_joint_limits",
        "ModelBuilder.add_joint_torque",
        "ModelBuilder.joint_names",
        "Model.coord_names",
        "Profile.eval",
        "SimulationResult.total_energy",
        "profiles.cubic",
        "actuators.motor_side",
        "validation.LagrangeValidator.torques",
        "scenes.basic",
    ):
        assert q in names, q
    assert len(API) > 200


def test_every_public_name_has_a_docstring():
    missing = [q for q, o in API if len(prose(q.rsplit(".", 1)[-1], o.__doc__)) < 10]
    assert not missing, "public names without a docstring: " + ", ".join(missing)


def _pybind11_params(name: str, doc: str) -> list[str] | None:
    """Parameter names of pybind11's (single) signature line, markers dropped."""
    lines = pybind11_lines(name, doc)
    if len(lines) != 1:
        return None
    inner = lines[0][len(name) + 1 : lines[0].rindex(") -> ")] if " -> " in lines[0] else None
    if inner is None:
        return None
    depth, cur, parts = 0, "", []
    for ch in inner:
        depth += ch in "([{"
        depth -= ch in ")]}"
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    names = [p.split(":")[0].split("=")[0].strip() for p in parts if p.strip()]
    return [n for n in names if n not in ("*", "/")]


def _documented_args(doc: str) -> list[str]:
    """Names listed in a Google-style ``Args:`` section."""
    m = re.search(r"^(\s*)Args:\n((?:\1\s+.*\n?|\s*\n)+)", doc, re.M)
    if not m:
        return []
    indent = None
    out = []
    for line in m.group(2).splitlines():
        if not line.strip():
            continue
        lead = len(line) - len(line.lstrip())
        indent = lead if indent is None else indent
        if lead == indent:
            head = line.strip().split(":")[0]
            out += [h.strip().lstrip("*") for h in head.split(",")]
    return [n for n in out if n.isidentifier()]


@pytest.mark.parametrize("qual, obj", CALLABLES, ids=[q for q, _ in CALLABLES])
def test_signature(qual: str, obj: Any):
    sig = inspect.signature(obj)
    params = [p.name for p in sig.parameters.values() if p.kind not in (p.VAR_KEYWORD,)]
    name = qual.rsplit(".", 1)[-1]
    doc = obj.__doc__ or ""
    if is_compiled(obj):
        documented = _pybind11_params(name, doc)
        assert documented is not None, f"{qual}: no single pybind11 signature line in __doc__"
        if inspect.isclass(obj):
            return
        assert [p.name for p in sig.parameters.values()] == documented, qual
    else:
        for arg in _documented_args(doc):
            assert arg in sig.parameters or any(
                p.kind == p.VAR_KEYWORD for p in sig.parameters.values()
            ), f"{qual}: documents argument {arg!r}, not in {params}"


@pytest.mark.parametrize(
    "cls", [ad.Model, ad.ModelBuilder, ad.Data, ad.Profile, ad.Motor, ad.Actuator]
)
def test_compiled_classes_have_typed_text_signatures(cls):
    # every pybind11 method exposes __text_signature__ (the pybind11 line stays in __doc__)
    for name, value in vars(cls).items():
        if type(value).__name__ != "instancemethod" or name == "_pybind11_conduit_v1_":
            continue
        fn = getattr(cls, name)
        assert fn.__text_signature__ and fn.__text_signature__.startswith("(self"), (cls, name)
        assert pybind11_lines(name, fn.__doc__), (cls, name)


def test_methods_unbound_and_bound():
    expected = ["name", "parent", "child", "point", "axis"]
    unbound = inspect.signature(ad.ModelBuilder.add_revolute)
    assert list(unbound.parameters) == ["self", *expected]
    bound = inspect.signature(ad.ModelBuilder().add_revolute)
    assert list(bound.parameters) == expected
    # defaults: Python literals kept, anything else as ...
    sig = inspect.signature(ad.ModelBuilder.add_frame)
    assert sig.parameters["position"].default == (0.0, 0.0, 0.0)
    assert sig.parameters["orientation"].default == (1.0, 0.0, 0.0, 0.0)
    sig = inspect.signature(ad.ModelBuilder.add_motor)
    assert sig.parameters["torque_limit"].default == 1e300
    assert sig.parameters["feedforward"].default is None
    # keyword-only markers survive
    sig = inspect.signature(ad.urdf_builder)
    assert sig.parameters["mimic"].kind is inspect.Parameter.KEYWORD_ONLY
    assert sig.parameters["fixed_base"].kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
    assert list(inspect.signature(ad.Motor).parameters)[:2] == ["name", "torque_constant"]
    # the signature binds the way the function is called
    sig = inspect.signature(ad.frame_pose)
    bound_args = sig.bind(object(), np.zeros(2), "tip")
    assert bound_args.arguments["frame"] == "tip"
    assert sig.parameters["data"].default is None


def test_docstrings_keep_the_pybind11_signature_for_stubgen():
    doc = ad.ModelBuilder.add_revolute.__doc__
    assert doc.startswith("add_revolute(self: armdyn._core.ModelBuilder, name: str")
    assert "point: numpy.typing.ArrayLike" in doc
    assert ad.ModelBuilder.add_revolute.__text_signature__ == (
        "(self, name, parent, child, point, axis)"
    )
