"""The public API of armdyn as the typing tests walk it: every name of ``armdyn.__all__``, the
public names of its public submodules (``actuators``, ``scenes`` and its modules,
``validation``, ``profiles``), the papers' scenes (``papers.five_dof``, ``papers.geared_arm``),
and the public methods and properties of every public class."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import re
import types
from collections.abc import Iterator
from typing import Any

import armdyn as ad


def _defined_in(obj: Any, module: types.ModuleType) -> bool:
    """Whether obj belongs to module (not a name it imports from elsewhere)."""
    home = getattr(obj, "__module__", None)
    return home is None or home == module.__name__ or home.startswith(module.__name__ + ".")


def _module_names(module: types.ModuleType) -> list[str]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n in vars(module) if not n.startswith("_")]
    return [n for n in names if not isinstance(getattr(module, n), types.ModuleType)]


def _generated_init(cls: type, fn: Any) -> bool:
    """A dataclass's generated __init__ (documented by the class's docstring)."""
    code = getattr(fn, "__code__", None)
    return dataclasses.is_dataclass(cls) and code is not None and code.co_filename == "<string>"


def _members(qual: str, cls: type) -> Iterator[tuple[str, Any]]:
    for name, value in vars(cls).items():
        if name.startswith("_") and name != "__init__":
            continue
        if name == "__init__" and _generated_init(cls, value):
            continue
        if isinstance(value, (staticmethod, classmethod)):
            value = value.__func__
        if isinstance(value, property) or callable(value):
            yield f"{qual}.{name}", value


def public_api() -> list[tuple[str, Any]]:
    """(qualified name, object) of every public module, function, class, method and property."""
    out: list[tuple[str, Any]] = []
    modules: list[tuple[str, types.ModuleType]] = []
    for name in ad.__all__:
        obj = getattr(ad, name)
        if isinstance(obj, types.ModuleType):
            modules.append((name, obj))
        else:
            out.append((name, obj))
    # the scenes package's modules
    for name, mod in list(modules):
        for sub_name, sub in vars(mod).items():
            if isinstance(sub, types.ModuleType) and sub.__name__.startswith(mod.__name__ + "."):
                modules.append((f"{name}.{sub_name}", sub))
    # the papers' scenes (armdyn.papers: not imported by armdyn itself)
    for sub in ("five_dof", "geared_arm"):
        modules.append((f"papers.{sub}", importlib.import_module(f"armdyn.papers.{sub}")))
    for name, mod in modules:
        out.append((name, mod))
        for n in _module_names(mod):
            obj = getattr(mod, n)
            if (inspect.isclass(obj) or callable(obj)) and _defined_in(obj, mod):
                out.append((f"{name}.{n}", obj))
    classes = [(q, o) for q, o in out if inspect.isclass(o)]
    for qual, cls in classes:
        out.extend(_members(qual, cls))
    return out


def pybind11_lines(name: str, doc: str) -> list[str]:
    """pybind11's generated signature lines of `name` in a docstring."""
    pat = re.compile(r"^\s*(\d+\. )?" + re.escape(name) + r"\(.*\)( -> .*)?$")
    return [line for line in doc.splitlines() if pat.match(line)]


def prose(name: str, doc: str | None) -> str:
    """A docstring without pybind11's generated signature lines."""
    if not doc:
        return ""
    sig = set(pybind11_lines(name, doc))
    lines = [
        ln for ln in doc.splitlines() if ln not in sig and ln.strip() != "Overloaded function."
    ]
    return "\n".join(lines).strip()


def is_compiled(obj: Any) -> bool:
    """A pybind11 function (or a pybind11 method reached through its class)."""
    return isinstance(obj, types.BuiltinFunctionType) or type(obj).__name__ == "instancemethod"
