"""docs/api.md, the guide, matches the code: every name it documents exists (package functions,
builder methods, model properties, validation helpers), and its python blocks' results hold
against each other and against closed forms (the blocks are run once, each as pasted, by the
session fixture ``doc_file_blocks`` of tests/conftest.py; tests/docs/test_runnable_blocks.py
checks that all of them run)."""

import re
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest
from armdyn import validation
from doc_blocks import namespace_with

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


GUIDE = "docs/api.md"


@pytest.fixture(scope="module")
def doc_blocks(doc_file_blocks):
    """The guide's blocks (the other files' are not needed here)."""
    return doc_file_blocks(GUIDE)


def test_two_link_blocks(doc_blocks):
    """The blocks on the two-link arm of "Building", against each other: inverse dynamics undoes
    forward dynamics, the Cartesian path equals the joint path, and the batch equals the single
    call."""
    ns = namespace_with(doc_blocks, GUIDE, "tau", "same", "rows", "vdot", "res", "joint")
    np.testing.assert_allclose(ns["tau"], 0.0, atol=1e-10)
    np.testing.assert_allclose(ns["same"], ns["qdd"], rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(ns["rows"][2], ns["qdd"])
    assert ns["M"].shape == (2, 2) and ns["vdot"].shape == (12,)
    assert np.abs(ns["res"].q - ns["joint"].q).max() <= 1e-6


def test_work_precision_block(doc_blocks):
    """DOPRI5's error follows its tolerance; RK4's coarse step fails on the motor's damping and
    is a row, not an exception."""
    tab = namespace_with(doc_blocks, GUIDE, "wp")["wp"].table
    assert tab["status"].tolist() == ["ok", "ok", "failed", "ok"]
    assert tab["error"].iloc[1] < 1e-8 < tab["error"].iloc[0] < 1e-5


def test_sizing_blocks(doc_blocks):
    """A rotor of 0.2 kg m² driven by q = sin(π t) needs 0.2 π² N m at t = 0.5 and 1.5 s (output
    samples), above its 1 N m effort limit; its peak speed π rad/s is within 4 rad/s."""
    ns = namespace_with(doc_blocks, GUIDE, "sizing", "spans")
    sizing = ns["sizing"].loc["spin"]
    assert sizing["peak_torque"] == pytest.approx(0.2 * np.pi**2, rel=1e-12)
    assert sizing["torque_margin"] == pytest.approx(1.0 / (0.2 * np.pi**2), rel=1e-12)
    assert not sizing["ok"]
    spans = ns["spans"]
    assert spans["kind"].tolist() == ["effort", "effort"]
    np.testing.assert_allclose(spans["worst"], 0.2 * np.pi**2 * np.array([-1.0, 1.0]), rtol=1e-12)


def test_five_dof_dynamics_blocks(doc_blocks):
    """The five-DOF blocks (free arm, then driven arm; their own asserts hold): the mass matrix
    is the Lagrange validator's, and the batch equals row-by-row calls."""
    ns = namespace_with(doc_blocks, GUIDE, "QDD", "idr", "free")
    assert ns["QDD"].shape == (1000, 5)
    assert ns["idr"].drive_forces.shape == (3, 5)
    lag = ad.LagrangeValidator(ns["free"])
    np.testing.assert_allclose(ns["M"], lag.mass_matrix(ns["q"]), rtol=1e-12, atol=1e-14)
    Q = ns["Q"]
    rows = np.array([ad.forward_dynamics(ns["free"], Q[i], Q[i], Q[i]) for i in (0, 999)])
    np.testing.assert_array_equal(ns["QDD"][[0, 999]], rows)


def test_sweep_example(doc_blocks):
    """The pendulum sweep (client=None: its own LocalCluster) gives a Dataset over theta0 x length
    whose periods are the closed form 4/w0 K(sin^2(theta0/2)) of the physical pendulum,
    w0^2 = m g L / (2/5 m r^2 + m L^2), computed here with SciPy's ellipk."""
    pytest.importorskip("distributed")
    from scipy.special import ellipk

    block = next(b for b in doc_blocks if b.file == GUIDE and "ad.sweep(period" in b.code)
    assert not block.continues
    assert len([ln for ln in block.code.strip().splitlines() if ln.strip()]) <= 9
    ds = namespace_with(doc_blocks, GUIDE, "ds", "period")["ds"]
    assert ds["period"].dims == ("theta0", "length")
    assert (ds["status"].values == "ok").all()
    theta0 = ds["theta0"].values[:, None]
    length = ds["length"].values[None, :]
    r, g = 1e-3, 9.81
    exact = 4.0 / np.sqrt(g * length / (0.4 * r**2 + length**2)) * ellipk(np.sin(theta0 / 2) ** 2)
    np.testing.assert_allclose(ds["period"].values, exact, rtol=1e-8)
    # the seeded sweep on a client of one's own: its failing points are rows, not exceptions
    study = namespace_with(doc_blocks, GUIDE, "study")["study"]
    assert study.attrs["failed"] == 2 and study.attrs["seed"] == 7


SHAPE = re.compile(r"`ad\.(\w+)\(([^)]*)\) -> \S+ \(([\w, ]*)\)`")
ROWS_SHAPE = re.compile(r"\(rows:\s+`\(rows, ([^)]*)\)`\)")


def floating_arm():
    """A floating base (7 coordinates, 6 rates) with two revolute links: n_coords = n_dofs + 1
    and nq, nv differ from both, so every documented size is told apart."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("base", 3.0, [0.05, 0.06, 0.07], position=(0.0, 0.0, 0.5))
    b.add_body("upper", 1.0, [0.01, 0.01, 0.002], position=(0.2, 0.0, 0.5))
    b.add_body("lower", 0.5, [0.005, 0.005, 0.001], position=(0.6, 0.0, 0.5))
    b.add_free("float", "base")
    b.add_revolute("shoulder", "base", "upper", point=(0.0, 0.0, 0.5), axis=(0, 1, 0))
    b.add_revolute("elbow", "upper", "lower", point=(0.4, 0.0, 0.5), axis=(0, 0, 1))
    b.add_frame("tip", "lower", position=(0.8, 0.0, 0.5))
    return b.finalize()


def test_documented_shapes_are_the_returned_shapes():
    """Every ``ad.f(...) -> X (shape)`` of the guide (and its ``(rows: ...)`` batch form),
    evaluated on a model where n_coords, n_dofs, nq and nv all differ: the returned array has
    the documented shape (frame_jacobian was once documented as (6, n_coords))."""
    documented = {name: shape for name, _, shape in SHAPE.findall(API)}
    assert {"mass_matrix", "frame_pose", "frame_jacobian", "body_mass_matrix"} <= set(documented)
    model = floating_arm()
    sizes = {"n_coords": model.n_coords, "n_dofs": model.n_dofs, "nq": model.nq, "nv": model.nv}
    assert len(set(sizes.values())) == 4, sizes
    rng = np.random.default_rng(3)
    q = np.concatenate([[0.1, -0.2, 0.5, 1.0, 0.0, 0.0, 0.0], rng.uniform(-1, 1, 2)])
    qd = rng.uniform(-1, 1, model.n_dofs)
    u, v = ad.state_from_joints(model, q, qd)
    args = {"model": model, "q": q, "qd": qd, "u": u, "v": v, "frame": "tip"}

    def call(name, signature, q_rows=None):
        params = [p.strip() for p in signature.split(",") if "=" not in p]
        values = [args[p] for p in params]
        if q_rows is not None:
            values[params.index("q")] = q_rows
        return np.asarray(getattr(ad, name)(*values))

    def expected(shape, rows=None):
        dims = [d.strip() for d in shape.split(",") if d.strip()]
        out = tuple(sizes[d] if d in sizes else int(d) for d in dims)
        return out if rows is None else (rows, *out)

    for name, signature, shape in SHAPE.findall(API):
        assert call(name, signature).shape == expected(shape), (name, shape)
    # the batch form, stated in the same bullet as its function
    batched = []
    for item in re.split(r"\n- ", API):
        first, rows = SHAPE.search(item), ROWS_SHAPE.search(item)
        if first and rows:
            batched.append((first.group(1), first.group(2), rows.group(1)))
    assert {"mass_matrix", "frame_pose", "frame_jacobian"} <= {n for n, _, _ in batched}
    for name, signature, shape in batched:
        out = call(name, signature, q_rows=np.tile(q, (3, 1)))
        assert out.shape == expected(shape, rows=3), (name, shape)
