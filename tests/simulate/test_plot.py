"""result.plot, WorkPrecisionResult.plot and SizingReport.plot (armdyn.plotting): every line
drawn is the result's own array read back from the axes, with the joint's name as its label and
the unit on the axis; every kind on a Cartesian and a joint-space run; bad kinds, unknown joints
and kinds a run did not record raise naming the culprit; matplotlib is imported lazily."""

from __future__ import annotations

import dataclasses
import re
import subprocess
import sys
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

pytest.importorskip("matplotlib")
from matplotlib.figure import Figure

COORDINATES = ["cartesian", "joint"]
MG, L_STOP = 1.0 * 9.81, 0.1  # the limited pendulum: bob 1 kg at 1 m, lower stop at 0.1 rad


def limited_pendulum():
    """A point-like bob on a pivot with a stop at q = 0.1 rad, released at 0.3 rad: gravity
    brings it onto the stop, where it rests held by m g L sin(0.1)."""
    b = ad.ModelBuilder()
    b.add_body("bob", 1.0, [1e-4] * 3, position=(0, 0, -1))
    b.add_revolute("pivot", "ground", "bob", point=(0, 0, 0), axis=(0, 1, 0))
    b.set_joint_limits("pivot", L_STOP, 0.5)
    return b.finalize()


def ideal_gear_pair():
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("pinion", 0.2, [1e-4, 1e-4, 4e-5], position=(0, 0, 0))
    b.add_body("wheel", 1.0, [1e-3, 1e-3, 1.25e-3], position=(0.07, 0, 0))
    b.add_revolute("ja", "ground", "pinion", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jb", "ground", "wheel", point=(0.07, 0, 0), axis=(0, 0, 1))
    b.add_gear("mesh", "ja", "jb", 0.02, 0.05)
    b.add_joint_torque("ja", 0.5)
    return b.finalize()


@pytest.fixture(scope="module")
def runs():
    """(model, result) per scene and formulation, short runs on an output grid."""
    out = {}
    dp, lim, gear = ad.scenes.double_pendulum(), limited_pendulum(), ideal_gear_pair()
    for c in COORDINATES:
        out["double", c] = dp, ad.simulate(dp, 0.4, output_dt=0.02, coordinates=c)
        out["limit", c] = lim, ad.simulate(lim, 0.6, output_dt=0.02, q0=[0.3], coordinates=c)
        out["gear", c] = gear, ad.simulate(gear, 0.2, output_dt=0.02, coordinates=c)
    sc = ad.scenes.slider_crank()
    out["drive", "cartesian"] = sc, ad.simulate(sc, 0.3, output_dt=0.02)
    free = ad.scenes.free_body()
    out["free", "joint"] = free, ad.simulate(free, 0.2, output_dt=0.02, coordinates="joint")
    return out


def lines(ax, markers=False):
    """(label, x, y) of every data line of ax (with ``markers``: of the event markers, labelled
    "_events"), read back from matplotlib."""
    return [
        (ln.get_label(), *ln.get_xydata().T)
        for ln in ax.get_lines()
        if (ln.get_label() == "_events") == markers
    ]


def check_columns(ax, t, y, labels):
    got = lines(ax)
    assert [g[0] for g in got] == labels
    for k, (_, x, yk) in enumerate(got):
        np.testing.assert_array_equal(x, t)
        np.testing.assert_array_equal(yk, y[:, k])


# the joint-space tables: kind -> (result attribute, y label)
JOINT_KINDS = {
    "q": ("q", "q [rad]"),
    "qd": ("qd", "qd [rad/s]"),
    "qdd": ("qdd", "qdd [rad/s²]"),
    "torque": ("joint_torques", "τ [N m]"),
}


@pytest.mark.parametrize("coordinates", COORDINATES)
@pytest.mark.parametrize("kind", list(JOINT_KINDS))
def test_joint_space_kinds_draw_the_result_columns_named_with_units(runs, kind, coordinates):
    model, r = runs["double", coordinates]
    fig = r.plot(kind, model=model)
    assert isinstance(fig, Figure) and len(fig.axes) == 1
    ax = fig.axes[0]
    attr, ylabel = JOINT_KINDS[kind]
    check_columns(ax, r.t, getattr(r, attr), ["shoulder", "elbow"])
    assert ax.get_ylabel() == ylabel and ax.get_xlabel() == "t [s]"


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_reaction_energy_and_residual_panels(runs, coordinates):
    model, r = runs["double", coordinates]
    fig = r.plot(["reaction", "energy", "residual"], model=model, title="double pendulum")
    f_ax, m_ax, e_ax, p_ax, v_ax = fig.axes
    assert fig.get_suptitle() == "double pendulum"
    for ax, table, sym, unit in (
        (f_ax, r.reaction_forces, "F", "N"),
        (m_ax, r.reaction_torques, "M", "N m"),
    ):
        assert ax.get_ylabel() == f"{sym} [{unit}]"
        flat = table.reshape(len(r.t), -1)  # joint-major, x y z per joint
        labels = [f"{j} {sym}{c}" for j in ("shoulder", "elbow") for c in "xyz"]
        check_columns(ax, r.t, flat, labels)
    total = r.kinetic_energy + r.potential_energy
    check_columns(
        e_ax,
        r.t,
        np.column_stack([r.kinetic_energy, r.potential_energy, total]),
        ["kinetic", "potential (gravity, springs)", "total"],
    )
    assert e_ax.get_ylabel() == "energy [J]"
    for ax, y, unit in (
        (p_ax, r.position_residual, "m or rad"),
        (v_ax, r.velocity_residual, "m/s or rad/s"),
    ):
        ((_, x, yk),) = lines(ax)
        np.testing.assert_array_equal(x, r.t)
        np.testing.assert_array_equal(yk, y)
        assert ax.get_ylabel() == f"residual [{unit}]"
        assert ax.get_yscale() == ("log" if np.any(y > 0) else "linear")


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_limit_kind_draws_the_stop_torque_which_holds_m_g_l_sin_q(runs, coordinates):
    model, r = runs["limit", coordinates]
    ax = r.plot("limit", model=model).axes[0]
    check_columns(ax, r.t, r.limit_forces["force"], ["pivot"])
    assert ax.get_ylabel() == "stop effort [N m]"
    # resting on its lower stop the bob is held by the gravity torque (closed form)
    ((_, _, y),) = lines(ax)
    assert y[-1] == pytest.approx(MG * np.sin(L_STOP), rel=1e-9)
    # its landing on the stop (an impulse, not in limit_forces) is marked on the time axis
    assert list(r.events["limits"]["kind"]) == ["rest"]
    ((label, x, y),) = lines(ax, markers=True)
    np.testing.assert_array_equal(x, r.events["limits"]["t"])
    np.testing.assert_array_equal(y, [0.0])
    assert label not in [t.get_text() for t in ax.get_legend().get_texts()]


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_gear_kind_draws_the_mesh_force(runs, coordinates):
    model, r = runs["gear", coordinates]
    ax = r.plot("gear", joints="mesh", model=model).axes[0]
    check_columns(ax, r.t, r.gear_forces["force"], ["mesh"])
    assert ax.get_ylabel() == "mesh force [N]"


def test_drive_kind_draws_the_drive_effort(runs):
    model, r = runs["drive", "cartesian"]
    ax = r.plot("drive", model=model).axes[0]
    check_columns(ax, r.t, r.drive_forces, list(model.drive_names))
    assert ax.get_ylabel() == "effort [N m]"  # the crank's drive acts on a revolute joint


def test_a_floating_base_has_a_unit_per_line(runs):
    model, r = runs["free", "joint"]
    q_ax, qd_ax = r.plot(["q", "qd"], model=model).axes
    check_columns(
        q_ax, r.t, r.q, [f"float:{c} [m]" for c in "xyz"] + [f"float:e{k} [-]" for k in range(4)]
    )
    assert q_ax.get_ylabel() == "q [m, -]"
    labels = [f"float:v{c} [m/s]" for c in "xyz"] + [f"float:w{c} [rad/s]" for c in "xyz"]
    check_columns(qd_ax, r.t, r.qd, labels)
    # a joint's name selects all of its columns
    assert len(r.plot("q", joints="float", model=model).axes[0].get_lines()) == 7


@pytest.fixture(scope="module")
def ur5_runs():
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    model = ad.load_urdf(path)
    kw = dict(output_dt=0.02, q0=common.UR5_Q0, limits="ignore")
    return model, {c: ad.simulate(model, 0.2, coordinates=c, **kw) for c in COORDINATES}


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_ur5_selects_joints_by_name_and_index_in_the_order_given(ur5_runs, coordinates):
    model, runs_ = ur5_runs
    r = runs_[coordinates]
    names = list(model.joint_names)
    ax = r.plot("q", joints=["elbow_joint", 0], model=model).axes[0]
    check_columns(ax, r.t, r.q[:, [2, 0]], ["elbow_joint", "shoulder_pan_joint"])
    f_ax, m_ax = r.plot("reaction", joints=["wrist_3_joint"], model=model).axes
    check_columns(f_ax, r.t, r.reaction_forces[:, 5], [f"{names[5]} F{c}" for c in "xyz"])
    check_columns(m_ax, r.t, r.reaction_torques[:, 5], [f"{names[5]} M{c}" for c in "xyz"])
    # every kind that a UR5 falling freely records
    fig = r.plot(["q", "qd", "qdd", "torque", "reaction", "energy", "residual"], model=model)
    assert len(fig.axes) == 9
    assert [ln.get_label() for ln in fig.axes[1].get_lines()] == names


def test_the_result_holds_its_model_and_without_one_columns_are_numbered(runs):
    model, r = runs["double", "cartesian"]
    # simulate records the model: names and units without model=
    assert r.model is model
    ax = r.plot("qd", joints=["elbow"]).axes[0]
    check_columns(ax, r.t, r.qd[:, [1]], ["elbow"])
    assert ax.get_ylabel() == "qd [rad/s]"
    # a result without its model (built by hand, or model dropped): numbered columns
    bare = dataclasses.replace(r, model=None)
    ax = bare.plot("qd", joints=[1]).axes[0]
    check_columns(ax, r.t, r.qd[:, [1]], ["qd[1]"])
    assert ax.get_ylabel() == "qd [rad/s or m/s]"
    with pytest.raises(ad.ModelError, match=r"joint 'elbow' by name needs the model"):
        bare.plot("q", joints="elbow")


def test_draws_into_given_axes_and_saves_a_png(runs, tmp_path):
    model, r = runs["double", "joint"]
    fig = Figure()
    ax = fig.subplots()
    assert r.plot("q", model=model, ax=ax, lw=2.0) is ax
    check_columns(ax, r.t, r.q, ["shoulder", "elbow"])
    assert all(ln.get_linewidth() == 2.0 for ln in ax.get_lines())
    axes = Figure().subplots(2)
    assert r.plot("reaction", model=model, ax=axes) == list(axes)
    with pytest.raises(ValueError, match="2 panels to draw but 1 axes"):
        r.plot("reaction", model=model, ax=[ax])
    path = tmp_path / "run.png"
    r.plot(["q", "energy"], model=model, path=path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000


def test_bad_kinds_and_joints_raise_naming_the_culprit(runs, ur5_runs):
    model, r = runs["double", "cartesian"]
    with pytest.raises(ValueError, match=r"unknown kind 'angles'; the kinds are q, qd"):
        r.plot("angles", model=model)
    with pytest.raises(ValueError, match=r"unknown kind 'tau'"):
        r.plot(["q", "tau"], model=model)
    with pytest.raises(ad.ModelError, match=r"unknown joint 'wrist'.*\['shoulder', 'elbow'\]"):
        r.plot("q", joints=["shoulder", "wrist"], model=model)
    with pytest.raises(ad.ModelError, match=r"index 2 out of range.*2 columns"):
        r.plot("q", joints=[2], model=model)
    with pytest.raises(TypeError, match=r"names \(str\) or column indices \(int\)"):
        r.plot("q", joints=[1.0], model=model)
    # a result of another model
    ur5_r = ur5_runs[1]["cartesian"]
    with pytest.raises(ad.ModelError, match=r"result.q has shape \(11, 6\).*not from this model"):
        ur5_r.plot("q", model=model)


def test_kinds_a_run_did_not_record_say_what_records_them(runs):
    model, r = runs["double", "joint"]
    with pytest.raises(ad.ModelError, match=r"no joint-stop forces.*limits='enforce'"):
        r.plot("limit", model=model)
    with pytest.raises(ad.ModelError, match=r"no drives.*add_drive"):
        r.plot("drive", model=model)
    with pytest.raises(ad.ModelError, match=r"no gears"):
        r.plot(["q", "gear"], model=model)
    gear, rg = runs["gear", "joint"]
    with pytest.raises(ad.ModelError, match=r"gear 'ja' has no line.*\['mesh'\]"):
        rg.plot("gear", joints="ja", model=gear)
    empty = ad.SimulationResult(
        **{k: v[:0] for k, v in vars(r).items() if isinstance(v, np.ndarray)}, error="boom"
    )
    with pytest.raises(ValueError, match=r"no output rows \(the run could not start: boom\)"):
        empty.plot("q", model=model)


def test_work_precision_plot_draws_the_table_into_an_axes():
    pd = pytest.importorskip("pandas")
    table = pd.DataFrame(
        {
            "integrator": ["dopri5", "dopri5", "rk4", "rk4", "dopri5"],
            "coordinates": ["cartesian", "cartesian", "cartesian", "cartesian", "joint"],
            "error": [1e-3, 1e-6, 2e-2, np.nan, 1e-5],
            "cpu_s": [0.01, 0.05, 0.02, 0.03, 0.004],
            "status": ["ok", "ok", "ok", "failed", "ok"],
        }
    )
    wp = ad.WorkPrecisionResult(
        table=table,
        t=np.linspace(0, 1, 3),
        error_measure="max |q - q_ref| [rad]",
        reference={"dop853": {"estimated_error": 1e-9}},
    )
    ax = Figure().subplots()
    assert wp.plot(ax=ax, title="toy") is ax
    got = lines(ax)
    assert [g[0] for g in got] == ["dopri5", "rk4", "dopri5 (joint)", "reference's estimated error"]
    np.testing.assert_array_equal(got[0][1], [1e-3, 1e-6])
    np.testing.assert_array_equal(got[0][2], [0.01, 0.05])
    np.testing.assert_array_equal(got[1][1:], [[2e-2], [0.02]])  # the failed run is left out
    assert got[3][1][0] == 1e-9
    assert ax.get_xscale() == "log" and ax.get_title() == "toy"


def test_sizing_report_plot(runs, tmp_path):
    model, r = runs["drive", "cartesian"]
    report = ad.sizing_report(
        r, model, actuators={"crank_pin": dict(gear_ratio=50.0, rotor_inertia=1e-5)}
    )
    k = list(report.table.index).index("crank_pin")
    fig = report.plot("crank_pin", path=tmp_path / "crank.png")
    ((label, x, y),) = lines(fig.axes[0])[:1]
    assert label == "joint torque/force"
    np.testing.assert_array_equal(x, report.t)
    np.testing.assert_array_equal(y, report.torque[:, k])
    # the crank turns at a constant rate: the what-if rotor adds nothing but round-off to the
    # drive's effort
    np.testing.assert_allclose(y, r.drive_forces[:, 0], rtol=0, atol=1e-13)
    assert (tmp_path / "crank.png").read_bytes()[:4] == b"\x89PNG"
    # joint=None: a panel per joint with a torque (the driven crank only)
    assert [a.get_title() for a in report.plot().axes] == ["crank_pin"]
    ax = Figure().subplots()
    assert report.plot("crank_pin", kind="motor", ax=ax) is ax
    ((_, w, tm),) = lines(ax)[:1]
    np.testing.assert_array_equal(w, report.motors["crank_pin"].speed)
    np.testing.assert_array_equal(tm, report.motors["crank_pin"].torque)
    with pytest.raises(ad.ModelError, match=r"unknown joint 'crank'.*'crank_pin'"):
        report.plot("crank")
    with pytest.raises(ad.ModelError, match=r"'crank_rod' has no motor.*\['crank_pin'\]"):
        report.plot("crank_rod", kind="motor")
    with pytest.raises(ValueError, match=r"unknown kind 'speed'"):
        report.plot("crank_pin", kind="speed")


def test_import_armdyn_does_not_import_matplotlib():
    code = (
        "import sys, armdyn, armdyn.plotting; armdyn.SimulationResult.plot; "
        "assert 'matplotlib' not in sys.modules, 'matplotlib imported'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_docs_plotting_block_runs(tmp_path, monkeypatch):
    doc = (Path(__file__).resolve().parents[2] / "docs" / "plotting.md").read_text("utf-8")
    (block,) = re.findall(r"```python\n(.*?)```", doc, re.S)
    monkeypatch.chdir(tmp_path)
    # (how long the block takes is not a test: tests/docs/test_runnable_blocks.py bounds the
    # CPU time of all documented blocks together)
    exec(compile(block, "docs/plotting.md", "exec"), {})
    assert (tmp_path / "double_pendulum.png").read_bytes()[:4] == b"\x89PNG"
