"""What a plain ``pip install .`` gives: every CLI runs on the ordinary dependencies alone.

* Every third-party module imported anywhere in the package (module level or inside a function)
  is an ordinary dependency in pyproject.toml, except the ones of the optional features listed
  in OPTIONAL, which are in the named extra and imported only by the named modules.
* ``armdyn verify`` and ``armdyn size`` need no scipy: K(m) by the AGM (against closed forms and
  scipy.special.ellipk) and the not-a-knot spline (against scipy.interpolate.CubicSpline), and
  both commands run with scipy made unimportable.
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
import pandas as pd
import pytest
from armdyn.size import not_a_knot_spline_derivative
from armdyn.verify import ellipk

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
    assert {"numpy", "pandas", "matplotlib", "tqdm", "tomli"} <= imports.keys()
    for module, files in sorted(imports.items()):
        dists = {d.lower().replace("_", "-") for d in dist_of.get(module, [module])}
        if module in OPTIONAL:
            extra, allowed = OPTIONAL[module]
            assert files <= allowed, f"{module} (extra {extra!r}) imported by {files - allowed}"
            assert dists & extras[extra], f"{module}: not in the {extra!r} extra"
        else:
            assert dists & deps, f"{module} (imported by {sorted(files)}) is not a dependency"
    # scipy is gone from the CLI: no module of the package imports it
    assert "scipy" not in imports


def test_tomli_only_where_tomllib_is_missing():
    (req,) = [r for r in PYPROJECT["project"]["dependencies"] if r.startswith("tomli")]
    assert req.replace(" ", "").endswith(";python_version<'3.11'")


def test_ellipk_against_closed_forms_and_scipy():
    assert ellipk(0.0) == math.pi / 2
    # K(1/2) = Γ(1/4)² / (4 √π)
    assert ellipk(0.5) == pytest.approx(math.gamma(0.25) ** 2 / (4 * math.sqrt(math.pi)), 4e-16)
    # K(m) ~ ln(4 / √(1 - m)) as m -> 1, error O((1 - m) ln(1 - m))
    m = 1 - 1e-14
    assert ellipk(m) == pytest.approx(math.log(4 / math.sqrt(1 - m)), abs=1e-12)
    special = pytest.importorskip("scipy.special")
    for m in np.concatenate([np.linspace(0, 0.999, 37), 1 - np.logspace(-3, -15, 13)]):
        assert ellipk(m) == pytest.approx(special.ellipk(m), rel=1e-15, abs=0)
    for bad in (-0.1, 1.0, float("nan")):
        with pytest.raises(ValueError, match="outside"):
            ellipk(bad)


@pytest.mark.parametrize("n", [4, 5, 6, 9, 200])
def test_spline_derivatives_match_scipy_cubic_spline(n):
    interpolate = pytest.importorskip("scipy.interpolate")
    rng = np.random.default_rng(n)
    t = np.cumsum(rng.uniform(0.01, 1.0, n))  # uneven steps, ratios up to 100
    y = np.sin(3 * t) + rng.normal(size=n)
    spline = interpolate.CubicSpline(t, y)
    for order in (1, 2):
        ref = spline(t, order)
        got = not_a_knot_spline_derivative(t, y, order)
        assert np.abs(got - ref).max() <= 1e-13 * np.abs(ref).max()


def test_spline_is_exact_on_a_cubic():
    t = np.cumsum(np.random.default_rng(3).uniform(0.05, 0.5, 12))
    y = 1 + 2 * t - 3 * t**2 + 0.5 * t**3
    np.testing.assert_allclose(
        not_a_knot_spline_derivative(t, y, 1), 2 - 6 * t + 1.5 * t**2, rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(
        not_a_knot_spline_derivative(t, y, 2), -6 + 3 * t, rtol=0, atol=1e-11
    )


def run_blocked(blocked: list[str], code: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter where the modules ``blocked`` cannot be imported."""
    prelude = f"import sys\nfor _m in {blocked!r}: sys.modules[_m] = None\n"
    return subprocess.run(
        [sys.executable, "-c", prelude + code], capture_output=True, text=True, timeout=120
    )


def test_size_differentiates_positions_without_scipy(tmp_path):
    """armdyn size on a positions-only CSV, scipy unimportable: the pendulum's torque
    τ = I_p q̈ + m g l sin q (tests/validate/test_size_cli.py) to the spline's accuracy."""
    i_p, mgl = 0.01 + 2.0 * 0.5**2, 2.0 * 9.81 * 0.5
    t = np.linspace(0.0, 2.0, 801)
    w = np.pi
    q, qdd = 0.5 * np.sin(w * t), -0.5 * w * w * np.sin(w * t)
    pd.DataFrame({"t": t, "pivot": q}).to_csv(
        tmp_path / "pos.csv", index=False, float_format="%.17g"
    )
    proc = run_blocked(
        ["scipy"],
        "from armdyn.__main__ import main\n"
        f"sys.exit(main(['size', {str(URDF)!r}, '--trajectory', {str(tmp_path / 'pos.csv')!r},"
        f" '--out', {str(tmp_path / 'rep')!r}]))",
    )
    assert proc.returncode == 0, proc.stderr
    tab = pd.read_csv(tmp_path / "rep" / "table.csv", index_col="joint")
    tau = i_p * qdd + mgl * np.sin(q)
    assert tab.loc["pivot", "peak_torque"] == pytest.approx(np.max(np.abs(tau)), rel=1e-5)


def test_verify_pendulum_without_scipy():
    proc = run_blocked(
        ["scipy"],
        "import numpy as np\nfrom armdyn.verify import pendulum_period\n"
        "sim, exact = pendulum_period(np.radians(90.0))\n"
        "print(repr(float(sim)), repr(float(exact)))",
    )
    assert proc.returncode == 0, proc.stderr
    sim, exact = map(float, proc.stdout.split())
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
