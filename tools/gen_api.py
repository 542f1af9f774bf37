"""Write docs/reference.md, the API reference, from the installed (or PYTHONPATH) armdyn's
docstrings and signatures.

    python tools/gen_api.py            # rewrite docs/reference.md
    python tools/gen_api.py --check    # exit 1 with a diff when docs/reference.md is stale

What it walks: every name of ``armdyn.__all__`` (functions, classes, the ``profiles`` module),
then every public submodule (``armdyn.simulation``, ``armdyn.sizing``, ``armdyn.papers.five_dof``,
...: module names without a leading underscore, ``__main__`` excepted) for the public functions,
classes and numeric constants it defines that were not already listed. A class lists its
constructor and the public methods and properties it defines itself.

Signatures come from ``inspect.signature``; a compiled (pybind11) function without one falls
back to the signature line(s) pybind11 writes at the head of its docstring (each overload of an
overloaded function), ``self`` dropped. Object addresses (``at 0x...``) are removed so the output
does not depend on the process. tests/docs/test_reference.py regenerates the file and fails
when the committed one differs.
"""

from __future__ import annotations

import argparse
import difflib
import importlib
import inspect
import pkgutil
import re
import sys
import types
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "reference.md"
COMMAND = "python tools/gen_api.py"

HEADER = f"""# armdyn API reference

Generated from the docstrings and signatures by `{COMMAND}`; do not edit by hand
(`tests/docs/test_reference.py` fails when this file is out of step with the code). The guide,
with worked examples, is [api.md](api.md).
"""

_ADDRESS = re.compile(r" at 0x[0-9a-fA-F]+")
_SELF = re.compile(r"\(self(?:: [\w.]+)?(?:, )?")


class _Text:
    """An annotation or default shown as its text (no quotes around string annotations)."""

    def __init__(self, text: str) -> None:
        self.text = text

    def __repr__(self) -> str:
        return self.text


def _clean(text: str) -> str:
    return _ADDRESS.sub("", text)


def _is_compiled(obj) -> bool:
    return isinstance(obj, types.BuiltinFunctionType) or type(obj).__name__ in (
        "instancemethod",
        "builtin_function_or_method",
    )


def _pybind_signatures(name: str, doc: str | None) -> tuple[list[str], str]:
    """(signature lines, remaining docstring) of a pybind11 docstring: its first line is
    ``name(args) -> ret``; an overloaded function lists ``1. name(args) -> ret`` lines, each
    followed by that overload's own text."""
    doc = doc or ""
    lines = doc.strip("\n").splitlines()
    if not lines or not lines[0].startswith(name + "("):
        return [], doc
    if len(lines) > 1 and lines[1].strip() == "Overloaded function.":
        sigs, rest = [], []
        for line in lines[2:]:
            m = re.match(r"^\d+\. (" + re.escape(name) + r"\(.*)$", line)
            if m:
                sigs.append(m.group(1))
            elif line.strip() or rest:
                rest.append(line)
        return sigs, "\n".join(rest)
    return [lines[0]], "\n".join(lines[1:])


def _drop_self(sig: str) -> str:
    return _SELF.sub("(", sig, count=1)


def _format_signature(sig: inspect.Signature) -> str:
    params = []
    for p in sig.parameters.values():
        kw = {}
        if p.annotation is not inspect.Parameter.empty:
            ann = p.annotation
            kw["annotation"] = _Text(ann if isinstance(ann, str) else inspect.formatannotation(ann))
        if p.default is not inspect.Parameter.empty:
            kw["default"] = _Text(repr(p.default))
        params.append(p.replace(**kw))
    ret = sig.return_annotation
    if ret is not inspect.Signature.empty:
        ret = _Text(ret if isinstance(ret, str) else inspect.formatannotation(ret))
    return str(sig.replace(parameters=params, return_annotation=ret))


def signatures(name: str, obj) -> tuple[list[str], str]:
    """(signature lines shown as ``name(...)``, docstring without pybind11's signature lines)."""
    doc = inspect.getdoc(obj) or ""
    target = obj
    if inspect.isclass(obj):
        try:
            sig = inspect.signature(obj)
            return [name + _format_signature(sig)], doc
        except (TypeError, ValueError):
            target = obj.__init__
            sigs, _ = _pybind_signatures("__init__", target.__doc__)
            return [name + _drop_self(s)[len("__init__") :] for s in sigs], doc
    try:
        sig = inspect.signature(target)
    except (TypeError, ValueError):
        short = getattr(target, "__name__", name.rsplit(".", 1)[-1])
        sigs, rest = _pybind_signatures(short, doc)
        prefix = name[: -len(short)] if name.endswith(short) else ""
        return [prefix + _drop_self(s) for s in sigs], rest.strip("\n")
    if _is_compiled(target):  # a text signature: drop pybind11's signature line all the same
        _, doc = _pybind_signatures(getattr(target, "__name__", ""), doc)
    params = list(sig.parameters.values())
    if params and params[0].name == "self":
        sig = sig.replace(parameters=params[1:])
    return [name + _format_signature(sig)], doc.strip("\n")


def _property_line(name: str, prop) -> tuple[list[str], str]:
    """A property: ``Class.name -> type`` (from its getter's annotation or pybind11 line)."""
    fget = getattr(prop, "fget", None)
    doc = inspect.getdoc(prop) or ""
    ret = ""
    if fget is not None:
        try:
            ann = inspect.signature(fget).return_annotation
            if ann is not inspect.Signature.empty:
                ret = ann if isinstance(ann, str) else inspect.formatannotation(ann)
        except (TypeError, ValueError):
            sigs, _ = _pybind_signatures(getattr(fget, "__name__", ""), fget.__doc__)
            if sigs and " -> " in sigs[0]:
                ret = sigs[0].rsplit(" -> ", 1)[1]
        if not doc:
            _, doc = _pybind_signatures(getattr(fget, "__name__", ""), inspect.getdoc(fget))
    if doc:  # pybind11 puts the getter's signature line first in the property's docstring too
        first = doc.splitlines()[0]
        if re.match(r"^\w*\(self", first):
            doc = "\n".join(doc.splitlines()[1:])
    if prop.__class__ is property and getattr(prop, "fset", None) is None:
        kind = "property, read-only"
    else:
        kind = "property"
    return [f"{name}{' -> ' + ret if ret else ''}  ({kind})"], doc.strip("\n")


def _entry(level: int, name: str, sigs: list[str], doc: str) -> str:
    body = "\n".join(_clean(s) for s in sigs)
    text = _clean(doc).strip("\n") or "(no docstring)"
    fence = "````" if "```" in text else "```"
    head = body + "\n\n" if body else ""
    return f"{'#' * level} `{name}`\n\n{fence}text\n{head}{text}\n{fence}\n"


def _class_members(cls) -> list[tuple[str, object]]:
    out = []
    for member, value in cls.__dict__.items():
        if member.startswith("_"):
            continue
        if isinstance(value, (staticmethod, classmethod)):
            value = value.__func__
        out.append((member, value))
    return sorted(out)


def document_class(qualname: str, cls) -> str:
    sigs, doc = signatures(qualname, cls)
    parts = [_entry(3, qualname, sigs, doc)]
    for member, value in _class_members(cls):
        full = f"{qualname}.{member}"
        if isinstance(value, property) or type(value).__name__ in (
            "property",
            "pybind11_static_property",
        ):
            parts.append(_entry(4, full, *_property_line(full, value)))
        elif callable(value):
            parts.append(_entry(4, full, *signatures(full, value)))
    return "\n".join(parts)


def document_object(qualname: str, obj) -> str | None:
    if inspect.isclass(obj):
        return document_class(qualname, obj)
    if callable(obj):
        return _entry(3, qualname, *signatures(qualname, obj))
    if isinstance(obj, (int, float)) and not isinstance(obj, bool):
        return f"### `{qualname}`\n\n```text\n{qualname} = {obj!r}\n```\n"
    return None


def _module_doc(mod) -> str:
    doc = inspect.getdoc(mod) or ""
    return _clean(doc).strip()


def public_submodules(package) -> list[str]:
    names = []
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        parts = info.name.split(".")
        if any(p.startswith("_") for p in parts[1:]):
            continue
        names.append(info.name)
    return sorted(names)


def generate() -> str:
    import armdyn

    seen: set[int] = set()
    out = [HEADER]
    out.append("## `armdyn`\n")
    out.append(f"```text\n{_module_doc(armdyn)}\n```\n")
    modules_in_all = []
    for name in sorted(armdyn.__all__, key=lambda n: (n[0].islower(), n.lower())):
        obj = getattr(armdyn, name)
        if inspect.ismodule(obj):
            modules_in_all.append((name, obj))
            continue
        text = document_object(f"armdyn.{name}", obj)
        if text is not None:
            seen.add(id(obj))
            out.append(text)
    # compiled submodules named in __all__ (armdyn.profiles) have no file to walk
    for name, mod in modules_in_all:
        if getattr(mod, "__file__", None) is None or mod.__name__ == "armdyn._core.profiles":
            out.append(_module_section(f"armdyn.{name}", mod, seen, compiled=True))
    for modname in public_submodules(armdyn):
        mod = importlib.import_module(modname)
        section = _module_section(modname, mod, seen)
        if section:
            out.append(section)
    modules = [re.match(r"## `([\w.]+)`", part).group(1) for part in out if part.startswith("## ")]
    contents = ", ".join(f"[`{m}`](#{m.replace('.', '')})" for m in modules)
    out.insert(1, f"Modules: {contents}.\n")
    return "\n".join(out).rstrip("\n") + "\n"


def _module_section(modname: str, mod, seen: set[int], compiled: bool = False) -> str:
    names = getattr(mod, "__all__", None)
    if names is None:
        names = sorted(n for n in vars(mod) if not n.startswith("_"))
    entries = []
    for name in names:
        obj = getattr(mod, name)
        if id(obj) in seen or inspect.ismodule(obj):
            continue
        defined_here = compiled or getattr(obj, "__module__", None) == mod.__name__
        if inspect.isclass(obj) or callable(obj):
            if not defined_here:
                continue
        elif not (name.isupper() and isinstance(obj, (int, float))):
            continue
        text = document_object(f"{modname}.{name}", obj)
        if text is not None:
            if inspect.isclass(obj) or callable(obj):
                seen.add(id(obj))
            entries.append(text)
    doc = _module_doc(mod)
    if not entries and not doc:
        return ""
    head = f"## `{modname}`\n"
    if doc:
        head += f"\n```text\n{doc}\n```\n"
    return "\n".join([head, *entries])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare, do not write")
    args = parser.parse_args(argv)
    text = generate()
    if args.check:
        old = OUT.read_text("utf-8") if OUT.exists() else ""
        if old != text:
            sys.stdout.writelines(
                difflib.unified_diff(
                    old.splitlines(True), text.splitlines(True), "docs/reference.md", "generated"
                )
            )
            print(f"docs/reference.md is stale: run `{COMMAND}`")
            return 1
        return 0
    OUT.write_text(text, "utf-8")
    print(f"wrote {OUT.relative_to(ROOT)} ({len(text)} characters)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
