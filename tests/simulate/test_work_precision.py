"""``armdyn.work_precision``: error against CPU time for a user's own model.

On a five-DOF arm built here with ``ModelBuilder`` (waist, shoulder, elbow, wrist pitch and roll;
released from a bent pose with the waist turning), the sweep's errors are measured against the
default reference, DOP853 at rtol 1e-13 on the joint coordinates while the sweep integrates the
Cartesian formulation. Checked here:

* the table: its columns and dtypes; every integrator's curve; DOPRI5's error falls by more than
  100x over its sweep, RK4's by about 16x per halved step (fourth order);
* the tightest DOPRI5 point against an independent solution: SciPy DOP853 (rtol 1e-13) on
  M(q) q'' = -b(q, q') from ``LagrangeValidator`` (Euler–Lagrange equations by automatic
  differentiation, no Newton–Euler code), and the reference against a Cartesian DOP853 run;
* the references' bookkeeping: the reference's own error estimate, a closed loop falling back
  to the Cartesian formulation with a different integrator for DOP853's curve, a fully driven
  model measured against the kinematic path, a reference given by the user;
* failed runs as rows, bad inputs as ``ModelError``, the plot, and ``import armdyn`` staying
  free of pandas (and of dask, distributed and xarray, which armdyn.sweep imports when run).
"""

import subprocess
import sys

import armdyn as ad
import numpy as np
import pytest
from armdyn.papers import five_dof
from armdyn.scenes import standard

T_END = 1.0
N_OUT = 50
Q0 = np.array([0.2, -0.6, 0.9, 0.3, 0.5])
QD0 = np.array([1.5, 0.0, -0.5, 0.0, 2.0])
RTOLS = [1e-4, 1e-6, 1e-8, 1e-10]


def five_dof_arm():
    """A user's arm: waist about z, shoulder, elbow and wrist pitch about y, a roll about the
    last link's axis x, with an off-axis tool on the roll."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("base", 3.0, [0.02, 0.02, 0.015], position=(0, 0, 0.1))
    b.add_body("upper", 2.0, [0.003, 0.04, 0.04], position=(0.2, 0, 0.2))
    b.add_body("fore", 1.2, [0.002, 0.02, 0.02], position=(0.55, 0, 0.2))
    b.add_body("wrist", 0.5, [0.0005, 0.001, 0.001], position=(0.75, 0, 0.2))
    b.add_body("tool", 0.4, [0.0008, 0.0012, 0.0006], position=(0.88, 0.03, 0.2))
    b.add_revolute("waist", "ground", "base", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("shoulder", "base", "upper", point=(0, 0, 0.2), axis=(0, 1, 0))
    b.add_revolute("elbow", "upper", "fore", point=(0.4, 0, 0.2), axis=(0, 1, 0))
    b.add_revolute("pitch", "fore", "wrist", point=(0.7, 0, 0.2), axis=(0, 1, 0))
    b.add_revolute("roll", "wrist", "tool", point=(0.8, 0, 0.2), axis=(1, 0, 0))
    return b.finalize()


@pytest.fixture(scope="module")
def arm():
    return five_dof_arm()


@pytest.fixture(scope="module")
def sweep(arm):
    return ad.work_precision(
        arm,
        T_END,
        q0=Q0,
        qd0=QD0,
        integrators=["dopri5", "dop853", "trbdf2", "rk4"],
        rtols={"dopri5": RTOLS, "dop853": RTOLS, "trbdf2": [1e-3, 1e-4, 1e-5, 1e-6]},
        n_out=N_OUT,
    )


def _curve(table, integrator):
    return table[table["integrator"] == integrator]


def test_table_columns_and_dtypes(sweep):
    tab = sweep.table
    assert list(tab.columns) == list(ad.workprecision.COLUMNS)
    for col in ("integrator", "coordinates", "status", "message", "reference", "error_measure"):
        assert tab[col].map(type).eq(str).all(), col
    for col in ("rtol", "atol", "dt", "error", "cpu_s", "integration_s", "max_position_residual"):
        assert tab[col].dtype == np.float64, col
    for col in ("steps", "rejected", "rhs_evals", "kkt_solves", "factorizations"):
        assert str(tab[col].dtype) == "Int64", col
    assert len(tab) == 4 + 4 + 4 + 6
    assert (tab["status"] == "ok").all(), tab[["integrator", "message"]]
    assert (tab["coordinates"] == "cartesian").all()
    # atol is tied to rtol (atol_factor 1); RK4 rows carry the step instead
    tol_rows = tab[tab["integrator"] != "rk4"]
    np.testing.assert_array_equal(tol_rows["atol"], tol_rows["rtol"])
    assert tol_rows["dt"].isna().all()
    rk4 = _curve(tab, "rk4")
    assert rk4["rtol"].isna().all() and rk4["atol"].isna().all()
    # default steps: the output spacing divided by 1 ... 32
    np.testing.assert_allclose(rk4["dt"], T_END / N_OUT / np.array([1, 2, 4, 8, 16, 32]))
    np.testing.assert_array_equal(rk4["steps"], N_OUT * np.array([1, 2, 4, 8, 16, 32]))
    assert (tab["cpu_s"] > 0).all() and (tab["rhs_evals"] > 0).all()
    assert (tab["max_position_residual"] < 1e-9).all()
    assert tab["error_measure"].str.contains("joint coordinates").all()
    assert "rad" in sweep.error_measure and "m for displacements" in sweep.error_measure
    assert len(sweep.t) == N_OUT + 1


def test_errors_fall_along_each_curve(sweep):
    tab = sweep.table
    assert tab["integrator"].nunique() >= 3
    dopri5 = _curve(tab, "dopri5")["error"].to_numpy()
    assert dopri5[0] / dopri5[-1] >= 100.0, dopri5
    assert dopri5[-1] < 1e-8, dopri5
    # error control follows the tolerance: within two decades of it at each point
    np.testing.assert_array_less(dopri5, 100 * np.array(RTOLS))
    dop853 = _curve(tab, "dop853")["error"].to_numpy()
    assert dop853[0] / dop853[-1] >= 100.0, dop853
    trbdf2 = _curve(tab, "trbdf2")["error"].to_numpy()
    assert trbdf2[0] / trbdf2[-1] >= 10.0, trbdf2
    # RK4 at fixed steps: fourth order, 16x per halved step once in the asymptotic range
    rk4 = _curve(tab, "rk4")["error"].to_numpy()
    ratios = rk4[2:-1] / rk4[3:]  # the last point may touch the reference's floor
    assert np.all((ratios > 10) & (ratios < 25)), rk4
    # tighter tolerances cost more steps
    assert np.all(np.diff(_curve(tab, "dopri5")["steps"].to_numpy()) > 0)


def test_reference_is_the_other_formulation_and_its_floor_is_below_every_error(sweep):
    (label,) = sweep.reference
    assert label == "dop853 rtol 1e-13 (joint)"
    ref = sweep.reference[label]
    assert ref["method"] == "dop853" and ref["formulation"] == "joint" and ref["rtol"] == 1e-13
    assert (sweep.table["reference"] == label).all()
    # DOP853 at 1e-13 against 1e-12: far below the smallest error of the sweep
    assert 0 < ref["estimated_error"] < 1e-10
    assert ref["estimated_error"] < sweep.table["error"].min() / 10
    assert sweep.floor() == ref["estimated_error"]


def _lagrange_solution(model, t):
    """SciPy DOP853 at rtol 1e-13 on M(q) q'' = -b(q, q') from the Euler–Lagrange validator:
    b = torques(q, q', 0) holds the velocity and gravity terms, and no joint is actuated."""
    from scipy.integrate import solve_ivp

    lag = ad.LagrangeValidator(model)
    n = model.n_coords
    zero = np.zeros(n)

    def f(_t, y):
        q, qd = y[:n], y[n:]
        qdd = np.linalg.solve(lag.mass_matrix(q), -lag.torques(q, qd, zero))
        return np.concatenate([qd, qdd])

    sol = solve_ivp(
        f, (0.0, t[-1]), np.concatenate([Q0, QD0]), "DOP853", t_eval=t, rtol=1e-13, atol=1e-13
    )
    assert sol.success
    return sol.y[:n].T


def test_tightest_point_against_an_independent_lagrange_solution(arm, sweep):
    lagrange = _lagrange_solution(arm, sweep.t)
    ref = sweep.reference_values["dop853 rtol 1e-13 (joint)"]
    # the default reference agrees with the Euler–Lagrange solution far below the sweep's errors
    # (2e-12 measured; SciPy at rtol 1e-12 is itself 6e-11 off)
    assert np.abs(ref - lagrange).max() < 1e-11
    # the tightest DOPRI5 point: the same run measured against the independent solution gives
    # the table's error
    row = _curve(sweep.table, "dopri5").iloc[-1]
    res = ad.simulate(
        arm,
        T_END,
        integrator="dopri5",
        rtol=row["rtol"],
        atol=row["atol"],
        output_dt=T_END / N_OUT,
        q0=Q0,
        coordinates="cartesian",  # the sweep's formulation (its default)
        qd0=QD0,
    )
    independent = np.abs(res.q - lagrange).max()
    assert 1e-10 < independent == pytest.approx(row["error"], rel=0.02)
    # the table's number, recomputed as the table measures it (angles wrapped: d + pi rounds d
    # to the ulp of pi, so the unwrapped difference can differ in its last bits)
    d = np.remainder(res.q - ref + np.pi, 2 * np.pi) - np.pi
    assert np.abs(d).max() == row["error"]


def test_reference_agrees_with_a_cartesian_run(arm, sweep):
    cart = ad.simulate(
        arm,
        T_END,
        integrator="dop853",
        rtol=1e-13,
        atol=1e-13,
        output_dt=T_END / N_OUT,
        q0=Q0,
        qd0=QD0,
    )
    assert np.abs(cart.q - sweep.reference_values["dop853 rtol 1e-13 (joint)"]).max() < 1e-10


def test_joint_sweep_is_measured_against_the_cartesian_formulation(arm):
    r = ad.work_precision(
        arm, 0.5, q0=Q0, qd0=QD0, integrators=["dopri5"], rtols=[1e-5], coordinates="joint"
    )
    assert list(r.reference) == ["dop853 rtol 1e-13 (cartesian)"]
    assert r.table["coordinates"].tolist() == ["joint"]
    assert r.table["kkt_solves"].tolist() == [0]  # the joint path solves no KKT system
    assert 1e-8 < r.table["error"].iloc[0] < 1e-4


def test_user_reference_as_callable_arrays_or_result(arm, sweep):
    label = "dop853 rtol 1e-13 (joint)"
    values = sweep.reference_values[label]
    given = ad.simulate(
        arm,
        T_END,
        integrator="dop853",
        rtol=1e-13,
        atol=1e-13,
        output_dt=T_END / N_OUT,
        q0=Q0,
        qd0=QD0,
        coordinates="joint",
    )
    opts = dict(q0=Q0, qd0=QD0, integrators=["dopri5"], rtols=RTOLS[:2], n_out=N_OUT)
    expected = _curve(sweep.table, "dopri5")["error"].to_numpy()[:2]

    def on_grid(t):  # a callable, evaluated on the output grid
        return np.column_stack([np.interp(t, sweep.t, column) for column in values.T])

    for reference in ((sweep.t, values), given, on_grid):
        r = ad.work_precision(arm, T_END, reference=reference, **opts)
        assert list(r.reference) == ["user"] and np.isnan(r.floor())
        assert (r.table["reference"] == "user").all()
        np.testing.assert_allclose(r.table["error"], expected, rtol=1e-6)
    with pytest.raises(ad.ModelError, match="output grid"):
        ad.work_precision(arm, T_END, reference=(sweep.t[::2], values[::2]), **opts)
    with pytest.raises(ad.ModelError, match="columns"):
        ad.work_precision(arm, T_END, reference=(sweep.t, values[:, :3]), **opts)


def test_closed_loop_uses_the_cartesian_formulation_with_another_integrator():
    model = standard.andrews_squeezer()
    assert "closed loops" in model.joint_path_reason
    r = ad.work_precision(model, 0.01, integrators=["dopri5", "dop853"], rtols=[1e-5, 1e-8])
    refs = r.table.groupby("integrator")["reference"].first()
    assert refs["dopri5"] == "dop853 rtol 1e-13 (cartesian)"
    assert refs["dop853"] == "dopri5 rtol 1e-12 (cartesian)"  # a different method
    assert "closed loops" in r.reference[refs["dopri5"]]["why"]
    assert (r.table["status"] == "ok").all()
    err = r.table["error"].to_numpy()
    assert err[0] / err[1] > 100 and err[2] / err[3] > 100
    assert r.floor() < 1e-9


def test_fully_driven_model_against_the_kinematic_path():
    r = ad.work_precision(
        five_dof.five_dof_arm(), 5.0, integrators=["kinematic", "dopri5"], rtols=[1e-6], n_out=20
    )
    assert list(r.reference) == ["kinematic (cartesian)"]
    assert r.table["integrator"].tolist() == ["kinematic", "dopri5"]
    # the drives prescribe every coordinate: the integrator only feeds the position solves
    assert (r.table["error"] < 1e-11).all()


def test_a_failing_run_is_a_row(arm):
    r = ad.work_precision(
        arm,
        T_END,
        q0=Q0,
        qd0=QD0,
        integrators=["dopri5", "rk4"],
        rtols=[1e-3, 1e-10],
        dts=[0.02, 0.001],
        max_steps=200,
    )
    tab = r.table
    assert tab["status"].tolist() == ["ok", "failed", "ok", "failed"]
    failed = tab[tab["status"] == "failed"]
    assert failed["error"].isna().all()
    assert failed["message"].str.contains("more than 200 steps").all()
    assert (failed["cpu_s"] > 0).all()
    assert failed["steps"].tolist() == [200, 200]  # the counters up to the failure
    assert np.isfinite(tab[tab["status"] == "ok"]["error"]).all()


def test_a_diverging_run_is_a_row():
    # a stiff joint spring (about 6300 rad/s): RK4 diverges at steps above 4.4e-4 s
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("p", 1.0, [0.01, 0.01, 0.01], position=(0.5, 0, 0))
    b.add_revolute("hinge", "ground", "p", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_joint_spring_damper("hinge", stiffness=1e7)
    model = b.finalize()
    r = ad.work_precision(model, 0.2, integrators=["rk4"], dts=[0.01, 1e-4], q0=[0.1], qd0=[0])
    first, second = r.table.itertuples()
    assert first.status == "failed" and np.isnan(first.error), first
    assert "did not converge" in first.message, first.message  # the projection gave up
    assert second.status == "ok" and np.isfinite(second.error)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"t_end": 0.0}, "t_end must be a positive number"),
        ({"t_end": -1.0}, "t_end must be a positive number"),
        ({"t_end": float("nan")}, "t_end must be a positive number"),
        ({"integrators": ["euler"]}, "unknown integrator 'euler'"),
        ({"integrators": ["auto"]}, "unknown integrator 'auto'"),
        ({"integrators": ["dopri5", "dopri5"]}, "duplicates"),
        ({"integrators": ["kinematic"]}, "fully driven"),
        ({"q0": np.zeros(4)}, r"q0 needs 5 joint coordinates .* shape \(4,\)"),
        ({"q0": [0, 0, np.nan, 0, 0]}, r"q0 has non-finite entries at \[2\]"),
        ({"q0": Q0, "qd0": np.zeros(6)}, "qd0 needs 5"),
        ({"qd0": np.zeros(5)}, "qd0 given without q0"),
        ({"rtols": [1e-6, -1e-3]}, "rtols of dopri5 must be positive"),
        ({"rtols": {"rk4": [1e-3]}}, r"rtols names \['rk4'\]"),
        ({"dts": [0.0]}, "dts must be positive"),
        ({"n_out": 0}, "n_out must be a positive integer"),
        ({"coordinates": "polar"}, "coordinates must be"),
        ({"observe": lambda res: res.q}, "observe needs reference="),
        ({"reference": "exact"}, "reference must be a callable"),
    ],
)
def test_bad_input_is_a_model_error(arm, kwargs, match):
    kwargs = {"t_end": T_END, **kwargs}
    with pytest.raises(ad.ModelError, match=match):
        ad.work_precision(arm, **kwargs)


def test_joint_coordinates_on_a_closed_loop_is_a_model_error():
    with pytest.raises(ad.ModelError, match=r"coordinates='joint' does not apply.*closed loops"):
        ad.work_precision(standard.andrews_squeezer(), 0.01, coordinates="joint")


def test_angles_are_wrapped_and_a_model_without_coordinates_is_a_model_error():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.01, 0.01, 0.01], position=(0.3, 0, 0))
    b.add_body("c", 1.0, [0.01, 0.012, 0.015], position=(0.6, 0, 0))
    b.add_cylindrical("j1", "ground", "a", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_spherical("j2", "a", "c", point=(0.45, 0, 0))
    model = b.finalize()
    np.testing.assert_array_equal(ad.workprecision._angular_mask(model), [True, False])
    np.testing.assert_array_equal(ad.workprecision._angular_mask(five_dof_arm()), [True] * 5)
    # an angle across the cut at pi is 0.2 rad off, not 2 pi - 0.2; displacements are not wrapped
    err = ad.workprecision._max_error
    assert err([[np.pi - 0.1, 1.0]], [[-np.pi + 0.1, 1.0]], [True, False]) == pytest.approx(0.2)
    assert err([[0.0, 7.0]], [[0.0, 0.0]], [True, False]) == 7.0
    b = ad.ModelBuilder()
    b.add_body("ball", 1.0, [0.01, 0.01, 0.01], position=(0.3, 0, 0))
    b.add_spherical("s", "ground", "ball", point=(0, 0, 0))
    with pytest.raises(ad.ModelError, match="no joint coordinates to compare"):
        ad.work_precision(b.finalize(), 1.0)


def test_plot_draws_one_line_per_integrator(sweep, tmp_path):
    path = tmp_path / "wp.png"
    fig = sweep.plot(path, title="five-DOF arm")
    assert path.stat().st_size > 10_000
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    labels = [line.get_label() for line in ax.get_lines()]
    assert labels == ["dopri5", "dop853", "trbdf2", "rk4", "reference's estimated error"]
    x, y = ax.get_lines()[0].get_data()
    np.testing.assert_array_equal(x, _curve(sweep.table, "dopri5")["error"])
    np.testing.assert_array_equal(y, _curve(sweep.table, "dopri5")["cpu_s"])


def test_import_armdyn_does_not_import_pandas():
    code = (
        "import sys, armdyn; armdyn.sweep; "
        "heavy = ('pandas', 'dask', 'distributed', 'xarray', 'matplotlib'); "
        "heavy = [m for m in heavy if m in sys.modules]; "
        "assert not heavy, f'imported: {heavy}'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
