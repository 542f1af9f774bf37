"""docs/api.md matches the code: every name it documents exists (package functions, builder
methods, model properties, validation helpers), and every python block runs, in order, in one
namespace."""

import re
from pathlib import Path

import armdyn as ad
import pytest
from armdyn import validation

API = (Path(__file__).resolve().parents[2] / "docs" / "api.md").read_text("utf-8")


def test_documented_package_names_exist():
    names = set(re.findall(r"\bad\.(\w+)", API))
    assert {"forward_dynamics", "inverse_dynamics", "mass_matrix", "Data"} <= names
    missing = sorted(n for n in names if not hasattr(ad, n))
    assert not missing, missing


def test_documented_builder_methods_exist():
    names = set(re.findall(r"^(?:model = )?b\.(\w+)\b", API, re.M))
    assert len(names) >= 20
    missing = sorted(n for n in names if not hasattr(ad.ModelBuilder, n))
    assert not missing, missing
    # and every public builder method is documented
    undocumented = sorted(
        n for n in dir(ad.ModelBuilder) if not n.startswith("_") and n not in names
    )
    assert not undocumented, undocumented


def test_documented_model_properties_exist():
    section = API.split("## Model (immutable)", 1)[1].split("##", 1)[0]
    names = {n.strip().removesuffix("()") for n in section.split("`")[1].split(",")}
    public = {n for n in dir(ad.Model) if not n.startswith("_")}
    assert public <= names, sorted(public - names)
    assert names <= public, sorted(names - public)


def test_documented_validation_helpers_exist():
    names = set(re.findall(r"\bvalidation\.(\w+)\(", API))
    assert names
    missing = sorted(n for n in names if not hasattr(validation, n))
    assert not missing, missing


def test_python_blocks_run():
    blocks = re.findall(r"```python\n(.*?)```", API, re.S)
    assert len(blocks) >= 5
    ns: dict = {}
    for i, code in enumerate(blocks):
        exec(compile(code, f"docs/api.md python block {i + 1}", "exec"), ns)
    # the blocks' own results, against each other: inverse dynamics undoes forward dynamics,
    # the Cartesian path equals the joint path, and the batch equals the single call
    import numpy as np

    np.testing.assert_allclose(ns["tau"], 0.0, atol=1e-10)
    np.testing.assert_allclose(ns["same"], ns["qdd"], rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(ns["rows"][2], ns["qdd"])
    assert ns["M"].shape == (2, 2) and ns["vdot"].shape == (12,)
    assert np.abs(ns["res"].q - ns["joint"].q).max() <= 1e-6
    # the work-precision block: DOPRI5's error follows its tolerance; RK4's coarse step fails
    # on the motor's damping and is a row, not an exception
    tab = ns["wp"].table
    assert tab["status"].tolist() == ["ok", "ok", "failed", "ok"]
    assert tab["error"].iloc[1] < 1e-8 < tab["error"].iloc[0] < 1e-5
    # the sizing block: a rotor of 0.2 kg m² driven by q = sin(π t) needs 0.2 π² N m at
    # t = 0.5 and 1.5 s (output samples), above its 1 N m effort limit; its peak speed π rad/s
    # is within 4 rad/s
    sizing = ns["sizing"].loc["spin"]
    assert sizing["peak_torque"] == pytest.approx(0.2 * np.pi**2, rel=1e-12)
    assert sizing["torque_margin"] == pytest.approx(1.0 / (0.2 * np.pi**2), rel=1e-12)
    assert not sizing["ok"]
    spans = ns["spans"]
    assert spans["kind"].tolist() == ["effort", "effort"]
    np.testing.assert_allclose(spans["worst"], 0.2 * np.pi**2 * np.array([-1.0, 1.0]), rtol=1e-12)
