"""Regenerate the type stubs of the compiled module, python/armdyn/_core/*.pyi.

    python tools/gen_stubs.py            # rewrite the committed stubs
    python tools/gen_stubs.py --check    # exit 1 with a diff when they are out of date
    python tools/gen_stubs.py --out DIR  # write them under DIR/armdyn/_core/ instead

Run it with the freshly built ``armdyn._core`` importable (PYTHONPATH=python, the .so copied
next to the package). pybind11-stubgen (pinned in the ``[test]`` extra: the output must not
change with its version) reads pybind11's annotated signature lines from the docstrings. The
module also gives each function a plain ``__text_signature__`` (for inspect.signature), which
pybind11-stubgen would otherwise prefer: here the docstring line wins, so the stubs keep their
types (numpy.typing.ArrayLike in, numpy.typing.NDArray[numpy.float64] out).
"""

from __future__ import annotations

import argparse
import difflib
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STUBS = ROOT / "python" / "armdyn" / "_core"
COMMAND = "python tools/gen_stubs.py"


def _prefer_docstring_signatures() -> None:
    from pybind11_stubgen.parser.mixins.parse import ExtractSignaturesFromPybind11Docstrings
    from pybind11_stubgen.structs import Identifier

    original = ExtractSignaturesFromPybind11Docstrings.handle_function
    if getattr(original, "_armdyn", False):
        return

    def handle_function(self, path, func):
        doc = getattr(func, "__doc__", None)
        if doc and getattr(func, "__text_signature__", None):
            parsed = self.parse_function_docstring(Identifier(path[-1]), doc.splitlines())
            if parsed:
                return parsed
        return original(self, path, func)

    handle_function._armdyn = True
    ExtractSignaturesFromPybind11Docstrings.handle_function = handle_function


def generate(out: Path) -> dict[str, str]:
    """Write the stubs under out/armdyn/_core/; {file name: text}."""
    import pybind11_stubgen

    _prefer_docstring_signatures()
    pybind11_stubgen.main(["armdyn._core", "-o", str(out), "--exit-code"])
    files = sorted((out / "armdyn" / "_core").glob("*.pyi"))
    # stubgen's layout as it is (ruff leaves the generated files alone: pyproject's
    # extend-exclude), so the output depends on the pinned pybind11-stubgen only
    return {f.name: f.read_text() for f in files}


def diff(new: dict[str, str], old_dir: Path = STUBS) -> str:
    """A unified diff from the stubs in old_dir to `new`; '' when identical."""
    old = {f.name: f.read_text() for f in sorted(old_dir.glob("*.pyi"))}
    out = []
    for name in sorted(set(old) | set(new)):
        out += difflib.unified_diff(
            old.get(name, "").splitlines(keepends=True),
            new.get(name, "").splitlines(keepends=True),
            f"committed/{name}",
            f"generated/{name}",
        )
    return "".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with the committed stubs")
    ap.add_argument("--out", type=Path, help="write under OUT/armdyn/_core/")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        new = generate(Path(tmp) if args.check or args.out is None else args.out)
    if args.check:
        d = diff(new)
        if d:
            sys.stdout.write(d)
            print(f"\nthe committed stubs are out of date: run `{COMMAND}`", file=sys.stderr)
            return 1
        return 0
    if args.out is None:
        STUBS.mkdir(exist_ok=True)
        for f in STUBS.glob("*.pyi"):
            if f.name not in new:
                f.unlink()
        for name, text in new.items():
            (STUBS / name).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
