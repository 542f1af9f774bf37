"""What a plain ``pip install .`` gives: every CLI runs on the ordinary dependencies alone.

* Every third-party module imported anywhere in the package (module level or inside a function)
  is an ordinary dependency in pyproject.toml, except the ones of the optional features listed
  in OPTIONAL, which are in the named extra and imported only by the named modules.
* A missing dependency gives a one-line message naming it and exit code 2, no traceback.
"""

from __future__ import annotations

import ast
import math
import re
import subprocess
import sys
from importlib.metadata import packages_distributions
from pathlib import Path

import numpy as np
import pytest

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "python" / "armdyn"
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
URDF = ROOT / "tests" / "data" / "urdf" / "sizing_pendulum.urdf"

# third-party module -> (extra that provides it, the only package modules allowed to import it)
OPTIONAL = {
    "distributed": ("distributed", {"sweeps.py"}),
    "xarray": ("distributed", {"sweeps.py"}),
    # armdyn.animate: K3D's viewer, the URDF meshes (pycollada's module is ``collada``)
    "k3d": ("viz", {"animation.py"}),
    "trimesh": ("viz", {"animation.py"}),
    "collada": ("viz", {"animation.py"}),
    # armdyn.load_mjcf: MuJoCo's own MJCF parser and compiler
    "mujoco": ("mjcf", {"mjcf.py"}),
}


def _requirement_names(req: str) -> set[str]:
    """The distribution a requirement names, and the ones its extras stand for
    (``dask[distributed]`` installs ``distributed``)."""
    m = re.match(r"\s*([A-Za-z0-9_.\-]+)\s*(?:\[([^\]]*)\])?", req)
    names = {m.group(1), *(m.group(2) or "").split(",")} - {""}
    return {n.strip().lower().replace("_", "-") for n in names}


def _names(reqs: list[str]) -> set[str]:
    return set().union(*map(_requirement_names, reqs))


def third_party_imports() -> dict[str, set[str]]:
    """{top-level module: {package files importing it}} over every import statement."""
    out: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                if top != "armdyn" and top not in sys.stdlib_module_names:
                    out.setdefault(top, set()).add(path.name)
    return out


def test_every_import_is_a_dependency_or_a_named_optional_feature():
    deps = _names(PYPROJECT["project"]["dependencies"])
    extras = {k: _names(v) for k, v in PYPROJECT["project"]["optional-dependencies"].items()}
    dist_of = packages_distributions()
    imports = third_party_imports()
    # the walk sees what it must: the lazily imported ones included
    assert {"numpy", "pandas", "matplotlib", "scipy", "tqdm", "tomli"} <= imports.keys()
    for module, files in sorted(imports.items()):
        dists = {d.lower().replace("_", "-") for d in dist_of.get(module, [module])}
        if module in OPTIONAL:
            extra, allowed = OPTIONAL[module]
            assert files <= allowed, f"{module} (extra {extra!r}) imported by {files - allowed}"
            assert dists & extras[extra], f"{module}: not in the {extra!r} extra"
        else:
            assert dists & deps, f"{module} (imported by {sorted(files)}) is not a dependency"


def test_tomli_only_where_tomllib_is_missing():
    (req,) = [r for r in PYPROJECT["project"]["dependencies"] if r.startswith("tomli")]
    assert req.replace(" ", "").endswith(";python_version<'3.11'")


def run_blocked(blocked: list[str], code: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter where the modules ``blocked`` cannot be imported."""
    prelude = f"import sys\nfor _m in {blocked!r}: sys.modules[_m] = None\n"
    return subprocess.run(
        [sys.executable, "-c", prelude + code], capture_output=True, text=True, timeout=120
    )


def test_verify_pendulum_period_against_the_closed_form():
    from armdyn.verify import pendulum_period

    sim, exact = pendulum_period(np.radians(90.0))
    # T = 4 / ω₀ K(sin²45°), ω₀ = √(m g L / I_pivot), I_pivot = 0.4 m r² + m L² (r = 1e-3)
    omega0 = math.sqrt(9.81 / (0.4e-6 + 1.0))
    k_half = math.gamma(0.25) ** 2 / (4 * math.sqrt(math.pi))
    assert exact == pytest.approx(4 / omega0 * k_half, rel=1e-15)
    assert sim == pytest.approx(exact, rel=1e-8)


def test_missing_dependency_is_named_without_traceback(tmp_path):
    proc = run_blocked(
        ["pandas"],
        "from armdyn.__main__ import main\n"
        f"sys.exit(main(['size', {str(URDF)!r}, '--trajectory', {str(tmp_path / 'x.csv')!r}]))",
    )
    assert proc.returncode == 2
    expected = "armdyn size: needs the Python module 'pandas': pip install pandas"
    assert proc.stderr.strip() == expected


def test_help_lists_the_commands():
    proc = subprocess.run(
        [sys.executable, "-m", "armdyn", "--help"], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0, proc.stderr
    for command in ("verify", "reproduce", "size"):
        assert command in proc.stdout
