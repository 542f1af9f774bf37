"""The C++ folders are the layers (docs/development.md, "Layers"): every ``#include "armdyn/..."``
in ``cpp/`` and ``tests/cpp`` names a file of its own layer or of one below it, so includes run
one way and no two folders include each other; and no installed header is private to one
source file (those sit next to their ``.cpp`` under ``cpp/src/``). Read from the sources."""

from __future__ import annotations

import re
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
INCLUDE = ROOT / "cpp" / "include" / "armdyn"

#: the layers, lowest first; each may include only its own layer and those before it. A
#: folder of armdyn/ is named by its name, a file at the top of armdyn/ by its file name.
LAYERS = [
    ("errors.hpp", "poll.hpp"),  # exceptions and message formatting; interruption checks
    ("math",),  # types, quaternions, angles, small dense factorizations
    ("integrate",),  # ODE interface and integrators: know nothing of models
    ("model",),  # Model (the description), profiles, the derived-value store
    ("kernels",),  # data-free building blocks: jets, constraint rows, KKT factor, sweeps
    ("data.hpp",),  # Data(model): every per-evaluation buffer
    ("algorithm",),  # one stage per file over (const Model&, Data&)
    ("builder",),  # ModelBuilder, finalize, the welded form
    ("simulate",),  # whole runs: the ODE systems, joint stops, the recorder
    ("validate",),  # Lagrange and geometric validators
    ("io",),  # URDF, serialization
    ("armdyn.hpp",),  # the umbrella header
    ("bindings",),  # the Python module (cpp/bindings)
    ("tests",),  # the C++ tests (tests/cpp)
]
RANK = {name: i for i, names in enumerate(LAYERS) for name in names}
INCLUDE_RE = re.compile(r'^\s*#\s*include\s+"armdyn/([^"]+)"', re.M)


def _unit(rel_to_armdyn: str) -> str:
    """The layer unit of a path relative to armdyn/ (include/armdyn or src)."""
    head, _, rest = rel_to_armdyn.partition("/")
    return head if rest else head.replace(".cpp", ".hpp")


def _files() -> dict[Path, str]:
    """Every C++ file of the project -> its layer unit."""
    out = {}
    for p in (ROOT / "cpp").rglob("*.[ch]pp"):
        rel = p.relative_to(ROOT / "cpp")
        if rel.parts[0] == "include":
            out[p] = _unit(rel.relative_to("include/armdyn").as_posix())
        elif rel.parts[0] == "src":
            out[p] = _unit(rel.relative_to("src").as_posix())
        else:
            out[p] = rel.parts[0]
    for p in (ROOT / "tests" / "cpp").rglob("*.[ch]pp"):
        out[p] = "tests"
    return out


def _includes(path: Path) -> list[str]:
    return INCLUDE_RE.findall(path.read_text(encoding="utf-8"))


def test_every_folder_has_a_layer():
    units = set(_files().values())
    assert units <= set(RANK), f"folders without a layer (add them to LAYERS): {units - set(RANK)}"
    # the list names no folder that is gone
    assert set(RANK) - {"bindings", "tests"} <= units, set(RANK) - units


def test_includes_run_down_the_layers():
    upward = []
    for path, unit in _files().items():
        for inc in _includes(path):
            target = _unit(inc)
            if target not in RANK:
                upward.append(f"{path.relative_to(ROOT)} includes armdyn/{inc}: no such layer")
            elif RANK[target] > RANK[unit]:
                upward.append(f"{path.relative_to(ROOT)} ({unit}) includes armdyn/{inc} ({target})")
    assert not upward, "includes up the layers:\n" + "\n".join(sorted(upward))


def test_no_cycle_between_folders():
    edges = defaultdict(set)
    for path, unit in _files().items():
        for inc in _includes(path):
            if _unit(inc) != unit:
                edges[unit].add(_unit(inc))
    both = sorted({tuple(sorted((a, b))) for a in edges for b in edges[a] if a in edges.get(b, ())})
    assert not both, f"folders that include each other: {both}"


def test_every_included_file_exists():
    missing = [
        f"{path.relative_to(ROOT)}: armdyn/{inc}"
        for path in _files()
        for inc in _includes(path)
        if not (INCLUDE / inc).is_file()
    ]
    assert not missing, missing


def test_private_includes_stay_in_their_folder():
    """A header included by a path not under armdyn/ is a private header next to its user."""
    wrong = []
    for path in (ROOT / "cpp").rglob("*.[ch]pp"):
        text = path.read_text(encoding="utf-8")
        for inc in re.findall(r'^\s*#\s*include\s+"([^"]+)"', text, re.M):
            if not inc.startswith("armdyn/") and not (path.parent / inc).is_file():
                wrong.append(f"{path.relative_to(ROOT)}: {inc}")
            elif not inc.startswith("armdyn/") and "/" in inc:
                wrong.append(f"{path.relative_to(ROOT)}: {inc} (another folder's private header)")
    assert not wrong, wrong


def test_no_installed_header_is_private_to_one_source():
    """An installed header is needed by another installed header (to compile it), named by
    the umbrella header or the bindings, or used by at least two sources other than its own
    .cpp; one that only a single source uses belongs next to it under cpp/src/ (the C++ tests
    include such headers by their path there)."""
    users = defaultdict(set)
    for path in _files():
        for inc in _includes(path):
            users[inc].add(path)
    private = []
    for header in INCLUDE.rglob("*.hpp"):
        rel = header.relative_to(INCLUDE).as_posix()
        own = ROOT / "cpp" / "src" / rel.replace(".hpp", ".cpp")
        others = {p for p in users[rel] if p != own and p.relative_to(ROOT).parts[0] != "tests"}
        needed = any(INCLUDE in p.parents or "bindings" in p.parts for p in others)
        if rel != "armdyn.hpp" and not needed and len(others) < 2:
            names = sorted(str(p.relative_to(ROOT)) for p in others)
            private.append(f"armdyn/{rel} (used by {names})")
    assert not private, "installed headers private to one source:\n" + "\n".join(sorted(private))
