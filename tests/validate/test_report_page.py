"""The report page's model and HTML (armdyn.sizing.html, armdyn.sizing.writer), without a
browser (tests/viz/test_report.py renders it):

- a SizingReport's verdict rows against a second computation straight from its table (the
  least of its margin columns, the table's ``ok``) and its motor details against the motor's
  datasheet;
- other parts' values (gearbox...) enter the details and the verdict when the table has them;
  parts without data say "not checked";
- a drivetrain selection (duck-typed as the spec's DrivetrainSelection) feeds the same page:
  verdict rows, ranking and the objective-against-margin figure;
- names from the model or a catalog are escaped; the page loads nothing from elsewhere.
"""

from __future__ import annotations

import re
from types import SimpleNamespace

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn.sizing import make_motor
from armdyn.sizing.checks import CHECKS_BY_NAME
from armdyn.sizing.html import (
    ReportModel,
    Section,
    VerdictRow,
    check_details,
    render_page,
    row_status,
)
from armdyn.sizing.writer import (
    cycle_torque_figure,
    report_verdict,
    selection_report_model,
    sweep_section,
    write_selection_report,
)

from benchmarks import common

# the table's margin columns of each check the verdict covers (a second, independent mapping)
TABLE_MARGINS = {
    "effort_limit": "torque_margin",
    "velocity_limit": "speed_margin",
    "continuous_torque": "continuous_torque_margin",
    "peak_torque": "peak_torque_margin",
    "speed": "motor_speed_margin",
    "envelope": "envelope_margin",
}


def motor(name, cont, peak):
    return make_motor(
        name=name,
        torque_constant=0.1,
        resistance=0.5,
        voltage=48.0,
        no_load_speed=480.0,
        continuous_torque=cont,
        peak_torque=peak,
        max_speed=400.0,
    )


@pytest.fixture(scope="module")
def ur5():
    model = ad.load_urdf(common.robot_urdf("ur5"))
    t = np.linspace(0.0, 2.0, 101)
    w = np.pi / 2.0
    s, sd, sdd = 0.5 - 0.5 * np.cos(w * t), 0.5 * w * np.sin(w * t), 0.5 * w * w * np.cos(w * t)
    dq = np.array([1.2, 0.6, -0.6, -0.7, 0.6, 0.8])
    q0 = np.array([0.0, -1.2, 1.0, -0.5, 0.4, 0.0])
    run = ad.trajectory_run(model, t, q0 + np.outer(s, dq), np.outer(sd, dq), np.outer(sdd, dq))
    spec = dict(gear_ratio=100.0, rotor_inertia=3e-5, efficiency=0.9)
    actuators = {
        "shoulder_pan_joint": dict(spec, motor=motor("<b>EC&45</b>", 0.3, 1.2)),
        "shoulder_lift_joint": dict(spec, motor=motor("small", 0.3, 1.2)),
        "elbow_joint": dict(spec, motor=motor("mid", 0.6, 2.5)),
        "wrist_2_joint": dict(spec, motor=make_motor(name="bare", torque_constant=0.05)),
    }
    return model, run, actuators, ad.sizing_report(run, model, actuators=actuators)


def test_verdict_rows_are_the_least_table_margin(ur5):
    *_, report = ur5
    rows, _ = report_verdict(report)
    table = report.table
    assert [r.joint for r in rows] == list(table.index)
    for r in rows:
        margins = {c: table.loc[r.joint, col] for c, col in TABLE_MARGINS.items()}
        checked = {c: m for c, m in margins.items() if not np.isnan(m)}
        least = min(checked, key=checked.get)
        assert r.binding_check == least and r.margin == checked[least], r
        expected = (
            "fail" if checked[least] < 1 else "pass" if table.loc[r.joint, "ok"] else "unchecked"
        )
        assert r.status == expected
    by = {r.joint: r for r in rows}
    assert by["shoulder_lift_joint"].status == "fail"  # 0.3 N m continuous is too small there
    assert by["wrist_2_joint"].status == "unchecked" and "peak_torque" in by["wrist_2_joint"].note
    assert by["wrist_1_joint"].parts == {} and by["elbow_joint"].parts == {
        "motor": "mid",
        "gearbox": "N = 100",
    }


def test_motor_details_against_the_datasheet(ur5):
    *_, report = ur5
    _, details = report_verdict(report)
    d = details.set_index(["joint", "check"])
    row = report.table.loc["elbow_joint"]
    cont = d.loc[("elbow_joint", "continuous_torque")]
    assert cont["value"] == row["motor_rms_torque"] and cont["allowable"] == 0.6
    assert cont["margin"] == pytest.approx(0.6 / row["motor_rms_torque"], rel=1e-15)
    assert d.loc[("elbow_joint", "speed")]["allowable"] == 400.0
    # the envelope's value is the worst |T + T0 w / w0|, T0 = k_t V / R, w0 the no-load speed
    env = d.loc[("elbow_joint", "envelope")]
    side = report.motors["elbow_joint"]
    t0 = 0.1 * 48.0 / 0.5
    worst = np.max(np.abs(side.torque + t0 * side.speed / 480.0))
    assert env["allowable"] == t0 and env["value"] == pytest.approx(worst, rel=1e-15)
    assert env["margin"] == pytest.approx(t0 / worst, rel=1e-12)
    # not made: the winding temperature (the report's thermal model is not a check) and every
    # gearbox, bearing, drive and brake check
    assert np.isnan(d.loc[("elbow_joint", "winding_temperature")]["margin"])
    others = details[details["part"].isin(["gearbox", "bearing", "drive", "brake"])]
    assert others["margin"].isna().all()


def test_other_parts_enter_when_the_table_has_them(ur5):
    """A gearbox's repeated peak in the table (CHECKS' column names): its check is made, it
    binds where its margin is the least, and a margin below 1 fails the joint."""
    *_, report = ur5
    from copy import copy

    rep = copy(report)
    rep.table = report.table.copy()
    n = len(rep.table)
    rep.table["gear_repeated_peak_torque"] = np.full(n, 40.0)
    rep.table["repeated_peak_torque"] = [30.0] + [400.0] * (n - 1)
    # the two-node check's columns, on the joints with a motor (NaN elsewhere)
    has = np.array([j in report.motors for j in rep.table.index])
    rep.table["winding_temperature_peak"] = np.where(has, 80.0, np.nan)
    rep.table["max_winding_temperature"] = np.where(has, 120.0, np.nan)
    rep.table["winding_temperature_margin"] = np.where(has, 2.0, np.nan)
    rows, details = report_verdict(rep)
    w = details[details["check"] == "winding_temperature"].set_index("joint")
    assert (
        (w.loc[list(report.motors), ["value", "allowable", "margin"]] == [80, 120, 2]).all().all()
    )
    assert w.loc["wrist_3_joint"].isna()[["value", "allowable", "margin"]].all()
    g = details[(details["check"] == "gear_repeated_peak")].set_index("joint")["margin"]
    assert g.iloc[0] == 30.0 / 40.0 and g.iloc[1] == 10.0
    assert rows[0].binding_check == "gear_repeated_peak" and rows[0].status == "fail"
    html = render_page(ReportModel("t", rows, details))
    assert "gear_repeated_peak (gearbox)" in re.sub(r"<[^>]+>", "", html)  # the text shown
    for part in ("bearing", "drive", "brake"):
        assert f'data-part="{part}">not checked: no {part} data' in html
    assert 'data-part="gearbox"' not in html
    # a joint without a motor: one line in the motor table, not a row per check
    for joint in ("wrist_1_joint", "wrist_3_joint"):
        line = f'<td>{joint}</td><td colspan="5" class="m-none">not checked: no motor data'
        assert html.count(line) == 1
    assert html.count('<td colspan="5"') == 2  # every joint has a gearbox value here


def test_row_status_and_overall():
    assert row_status(True, 1.0) == "pass" and row_status(True, np.inf) == "pass"
    assert row_status(False, 0.99) == "fail" and row_status(True, 0.5) == "fail"
    assert row_status(False, 2.0) == "unchecked" and row_status(False, np.nan) == "unchecked"
    row = lambda s: VerdictRow("j", {}, s, "", np.nan)  # noqa: E731
    empty = check_details([], {})
    assert ReportModel("t", [row("pass"), row("fail")], empty).status == "fail"
    assert ReportModel("t", [row("pass"), row("unchecked")], empty).status == "unchecked"
    assert ReportModel("t", [row("pass")], empty).status == "pass"
    assert ReportModel("t", [], empty).status == "unchecked"
    with pytest.raises(ValueError, match="status must be one of"):
        VerdictRow("j", {}, "ok", "", 1.0)


def test_check_details_margin_from_value_and_allowable():
    """Without a margin column the details compute it from value and allowable, a lower
    limit (a life) the other way round; missing columns are not checked."""
    d = check_details(["a", "b"], {"gear_life": [1e4, 4e4], "required_life": 2e4})
    life = d[d["check"] == "gear_life"]["margin"].to_numpy()
    np.testing.assert_array_equal(life, [0.5, 2.0])
    assert CHECKS_BY_NAME["gear_life"].lower
    assert d[d["check"] == "peak_torque"]["margin"].isna().all()
    # derived allowables: never for the winding temperature (its margin compares rises)
    cols = {"winding_temperature_peak": [80.0], "winding_temperature_margin": [2.0]}
    cols |= {"motor_rms_torque": [0.5], "continuous_torque_margin": [1.5]}
    d = check_details(["a"], cols, derive_allowable=True).set_index("check")["allowable"]
    assert np.isnan(d["winding_temperature"]) and d["continuous_torque"] == 0.75


def test_names_are_escaped_and_nothing_is_loaded(ur5):
    *_, report = ur5
    rows, details = report_verdict(report)
    sections = [Section("<script>x</script>", text="a < b & c", tables=[("t", report.table)])]
    html = render_page(ReportModel("Sizing <report>", rows, details, sections))
    assert "<b>EC&45</b>" not in html and "&lt;b&gt;EC&amp;45&lt;/b&gt;" in html
    assert "<script" not in html and "&lt;script&gt;" in html
    # nothing to fetch: no script, link, iframe, and every src/href is a data: URI or a fragment
    assert not re.search(r"<(script|link|iframe|object|embed)\b", html)
    for url in re.findall(r'(?:src|href)="([^"]*)"', html):
        assert url.startswith(("data:", "#")), url
    assert not re.search(r"url\(|@import", html)


class FakeSelection:
    """The DrivetrainSelection of issue 33 part 6 as the page reads it (branch i33-select):
    ``table`` by joint (parts, ok, binding_check, margin, objective, values, <check>_margin),
    ``objective``, ``passes``, ``converged``, ``infeasible``, ``bus`` and
    ``candidates(joint)`` ranked best first."""

    objective = "mass"
    passes = 2
    converged = True

    def __init__(self):
        self.table = pd.DataFrame(
            {
                "motor": ["M1", "M2"],
                "gearbox": ["G100", "G50"],
                "drive": [None, None],
                "ok": [True, False],
                "binding_check": ["gear_life", "peak_torque"],
                "margin": [1.4, 0.8],
                "objective": [1.2, 3.4],
                "mass": [1.2, 3.4],
                "gear_life": [2.8e4, 1e5],
                "gear_life_margin": [1.4, 5.0],
                "motor_peak_torque": [1.0, 2.5],
                "peak_torque_margin": [3.0, 0.8],
            },
            index=pd.Index(["j1", "j2"], name="joint"),
        )
        self.infeasible = pd.DataFrame(
            {
                "joint": ["j2"],
                "check": ["peak_torque"],
                "part": ["motor"],
                "best_margin": [0.8],
                "motor": ["M2"],
                "gearbox": ["G50"],
                "drive": [None],
                "reason": ["no candidate passes peak_torque (motor): best margin 0.8"],
            }
        )
        self.bus = {"peak_bus_power": 812.5, "bus_voltage_margin": 1.3, "power": np.zeros(5)}
        t = np.array([0.0, 0.5, 1.0, 1.0, 3.0])
        torque = np.array([[1.0, 2.0], [3.0, -1.0], [2.0, 0.5], [2.5, 0.4], [2.5, 0.4]])
        self.cycle = SimpleNamespace(
            t=t,
            names=["j1", "j2", "j3"],
            torque=np.c_[torque, np.zeros(5)],
            gravity_torque=np.c_[torque * 0.5, np.zeros(5)],
            moving=t < 1.0,
        )

    def candidates(self, joint):
        rng = np.random.default_rng(len(joint))
        m = np.sort(rng.uniform(0.5, 3.0, 14))[::-1]
        m[3] = np.inf  # a zero load: drawn at the axis' end, not lost
        y = rng.uniform(1, 4, 14)
        return pd.DataFrame(
            {"motor": [f"M{k}" for k in range(14)], "objective": y, "margin": m, "x": y},
            index=pd.RangeIndex(1, 15, name="rank"),
        )


def test_a_selection_feeds_the_same_page(tmp_path):
    sel = FakeSelection()
    model = selection_report_model(sel)
    assert [(r.joint, r.status, r.binding_check, r.margin) for r in model.rows] == [
        ("j1", "pass", "gear_life", 1.4),
        ("j2", "fail", "peak_torque", 0.8),
    ]
    assert model.rows[0].parts == {"motor": "M1", "gearbox": "G100"}  # no drive: not shown
    assert model.rows[1].note == "no feasible candidate: closest shown; peak_torque best margin 0.8"
    d = model.checks.set_index(["joint", "check"])["margin"]
    assert d[("j1", "gear_life")] == 1.4 and d[("j2", "peak_torque")] == 0.8
    # the allowables the margins imply: a life (lower limit) value / margin, a torque margin x
    # value (the catalog's 2e4 h and 3 N m, 2 N m of the fake's table)
    a = model.checks.set_index(["joint", "check"])["allowable"]
    assert a[("j1", "gear_life")] == pytest.approx(2.8e4 / 1.4, rel=1e-15)
    assert a[("j1", "peak_torque")] == 3.0 and a[("j2", "peak_torque")] == 2.0
    assert np.isnan(a[("j1", "speed")])  # no value, no margin
    assert np.isnan(d[("j1", "bearing_moment")])
    assert model.status == "fail" and "2 coupled pass(es)" in model.subtitle
    titles = [s.title for s in model.sections]
    assert titles == [
        "Ranking",
        "Torque histories",
        "Where nothing fits",
        "DC bus of the chosen set",
        "All values",
    ]
    # the cycle's panels: one per selected joint, the torque and the holding torque as given
    assert model.sections[1].figures[0].png[:4] == b"\x89PNG"
    fig = cycle_torque_figure(sel.cycle, ["j1", "j2"])
    for ax, k in zip(fig.axes[:2], (0, 1), strict=True):
        (_, y), (_, g) = (line.get_data() for line in ax.lines[:2])
        np.testing.assert_array_equal(y, sel.cycle.torque[:, k])
        np.testing.assert_array_equal(g, sel.cycle.gravity_torque[:, k])
        # the shaded dwell (axvspan: a Rectangle, x in data units) where the cycle does not move
        span = ax.patches[0]
        assert (span.get_x(), span.get_x() + span.get_width()) == (1.0, 3.0)
    assert [a.get_ylabel() for a in fig.axes[:2]] == ["j1\n[N m]", "j2\n[N m]"]
    bus = model.sections[3].tables[0][1]
    ranking = model.sections[0]
    assert list(ranking.tables[0][1].columns) == ["motor", "margin", "objective"]
    assert len(ranking.tables[0][1]) == 10
    assert list(bus.index) == ["peak_bus_power", "bus_voltage_margin"]  # the scalars
    sel.converged = False
    assert "NOT CONVERGED" in selection_report_model(sel).subtitle
    sel.converged = True
    page = write_selection_report(sel, tmp_path / "sel")
    html = page.read_text("utf-8")
    assert (tmp_path / "sel" / "ranking.png").read_bytes()[:4] == b"\x89PNG"
    assert pd.read_csv(tmp_path / "sel" / "selection.csv", index_col="joint").shape == (2, 12)
    assert html.index('id="verdict"') < html.index('id="checks"') < html.index("Ranking")


def test_the_sweep_section():
    pendulum = common.ROOT / "tests" / "data" / "urdf" / "sizing_pendulum.urdf"
    model = ad.load_urdf(pendulum)
    t = np.linspace(0.0, 2.0, 201)
    q = 0.5 * np.sin(np.pi * t)
    qd, qdd = 0.5 * np.pi * np.cos(np.pi * t), -(np.pi**2) * q
    run = ad.trajectory_run(model, t, q[:, None], qd[:, None], qdd[:, None])
    act = {"pivot": dict(rotor_inertia=1e-5, motor=motor("m", 0.2, 0.6))}
    sweep = ad.gear_ratio_sweep(run, model, ratios=np.geomspace(10, 300, 7), actuators=act)
    s = sweep_section(sweep)
    assert len(s.figures) == 1 and s.figures[0].png[:4] == b"\x89PNG"
    pd.testing.assert_frame_equal(s.tables[0][1], sweep.summary)
    assert "not run" in sweep_section(None).text


def test_a_joint_without_limits_or_motor_is_not_checked():
    """An infinite joint limit is none given: a joint without limits and without a motor has
    nothing checked (status 'unchecked', no binding check), while a joint with a limit is
    checked against it."""
    b = ad.ModelBuilder(gravity=(0, 0, -9.81))
    b.add_body("upper", mass=2.0, inertia=[0.02, 0.17, 0.17], position=(0.4, 0, 0))
    b.add_body("fore", mass=1.0, inertia=[0.005, 0.05, 0.05], position=(1.0, 0, 0))
    b.add_revolute("shoulder", "ground", "upper", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_revolute("elbow", "upper", "fore", point=(0.8, 0, 0), axis=(0, 1, 0))
    b.set_joint_limits("shoulder", -3.0, 3.0, effort=60.0, velocity=5.0)
    model = b.finalize()
    t = np.linspace(0.0, 1.0, 101)
    q, qd, qdd = ad.profiles.quintic(0.0, 1.0, 0.0, 1.0).eval(t)
    two = [np.stack([x, x], axis=1) for x in (q, qd, qdd)]
    report = ad.sizing_report(ad.trajectory_run(model, t, *two))
    rows, _ = report_verdict(report)
    by = {r.joint: r for r in rows}
    assert by["elbow"].status == "unchecked" and by["elbow"].binding_check == ""
    assert np.isnan(by["elbow"].margin)
    margins = {
        "effort_limit": 60.0 / float(np.max(np.abs(report.torque[:, 0]))),
        "velocity_limit": 5.0 / float(np.max(np.abs(qd))),
    }
    least = min(margins, key=margins.get)
    assert by["shoulder"].status == "pass" and by["shoulder"].binding_check == least
    assert by["shoulder"].margin == pytest.approx(margins[least], rel=1e-12)
