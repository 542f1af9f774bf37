"""The sizing report's files (:meth:`SizingReport.save`): ``table.csv``, the figures
``torque_<k>.png`` / ``motor_<k>.png`` and the page ``report.html``, which opens with the
verdict and embeds every figure (:mod:`armdyn.sizing.html`; it needs no other file).

:func:`report_model` turns a :class:`SizingReport` into the page's
:class:`~armdyn.sizing.html.ReportModel`:

- the verdict row of a joint: its motor (the :class:`armdyn.Motor`'s name) and gear ratio,
  ``status`` from the table's ``ok`` (fail when a made check fails, "not checked" when ``ok``
  is False only because a motor check could not be made: the table's ``unchecked``), and the
  binding check and margin of :func:`armdyn.sizing.checks.verdict` over the joint's checks;
- the checks: the joint's own limits (:data:`JOINT_CHECKS`: ``torque_margin``,
  ``speed_margin``), the motor checks of :data:`armdyn.sizing.checks.CHECKS` from the report's
  motor columns and its motor's datasheet, and every other check of CHECKS whose columns the
  table has (the winding temperature, the gearbox, bearing, drive and brake values, when
  present: CHECKS' value, allowable and margin column names);
- the sections: torque histories, thermal histories (the first-order winding rise of
  :func:`armdyn.sizing.thermal.thermal_rise`, where the motor gives ``thermal_resistance`` and
  ``thermal_time_constant`` and the copper loss is known), each motor's operating points on
  its speed–torque plane, the gear-ratio sweep (when one is passed) and the full table.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from armdyn.sizing.checks import CHECKS, Check
from armdyn.sizing.drivetrain import OBJECTIVE_LABELS
from armdyn.sizing.html import (
    ReportFigure,
    ReportModel,
    Section,
    VerdictRow,
    check_details,
    figure_png,
    render_page,
    row_status,
    verdict_of,
)

#: a SizingReport (armdyn.sizing.report imports this module)
_SizingReport = Any

#: the joint's own limits (URDF ``<limit>``), checked by every sizing report
JOINT_CHECKS: tuple[Check, ...] = (
    Check(
        "effort_limit",
        "joint",
        "joint_peak_torque",
        "effort_limit",
        False,
        "N m or N",
        "largest joint torque/force (the rotor's share included) against the effort limit",
    ),
    Check(
        "velocity_limit",
        "joint",
        "joint_peak_speed",
        "velocity_limit",
        False,
        "rad/s or m/s",
        "largest joint speed against the velocity limit",
    ),
)

#: the report's motor margin columns by check name (armdyn.sizing.motor.MOTOR_CHECKS)
_MOTOR_MARGINS = {
    "continuous_torque": "continuous_torque_margin",
    "peak_torque": "peak_torque_margin",
    "speed": "motor_speed_margin",
    "envelope": "envelope_margin",
}


def write_report(
    report: _SizingReport, directory: str | os.PathLike[str], sweep: Any = None
) -> Path:
    """Write ``table.csv``, the figures and ``report.html`` of ``report`` into ``directory``
    (created if missing); returns the HTML page's path (see :meth:`SizingReport.save`)."""
    out = Path(os.fspath(directory))
    out.mkdir(parents=True, exist_ok=True)
    report.table.to_csv(out / "table.csv")
    model = report_model(report, sweep=sweep)
    for section in model.sections:
        for f in section.figures:
            if f.file:
                (out / f.file).write_bytes(f.png)
    page = out / "report.html"
    page.write_text(render_page(model), encoding="utf-8")
    return page


def _motor_attr(motor, name: str) -> float:
    value = getattr(motor, name, None) if motor is not None else None
    return np.nan if value is None else float(value)


def _check_columns(report: _SizingReport) -> dict[str, np.ndarray]:
    """The wide columns :func:`armdyn.sizing.html.check_details` reads (CHECKS' value,
    allowable and margin column names), per joint of the report's table."""
    from armdyn.sizing.motor import motor_envelope

    table = report.table
    joints = list(table.index)
    n = len(joints)
    cols: dict[str, np.ndarray] = {}
    # the other checks' values, when the table has them (CHECKS' own column names; the four
    # motor checks below have the report's own columns, "speed_margin" there is the joint's)
    for c in CHECKS:
        if c.name not in _MOTOR_MARGINS:
            for name in (c.value, c.allowable, c.margin_column):
                if name in table.columns:
                    cols[name] = table[name].to_numpy(dtype=float)
    # the joint's limits
    for c, v, m in zip(
        JOINT_CHECKS, ("peak_torque", "peak_speed"), ("torque_margin", "speed_margin"), strict=True
    ):
        cols[c.value] = table[v].to_numpy(dtype=float)
        limit = table[c.allowable].to_numpy(dtype=float)
        # an infinite limit is none given (the URDF or builder set none): not checked
        cols[c.allowable] = np.where(np.isinf(limit), np.nan, limit)
        cols[c.margin_column] = np.where(np.isinf(limit), np.nan, table[m].to_numpy(dtype=float))
    # the motor: the report's columns, the datasheet's limits
    allow = {k: np.full(n, np.nan) for k in ("continuous_torque", "peak_torque", "max_speed")}
    stall, worst = np.full(n, np.nan), np.full(n, np.nan)
    for k, joint in enumerate(joints):
        motor = report.envelopes.get(joint)
        if joint not in report.motors or motor is None:
            continue
        allow["continuous_torque"][k] = _motor_attr(motor, "continuous_torque")
        allow["peak_torque"][k] = _motor_attr(motor, "peak_torque")
        speed = _motor_attr(motor, "max_speed")
        allow["max_speed"][k] = speed if np.isfinite(speed) else _motor_attr(motor, "no_load_speed")
        t0, w0 = motor_envelope(motor)
        side = report.motors[joint]
        if np.isfinite(t0) and np.isfinite(w0) and t0 > 0 and w0 > 0:
            stall[k] = t0
            worst[k] = float(np.max(np.abs(side.torque + t0 * side.speed / w0)))
    cols.update(allow)
    cols["stall_torque"], cols["envelope_worst"] = stall, worst
    for name in ("motor_rms_torque", "motor_peak_torque", "motor_peak_speed"):
        if name in table.columns:
            cols[name] = table[name].to_numpy(dtype=float)
    for check, column in _MOTOR_MARGINS.items():
        if column in table.columns:
            cols[f"{check}_margin"] = table[column].to_numpy(dtype=float)
        else:  # no actuator in the report: the motor checks are not made
            cols[f"{check}_margin"] = np.full(n, np.nan)
    return cols


def _verdict_rows(report: _SizingReport, details) -> list[VerdictRow]:
    table = report.table
    rows = []
    for joint in table.index:
        _, binding, least = verdict_of(details, str(joint))
        ok = bool(table.loc[joint, "ok"])
        parts = {}
        motor = report.envelopes.get(joint)
        if joint in report.motors:
            parts["motor"] = (getattr(motor, "name", "") or "unnamed motor") if motor else "none"
            ratio = table.loc[joint, "gear_ratio"] if "gear_ratio" in table.columns else np.nan
            if np.isfinite(ratio):
                parts["gearbox"] = f"N = {ratio:g}"
        for kind in ("gearbox", "drive"):  # part names, when the table has them
            if kind in table.columns and isinstance(table.loc[joint, kind], str):
                parts[kind] = table.loc[joint, kind]
        unchecked = str(table.loc[joint, "unchecked"]) if "unchecked" in table.columns else ""
        note = ""
        if unchecked == "motor":
            note = "no motor data"
        elif unchecked and unchecked != "nan":
            note = f"not checked: {unchecked.replace(',', ', ')}"
        elif not binding:
            note = "nothing to check against: no joint limit and no part data"
        rows.append(VerdictRow(str(joint), parts, row_status(ok, least), binding, least, note))
    return rows


def report_verdict(report: _SizingReport) -> tuple[list[VerdictRow], Any]:
    """``(rows, details)`` of a :class:`SizingReport`: its verdict rows and the long table of
    its checks (see the module notes); no figure is drawn."""
    joints = [str(j) for j in report.table.index]
    details = check_details(joints, _check_columns(report), JOINT_CHECKS + CHECKS)
    return _verdict_rows(report, details), details


def report_model(report: _SizingReport, sweep: Any = None) -> ReportModel:
    """The page's :class:`~armdyn.sizing.html.ReportModel` of a :class:`SizingReport` (see the
    module notes); ``sweep``: a :class:`~armdyn.sizing.selection.GearRatioSweep` shown in its
    own section."""
    rows, details = report_verdict(report)
    sections = [
        _torque_section(report),
        _thermal_section(report),
        _envelope_section(report),
        sweep_section(sweep),
        Section("All values", tables=[("the sizing table", report.table)]),
    ]
    span = f"{report.t[0]:.6g} s to {report.t[-1]:.6g} s, {len(report.t)} samples"
    return ReportModel(
        "Sizing report",
        rows,
        details,
        sections,
        subtitle=f"run from {span}",
    )


def _torque_section(report: _SizingReport) -> Section:
    from armdyn.plotting import sizing_torque_figure

    figures = []
    for k, name in enumerate(report.table.index):
        tau = report.torque[:, k]
        if np.all(np.isnan(tau) | (tau == 0.0)):  # no actuation on this joint
            continue
        png = figure_png(sizing_torque_figure(report, name))
        figures.append(
            ReportFigure(f"torque of {name}", png, f"torque of {name}", f"torque_{k}.png")
        )
    text = "" if figures else "no joint has a non-zero torque in the run"
    return Section("Torque histories", text=text, figures=figures)


def _cycle_thermal_section(report: _SizingReport) -> Section:
    """The winding (solid) and housing (dashed) temperatures of each motor over the period of
    the repeated cycle's peak (``report.thermal``), with its maximum winding temperature."""
    from armdyn.plotting import _matplotlib_figure

    fig = _matplotlib_figure()(figsize=(7.5, 3.2))
    ax = fig.subplots()
    for k, (joint, (t, winding, housing)) in enumerate(report.thermal.items()):
        ax.plot(t, winding, lw=1.0, color=f"C{k}", label=f"{joint} winding")
        if np.any(np.isfinite(housing)):  # a one-node model has no housing node
            ax.plot(t, housing, lw=0.8, ls="--", color=f"C{k}", label=f"{joint} housing")
        limit = _motor_attr(report.envelopes.get(joint), "max_winding_temperature")
        if np.isfinite(limit):
            ax.axhline(limit, lw=0.8, ls=":", color=f"C{k}", label=f"{joint} max winding")
    return _thermal_figure(
        fig,
        ("t [s] (the period of the peak)", "temperature [°C]"),
        "motor temperatures over the repeated cycle",
        "winding and housing temperature over one period of the repeated cycle per motor",
    )


def _thermal_figure(fig, labels: tuple[str, str], title: str, alt: str) -> Section:
    """The thermal section of a figure whose one axes is drawn: labels, title, legend, grid."""
    ax = fig.axes[0]
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_title(title)
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    ax.grid(lw=0.3)
    fig.tight_layout()
    return Section("Thermal histories", figures=[ReportFigure(alt, figure_png(fig), alt)])


def _thermal_section(report: _SizingReport) -> Section:
    from armdyn.plotting import _matplotlib_figure
    from armdyn.sizing.thermal import thermal_rise

    if getattr(report, "thermal", None):
        return _cycle_thermal_section(report)

    curves = []
    for joint, side in report.motors.items():
        motor = report.envelopes.get(joint)
        r_th, tau_th = (
            _motor_attr(motor, a) for a in ("thermal_resistance", "thermal_time_constant")
        )
        if side.copper_included and np.isfinite(r_th) and np.isfinite(tau_th) and tau_th > 0:
            curves.append((joint, thermal_rise(side.t, side.loss_copper, r_th, tau_th)))
    if not curves:
        return Section(
            "Thermal histories",
            text="not available: no motor gives thermal_resistance, thermal_time_constant, "
            "torque_constant and resistance",
        )
    fig = _matplotlib_figure()(figsize=(7.5, 3.2))
    ax = fig.subplots()
    for joint, rise in curves:
        ax.plot(report.t, rise, lw=1.0, label=str(joint))
    return _thermal_figure(
        fig,
        ("t [s]", "winding temperature rise [K]"),
        "winding temperature rise from the start of the run (first-order model)",
        "winding temperature rise against time per motor",
    )


def _envelope_section(report: _SizingReport) -> Section:
    from armdyn.plotting import sizing_envelope_figure

    figures = []
    for k, name in enumerate(report.table.index):
        if name in report.motors:
            png = figure_png(sizing_envelope_figure(report, name))
            alt = f"speed-torque plane of the motor of {name}"
            figures.append(ReportFigure(alt, png, alt, f"motor_{k}.png"))
    text = "" if figures else "no joint has a motor (pass actuators= to sizing_report)"
    return Section("Operating points on the motor envelopes", text=text, figures=figures)


def sweep_section(sweep: Any) -> Section:
    """The gear-ratio sweep's section: per joint the RMS motor torque against the swept ratio
    (ratios where every check passes marked, the best ratio circled) and the sweep's summary
    table; a note when no sweep was given."""
    title = "Gear-ratio sweep"
    if sweep is None:
        return Section(title, text="not run (pass sweep=armdyn.gear_ratio_sweep(...) to save)")
    from armdyn.plotting import _matplotlib_figure

    table, summary = sweep.table, sweep.summary
    joints = list(summary.index)
    fig = _matplotlib_figure()(figsize=(7.5, 2.4 * len(joints) + 0.6), layout="constrained")
    axes = fig.subplots(len(joints), 1, squeeze=False)[:, 0]
    for ax, joint in zip(axes, joints, strict=True):
        rows = table.xs(joint, level=0)
        ratio = rows.index.to_numpy(dtype=float)
        rms = rows["motor_rms_torque"].to_numpy(dtype=float)
        ok = rows["ok"].to_numpy(dtype=bool)
        ax.plot(ratio, rms, "-", color="0.6", lw=0.8)
        ax.plot(ratio[ok], rms[ok], "o", color="#1b7f3b", ms=4, label="every check passes")
        ax.plot(ratio[~ok], rms[~ok], "x", color="#c62828", ms=5, label="some check fails")
        best = summary.loc[joint, "best_ratio"]
        if np.isfinite(best):
            ax.plot(
                [best],
                [summary.loc[joint, "best_rms_torque"]],
                "o",
                mfc="none",
                mec="k",
                ms=10,
                label="least RMS torque",
            )
        ax.set_xscale("log")
        ax.set_ylabel("RMS motor\ntorque [N m]")
        ax.set_title(str(joint), fontsize="medium")
        ax.grid(lw=0.3, which="both")
    axes[-1].set_xlabel("gear ratio N")
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    alt = "RMS motor torque against the gear ratio per joint"
    return Section(
        title,
        figures=[ReportFigure(alt, figure_png(fig), alt, "sweep.png")],
        tables=[("summary per joint", summary)],
    )


# ------------------------------------------------------------------------ a selection's page

#: how many ranked candidates per joint the selection's page lists
RANKED_ROWS = 10


def selection_series(selection: Any, catalog: Any) -> dict[str, tuple[Any, float, dict]]:
    """``{joint: (motor, gear ratio, series)}`` of each chosen drivetrain: its
    :class:`armdyn.Motor` (``catalog.motor``), its gearbox's ratio and
    :func:`armdyn.sizing.motor.motor_cycle_series` on the selection's duty cycle
    (``selection.cycle.joint_load``) with the gearbox's efficiency and the rotor inertia plus
    the gearbox's input inertia (the selection's motor side), at ``selection.options``."""
    from armdyn.sizing.motor import motor_cycle_series

    out = {}
    for joint, row in selection.table.iterrows():
        motor, gearbox = catalog.motor(row["motor"]), catalog.gearbox(row["gearbox"])
        inertia = (motor.rotor_inertia or 0.0) + (gearbox.input_inertia or 0.0)
        series = motor_cycle_series(
            selection.cycle.joint_load(str(joint)),
            gearbox.ratio,
            gearbox.efficiency,
            inertia,
            motor,
            selection.options,
        )
        out[str(joint)] = (motor, float(gearbox.ratio), series)
    return out


def _selection_motor_sections(selection: Any, catalog: Any) -> list[Section]:
    """The chosen motors' temperatures over the cycle and their operating points on their
    speed-torque planes (:func:`selection_series`)."""
    from types import SimpleNamespace

    import pandas as pd

    from armdyn.plotting import sizing_envelope_figure
    from armdyn.sizing.motor import motor_envelope

    chosen = selection_series(selection, catalog)
    thermal = SimpleNamespace(
        thermal={
            j: (s["t"], s["winding_temperature"], s["housing_temperature"])
            for j, (_, _, s) in chosen.items()
            if np.any(np.isfinite(s["winding_temperature"]))
        },
        envelopes={j: m for j, (m, _, _) in chosen.items()},
    )
    sections = [
        _cycle_thermal_section(thermal)
        if thermal.thermal
        else Section("Thermal histories", text="no chosen motor has a thermal model")
    ]
    figures = []
    for k, (joint, (motor, ratio, s)) in enumerate(chosen.items()):
        one = SimpleNamespace(
            motors={joint: SimpleNamespace(speed=s["speed"], torque=s["torque"])},
            envelopes={joint: motor},
            table=pd.DataFrame({"gear_ratio": [ratio]}, index=[joint]),
            _motor_envelope=lambda _j, m=motor: motor_envelope(m),
        )
        alt = f"speed-torque plane of the motor of {joint}"
        png = figure_png(sizing_envelope_figure(one, joint))
        figures.append(ReportFigure(alt, png, alt, f"motor_{k}.png"))
    sections.append(Section("Operating points on the motor envelopes", figures=figures))
    return sections


def selection_report_model(selection: Any, catalog: Any = None) -> ReportModel:
    """The page's model of a drivetrain selection (:func:`armdyn.select_drivetrain`): its
    ``.table`` indexed by joint (``motor, gearbox, drive, ok, binding_check, margin`` and the
    value, allowable and ``<check>_margin`` columns of :data:`armdyn.sizing.checks.CHECKS` it
    has) gives the verdict and the checks; ``.infeasible`` (a joint with no feasible
    candidate: which check none passes and the best margin reached) the rows' notes and a
    section; ``.candidates(joint)`` (ranked, best first) the ranking tables and the plot of each
    candidate's objective (its ``objective`` column) against its least margin (``margin``);
    ``.bus`` (the chosen set's DC bus) a table; ``.converged`` False is said in the subtitle.
    With the ``catalog`` the selection was made from, the chosen motors' temperatures and
    operating points over the cycle are drawn too (:func:`selection_series`)."""
    table = selection.table
    joints = [str(j) for j in table.index]
    values = {c: table[c].to_numpy() for c in table.columns if _is_number_column(table[c])}
    # the table gives values and margins, the catalog's allowables follow from them
    details = check_details(joints, values, CHECKS, derive_allowable=True)
    infeasible = getattr(selection, "infeasible", None)
    rows = []
    for joint in table.index:
        parts = {
            k: str(table.loc[joint, k])
            for k in ("motor", "gearbox", "drive")
            if k in table.columns and isinstance(table.loc[joint, k], str)
        }
        margin = float(table.loc[joint, "margin"])
        ok = bool(table.loc[joint, "ok"])
        status = "fail" if not ok or margin < 1.0 else "pass"
        note = ""
        if infeasible is not None and len(infeasible):
            reasons = infeasible[infeasible["joint"] == joint]
            if len(reasons):
                note = "no feasible candidate: closest shown; " + "; ".join(
                    f"{r.check} best margin {r.best_margin:.3g}" for r in reasons.itertuples()
                )
        binding = str(table.loc[joint, "binding_check"] or "")
        rows.append(VerdictRow(str(joint), parts, status, binding, margin, note))
    objective = str(getattr(selection, "objective", "") or "")
    passes = getattr(selection, "passes", None)
    sub = f"objective: {objective}" + (f"; {passes} coupled pass(es)" if passes else "")
    if getattr(selection, "converged", True) is False:
        sub += "; NOT CONVERGED (the choice still changed in the last pass)"
    sections = [_ranking_section(selection, joints, objective)]
    cycle = getattr(selection, "cycle", None)
    if cycle is not None:
        sections.append(cycle_torque_section(cycle, joints))
        if catalog is not None:
            sections.extend(_selection_motor_sections(selection, catalog))
    if infeasible is not None and len(infeasible):
        sections.append(
            Section("Where nothing fits", tables=[("checks no candidate passes", infeasible)])
        )
    bus = getattr(selection, "bus", None)
    if bus:
        import pandas as pd

        scalars = {k: v for k, v in bus.items() if np.ndim(v) == 0}
        frame = pd.DataFrame({"value": list(scalars.values())}, index=list(scalars))
        sections.append(Section("DC bus of the chosen set", tables=[("bus values", frame)]))
    sections.append(Section("All values", tables=[("the selection table", table)]))
    return ReportModel("Drivetrain selection", rows, details, sections, subtitle=sub)


def cycle_torque_section(cycle: Any, joints: list[str]) -> Section:
    """The load torques of a duty cycle (``cycle.t``, ``cycle.names``, ``cycle.torque`` and
    ``cycle.gravity_torque``, issue 33's DutyCycle) at the selected joints: one panel per joint,
    the torque against time over one period and the holding (gravity) torque at each pose, the
    dwell shaded (``cycle.moving`` False)."""
    if not any(j in list(cycle.names) for j in joints):
        return Section("Torque histories", text="the cycle has none of the selected joints")
    alt = "load torque of each selected joint over one period of the cycle"
    png = figure_png(cycle_torque_figure(cycle, joints))
    return Section("Torque histories", figures=[ReportFigure(alt, png, alt, "torque.png")])


def cycle_torque_figure(cycle: Any, joints: list[str]):
    """The figure of :func:`cycle_torque_section` (a bare matplotlib Figure)."""
    from armdyn.plotting import _matplotlib_figure

    names = list(cycle.names)
    shown = [j for j in joints if j in names]
    t = np.asarray(cycle.t, dtype=float)
    moving = np.asarray(getattr(cycle, "moving", np.ones(len(t), bool)), dtype=bool)
    fig = _matplotlib_figure()(figsize=(7.5, 2.0 * len(shown) + 0.6), layout="constrained")
    axes = fig.subplots(len(shown), 1, squeeze=False, sharex=True)[:, 0]
    for ax, joint in zip(axes, shown, strict=True):
        k = names.index(joint)
        ax.plot(t, np.asarray(cycle.torque)[:, k], lw=1.0, label="load torque")
        ax.plot(t, np.asarray(cycle.gravity_torque)[:, k], lw=0.8, ls="--", label="holding")
        if not moving.all():
            ax.axvspan(t[~moving].min(), t[~moving].max(), color="0.9", label="dwell")
        ax.set_ylabel(f"{joint}\n[N m]")
        ax.grid(lw=0.3)
    axes[-1].set_xlabel("t [s] (one period)")
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    return fig


def _is_number_column(column) -> bool:
    return column.dtype.kind in "fiub"


def _ranking_section(selection: Any, joints: list[str], objective: str) -> Section:
    """Per joint the ranked candidates (the first :data:`RANKED_ROWS`) and one figure: each
    candidate's objective against its least margin, the chosen one ringed, margin 1 dashed."""
    from armdyn.plotting import _matplotlib_figure

    ranked = {j: selection.candidates(j) for j in joints}
    fig = _matplotlib_figure()(figsize=(7.5, 2.4 * len(joints) + 0.6), layout="constrained")
    axes = fig.subplots(len(joints), 1, squeeze=False)[:, 0]
    for ax, joint in zip(axes, joints, strict=True):
        cand = ranked[joint]
        column = "objective" if "objective" in cand.columns else objective
        if column not in cand.columns or "margin" not in cand.columns or cand.empty:
            ax.set_title(f"{joint}: no candidate values", fontsize="medium")
            continue
        y = cand[column].to_numpy(dtype=float)
        # the log axis shows margins from 1e-3 to 1e3 (an infinite margin: a zero load)
        m = np.clip(cand["margin"].to_numpy(dtype=float), 1e-3, 1e3)
        ok = m >= 1.0
        ax.plot(m[ok], y[ok], "o", color="#1b7f3b", ms=3, label="passes")
        ax.plot(m[~ok], y[~ok], "x", color="#c62828", ms=4, label="fails")
        ax.plot(m[:1], y[:1], "o", mfc="none", mec="k", ms=11, label="ranked first")
        ax.axvline(1.0, color="k", ls="--", lw=0.8)
        ax.set_xscale("log")
        ax.set_ylabel(OBJECTIVE_LABELS.get(objective, objective or column))
        ax.set_title(str(joint), fontsize="medium")
        ax.grid(lw=0.3, which="both")
    axes[-1].set_xlabel("least margin (log; >= 1 passes)")
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    alt = f"{objective or 'objective'} against the least margin of every candidate per joint"
    tables = [
        (f"{j}: the first {RANKED_ROWS} candidates", _ranking_columns(ranked[j])) for j in joints
    ]

    return Section(
        "Ranking",
        figures=[ReportFigure(alt, figure_png(fig), alt, "ranking.png")],
        tables=tables,
    )


#: the columns of the ranking tables (those a candidates frame has)
RANKING_COLUMNS = ("motor", "gearbox", "drive", "ok", "binding_check", "margin", "objective")


def _ranking_columns(cand):
    """The first :data:`RANKED_ROWS` candidates, the :data:`RANKING_COLUMNS` they have plus
    ``mass`` and ``cost`` when given."""
    keep = [c for c in (*RANKING_COLUMNS, "mass", "cost") if c in cand.columns]
    return cand.head(RANKED_ROWS)[keep]


def write_selection_report(
    selection: Any, directory: str | os.PathLike[str], catalog: Any = None
) -> Path:
    """Write ``selection.csv`` (its table), the ranking figure and ``report.html`` (one
    self-contained page, :func:`selection_report_model`) into ``directory``; returns the
    page's path."""
    out = Path(os.fspath(directory))
    out.mkdir(parents=True, exist_ok=True)
    selection.table.to_csv(out / "selection.csv")
    model = selection_report_model(selection, catalog)
    for section in model.sections:
        for f in section.figures:
            if f.file:
                (out / f.file).write_bytes(f.png)
    page = out / "report.html"
    page.write_text(render_page(model), encoding="utf-8")
    return page
