"""Figures of runs, work-precision sweeps and sizing reports, on matplotlib.

matplotlib is imported when a figure is drawn, never by ``import armdyn``. The figures are bare
:class:`matplotlib.figure.Figure` objects (no pyplot state: nothing opens a window, the user's
backend is left alone, it works headless); given an ``ax``, a function draws into it instead.

- :func:`plot_result` (``SimulationResult.plot``): joint angles, rates, accelerations, torques,
  drive efforts, joint-stop and gear forces, joint reactions, energy and constraint residuals
  against time.
- :func:`work_precision_figure` (``WorkPrecisionResult.plot``): error against CPU time.
- :func:`sizing_torque_figure` and :func:`sizing_envelope_figure` (``SizingReport.plot``,
  ``SizingReport.save``, ``SizingReport.envelope_figure``): a joint's torque against time and its
  motor's operating points on the speed-torque plane.
"""

from __future__ import annotations

import os
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from armdyn import _core

if TYPE_CHECKING:  # matplotlib is imported when a figure is drawn
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

# the results drawn (armdyn.simulation.SimulationResult, armdyn.sizing.SizingReport,
# armdyn.workprecision.WorkPrecisionResult) are not imported: those modules import this one
_SimulationResult: TypeAlias = Any
_SizingReport: TypeAlias = Any
_WorkPrecisionResult: TypeAlias = Any

#: a path to save a figure to
_PathLike: TypeAlias = str | os.PathLike[str]

#: The kinds :func:`plot_result` draws, one panel each (``"reaction"`` and ``"residual"`` are
#: two panels: force and torque, position and velocity).
KINDS = (
    "q",
    "qd",
    "qdd",
    "torque",
    "drive",
    "limit",
    "gear",
    "reaction",
    "reaction_force",
    "reaction_torque",
    "energy",
    "residual",
    "position_residual",
    "velocity_residual",
)
_PANELS = {"reaction": ("reaction_force", "reaction_torque")}
_PANELS["residual"] = ("position_residual", "velocity_residual")

# the unit of a joint-space column by (quantity, column kind); column kinds: "angular" (a
# revolute or cylindrical angle, a floating base's angular velocity), "linear" (a prismatic or
# cylindrical displacement, a floating base's position and linear velocity), "quaternion" (a
# floating base's Euler parameters) and None (unknown without the model)
_UNITS = {
    "q": {"angular": "rad", "linear": "m", "quaternion": "-", None: "rad or m"},
    "qd": {"angular": "rad/s", "linear": "m/s", None: "rad/s or m/s"},
    "qdd": {"angular": "rad/s²", "linear": "m/s²", None: "rad/s² or m/s²"},
    "effort": {"angular": "N m", "linear": "N", None: "N m or N"},
}
_TITLES = {
    "q": "joint coordinates q",
    "qd": "joint rates qd",
    "qdd": "joint accelerations qdd",
    "torque": "applied joint torques/forces",
    "drive": "drive efforts",
    "limit": "joint-stop torques/forces (×: the stops' events, impacts and releases)",
    "gear": "gear mesh forces",
    "reaction_force": "joint reaction forces (child's joint frame)",
    "reaction_torque": "joint reaction torques (child's joint frame)",
    "energy": "energy",
    "position_residual": "position constraint residual max |f|",
    "velocity_residual": "velocity constraint residual max |ζ v − rhs|",
}


def _matplotlib_figure() -> type[Figure]:
    """``matplotlib.figure.Figure``, or an ImportError saying how to install matplotlib."""
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "armdyn's figures need matplotlib: pip install matplotlib (or the 'plot' extra, "
            "pip install 'armdyn[plot]')"
        ) from exc
    return Figure


def _figure_and_axes(ax: Axes | None, figsize: tuple[float, float]) -> tuple[Any, Any]:
    """(figure, axes) to draw one panel in: a new Figure of ``figsize`` [in] with one Axes, or
    the given ``ax`` and its figure."""
    if ax is None:
        fig = _matplotlib_figure()(figsize=figsize)
        return fig, fig.add_subplot()
    return ax.figure, ax


@dataclass
class _Panel:
    """One axes' worth: the lines (label, y), their joints (for selection), the y label."""

    kind: str
    labels: list
    joints: list  # per line: the joint (or gear) name it belongs to, None without a model
    columns: list  # per line: its column index in the panel's array (for integer selection)
    ys: list
    ylabel: str
    log: bool = False


def _joint_columns(model):
    """Per column of ``result.q`` and of ``result.qd``: (joint name, column kind), following
    the model's joint-space layout (the floating bases' blocks first, then every joint
    coordinate in joint order), or None when the model has a joint type this does not know."""
    names, types = list(model.joint_names), [str(t) for t in model.joint_types]
    q_cols, v_cols = [], []
    for name, jt in zip(names, types, strict=True):
        if jt == "free":
            q_cols += [(name, "linear")] * 3 + [(name, "quaternion")] * 4
            v_cols += [(name, "linear")] * 3 + [(name, "angular")] * 3
    per_type = {"revolute": ("angular",), "prismatic": ("linear",)}
    per_type["cylindrical"] = ("angular", "linear")
    for name, jt in zip(names, types, strict=True):
        for kind in per_type.get(jt, ()):
            q_cols.append((name, kind))
            v_cols.append((name, kind))
    if len(q_cols) != model.n_joint_coords or len(v_cols) != model.n_joint_dofs:
        return None
    return q_cols, v_cols


def _check_shape(result, name: str, n_cols: int, what: str, model) -> np.ndarray:
    a = np.asarray(getattr(result, name), dtype=float)
    if a.ndim < 2 or a.shape[0] != len(result.t) or a.shape[1] != n_cols:
        raise _core.ModelError(
            f"result.plot: result.{name} has shape {a.shape} but the model has {n_cols} {what}: "
            "the result is not from this model (pass the model the run was made with)"
        )
    return a


def _unit_label(quantity: str, kinds: list) -> tuple[str, bool]:
    """The y-axis unit of the lines' column kinds, and whether each line needs its own."""
    units = [_UNITS[quantity].get(k, _UNITS[quantity][None]) for k in kinds]
    distinct = list(dict.fromkeys(units))
    return ", ".join(distinct), len(distinct) > 1


def _column_panel(kind, quantity, y, names, joints, kinds, symbol):
    unit, mixed = _unit_label(quantity, kinds)
    labels = [
        f"{n} [{_UNITS[quantity].get(k, _UNITS[quantity][None])}]" if mixed else n
        for n, k in zip(names, kinds, strict=True)
    ]
    ys = [y[:, k] for k in range(y.shape[1])]
    return _Panel(kind, labels, joints, list(range(y.shape[1])), ys, f"{symbol} [{unit}]")


def _panel(result, kind: str, model) -> _Panel:
    """The lines of one panel (every column; selection comes after)."""
    layout = _joint_columns(model) if model is not None else None
    if kind in ("q", "qd", "qdd", "torque"):
        return _coordinate_panel(result, kind, model, layout)
    if kind == "drive":
        return _drive_panel(result, model, layout)
    if kind in ("limit", "gear"):
        return _stop_or_gear_panel(result, kind, layout)
    if kind in ("reaction_force", "reaction_torque"):
        return _reaction_panel(result, kind, model)
    if kind == "energy":
        ke = np.asarray(result.kinetic_energy, dtype=float)
        pe = np.asarray(result.potential_energy, dtype=float)
        ys = [ke, pe, np.asarray(result.total_energy, dtype=float)]
        labels = ["kinetic", "potential (gravity, springs)", "total"]
        return _Panel(kind, labels, [None] * 3, [0, 1, 2], ys, "energy [J]")
    if kind in ("position_residual", "velocity_residual"):
        y = np.asarray(getattr(result, kind), dtype=float)
        unit = "m or rad" if kind == "position_residual" else "m/s or rad/s"
        label = "max |f|" if kind == "position_residual" else "max |ζ v − rhs|"
        log = bool(np.any(y > 0))
        return _Panel(kind, [label], [None], [0], [y], f"residual [{unit}]", log=log)
    raise AssertionError(kind)  # pragma: no cover - kinds are checked before


def _coordinate_panel(result, kind: str, model, layout) -> _Panel:
    """``q``, ``qd``, ``qdd`` or ``torque`` (``result.joint_torques``): one line per
    joint-space column, named by the model (``q[k]`` ... without it)."""
    field = "joint_torques" if kind == "torque" else kind
    if model is not None:
        cols = model.joint_coord_names if kind == "q" else model.joint_dof_names
        what = "joint coordinates" if kind == "q" else "joint dofs"
        y = _check_shape(result, field, len(cols), what, model)
        names = list(cols)
        if layout is not None:
            per = layout[0] if kind == "q" else layout[1]
            joints, kinds = [j for j, _ in per], [k for _, k in per]
        else:
            joints, kinds = names, [None] * len(names)
    else:
        y = np.asarray(getattr(result, field), dtype=float)
        names = [f"{kind}[{k}]" for k in range(y.shape[1])]
        joints, kinds = [None] * len(names), [None] * len(names)
    quantity = "effort" if kind == "torque" else kind
    symbol = {"torque": "τ"}.get(kind, kind)
    return _column_panel(kind, quantity, y, names, joints, kinds, symbol)


def _drive_panel(result, model, layout) -> _Panel:
    """One line per drive (``result.drive_forces``), belonging to its driven joint."""
    y = np.asarray(result.drive_forces, dtype=float)
    if y.ndim != 2 or y.shape[1] == 0:
        raise _core.ModelError(
            "result.plot('drive'): the run has no drives (result.drive_forces has no "
            "columns): add_drive on the model prescribes a motion and records its effort; "
            "the applied torques of torque inputs and motors are kind 'torque'"
        )
    if model is None:
        names = [f"drive[{k}]" for k in range(y.shape[1])]
        joints, kinds = [None] * len(names), [None] * len(names)
        return _column_panel("drive", "effort", y, names, joints, kinds, "effort")
    names = list(model.drive_names)
    y = _check_shape(result, "drive_forces", len(names), "drives", model)
    dof_kinds = layout[1] if layout is not None else None
    kinds = [
        dof_kinds[c][1] if dof_kinds is not None and 0 <= c < len(dof_kinds) else None
        for c in model.drive_coords
    ]
    dof_joints = list(model.joint_dof_names)
    joints = [
        (dof_kinds[c][0] if dof_kinds is not None else dof_joints[c])
        if 0 <= c < len(dof_joints)
        else None
        for c in model.drive_coords
    ]
    joints = [j if j is not None else n for j, n in zip(joints, names, strict=True)]
    return _column_panel("drive", "effort", y, names, joints, kinds, "effort")


def _stop_or_gear_panel(result, kind: str, layout) -> _Panel:
    """``limit``: one line per joint with a stop (``result.limit_forces``); ``gear``: one per
    gear pair (``result.gear_forces``)."""
    store = result.limit_forces if kind == "limit" else result.gear_forces
    names = list(store.get("names", []))
    if not names:
        if kind == "limit":
            raise _core.ModelError(
                "result.plot('limit'): the run recorded no joint-stop forces "
                "(result.limit_forces is empty): they are recorded for the joints with a "
                "finite position limit (set_joint_limits, the URDF <limit>) when the run "
                "enforces them, simulate(..., limits='enforce') (the default)"
            )
        raise _core.ModelError(
            "result.plot('gear'): the run has no gears (result.gear_forces is empty): "
            "gear mesh forces are recorded for the model's gear pairs and ideal gears"
        )
    y = np.asarray(store["force"], dtype=float)
    if kind == "gear":
        return _Panel(kind, names, names, list(range(len(names))), list(y.T), "mesh force [N]")
    kinds = [None] * len(names)
    if layout is not None:
        by_joint = {j: k for j, k in layout[1]}
        kinds = [by_joint.get(n) for n in names]
    return _column_panel(kind, "effort", y, names, names, kinds, "stop effort")


def _reaction_panel(result, kind: str, model) -> _Panel:
    """``reaction_force`` / ``reaction_torque``: three lines (x, y, z) per joint."""
    field = "reaction_forces" if kind == "reaction_force" else "reaction_torques"
    if model is not None:
        jnames = list(model.joint_names)
        y = _check_shape(result, field, len(jnames), "joints", model)
    else:
        y = np.asarray(getattr(result, field), dtype=float)
        jnames = [f"joint[{k}]" for k in range(y.shape[1])]
    sym = "F" if kind == "reaction_force" else "M"
    labels, joints, columns, ys = [], [], [], []
    for k, name in enumerate(jnames):
        for c, axis in enumerate("xyz"):
            labels.append(f"{name} {sym}{axis}")
            joints.append(name if model is not None else None)
            columns.append(k)
            ys.append(y[:, k, c])
    unit = "N" if kind == "reaction_force" else "N m"
    return _Panel(kind, labels, joints, columns, ys, f"{sym} [{unit}]")


def _kinds(kind) -> list[str]:
    """The panels of ``kind`` (a kind or a list of kinds), or a ValueError naming a bad one."""
    asked = [kind] if isinstance(kind, str) else list(kind) if kind is not None else []
    if not asked:
        raise ValueError(f"result.plot: no kind given; the kinds are {', '.join(KINDS)}")
    panels = []
    for k in asked:
        if not isinstance(k, str) or k not in KINDS:
            raise ValueError(f"result.plot: unknown kind {k!r}; the kinds are {', '.join(KINDS)}")
        for p in _PANELS.get(k, (k,)):
            if p not in panels:
                panels.append(p)
    return panels


# the kinds whose lines belong to joints (or gears): the ones ``joints`` selects in
_PER_JOINT = (
    *("q", "qd", "qdd", "torque", "drive", "limit", "gear"),
    *("reaction_force", "reaction_torque"),
)


def _select(panel: _Panel, joints, model) -> _Panel:
    """The lines of ``panel`` for ``joints`` (names or column indices, in the order given)."""
    if joints is None or panel.kind not in _PER_JOINT:
        return panel
    keep: list[int] = []
    for sel in joints:
        if isinstance(sel, (int, np.integer)) and not isinstance(sel, bool):
            hit = _lines_of_column(panel, sel)
        elif isinstance(sel, str):
            hit = _lines_of_name(panel, sel, model)
        else:
            raise TypeError(
                f"result.plot: joints must be names (str) or column indices (int), got {sel!r}"
            )
        keep += [i for i in hit if i not in keep]
    return _Panel(
        panel.kind,
        [panel.labels[i] for i in keep],
        [panel.joints[i] for i in keep],
        [panel.columns[i] for i in keep],
        [panel.ys[i] for i in keep],
        panel.ylabel,
        panel.log,
    )


def _what(panel: _Panel) -> str:
    return "gear" if panel.kind == "gear" else "joint"


def _lines_of_column(panel: _Panel, sel) -> list[int]:
    """The lines of column index ``sel`` (negative from the end), or a ModelError."""
    n_cols = max(panel.columns) + 1 if panel.columns else 0
    if not -n_cols <= sel < n_cols:
        raise _core.ModelError(
            f"result.plot({panel.kind!r}): {_what(panel)} index {sel} out of range: the panel "
            f"has {n_cols} columns"
        )
    col = int(sel) % n_cols
    return [i for i, c in enumerate(panel.columns) if c == col]


def _lines_of_name(panel: _Panel, sel: str, model) -> list[int]:
    """The lines of joint (or gear) ``sel``, or of the line labelled so; a ModelError naming
    what the panel or the model has when there is none."""
    what = _what(panel)
    if panel.kind != "gear" and model is None and panel.kind != "limit":
        raise _core.ModelError(
            f"result.plot: selecting joint {sel!r} by name needs the model the run was "
            "made with: result.plot(..., model=model) (or select by column index)"
        )
    hit = [
        i
        for i, (j, lab) in enumerate(zip(panel.joints, panel.labels, strict=True))
        if sel == j or sel == lab.split(" [")[0]
    ]
    if hit:
        return hit
    if panel.kind == "gear" or (model is not None and sel in _known_names(model)):
        present = list(dict.fromkeys(j for j in panel.joints if j is not None))
        raise _core.ModelError(
            f"result.plot({panel.kind!r}): {what} {sel!r} has no line in this "
            f"panel; its {what}s are {present}"
        )
    raise _core.ModelError(
        f"result.plot: unknown joint {sel!r}; the model's joints are "
        f"{list(model.joint_names) if model is not None else []}"
        + (
            f" and its joint-space columns {list(model.joint_coord_names)}"
            if model is not None
            else ""
        )
    )


def _known_names(model) -> set:
    if model is None:
        return set()
    return set(model.joint_names) | set(model.joint_coord_names) | set(model.joint_dof_names)


def _axes_list(ax, n: int):
    """The axes to draw into: ``ax`` (one Axes for one panel, or a sequence of n)."""
    if n == 1 and not isinstance(ax, (list, tuple, np.ndarray)):
        return [ax]
    axes = list(np.ravel(ax)) if isinstance(ax, np.ndarray) else list(ax)
    if len(axes) != n:
        raise ValueError(f"result.plot: {n} panels to draw but {len(axes)} axes given in ax")
    return axes


def plot_result(
    result: _SimulationResult,
    kind: str | Sequence[str] = "q",
    joints: str | int | Sequence[str | int] | None = None,
    *,
    model: _core.Model | None = None,
    ax: Axes | Sequence[Axes] | None = None,
    path: _PathLike | None = None,
    title: str | None = None,
    **line_kw: Any,
) -> Figure | Axes | list[Axes]:
    """Plot a run's outputs against time, one panel (axes) per kind. See
    :meth:`armdyn.SimulationResult.plot`."""
    panels = _kinds(kind)
    if len(result.t) == 0:
        why = f" (the run could not start: {result.error})" if result.error else ""
        raise ValueError(f"result.plot: the result has no output rows{why}")
    if joints is not None and (isinstance(joints, (str, int, np.integer))):
        joints = [joints]
    drawn = [_select(_panel(result, p, model), joints, model) for p in panels]
    t = np.asarray(result.t, dtype=float)
    if ax is None:
        figure = _matplotlib_figure()
        fig = figure(figsize=(8.0, 0.6 + 2.6 * len(drawn)), layout="constrained")
        axes = list(fig.subplots(len(drawn), 1, sharex=True, squeeze=False)[:, 0])
    else:
        axes = _axes_list(ax, len(drawn))
        fig = axes[0].figure
    for a, panel in zip(axes, drawn, strict=True):
        styles = {"total": dict(color="k", lw=1.4)} if panel.kind == "energy" else {}
        for label, y in zip(panel.labels, panel.ys, strict=True):
            a.plot(t, y, label=label, **{**styles.get(label, {}), **line_kw})
        if panel.kind == "limit":
            _stop_events(a, result, panel)
        if panel.log:
            a.set_yscale("log")
        a.set_ylabel(panel.ylabel)
        a.set_title(_TITLES[panel.kind], fontsize=9, loc="left")
        a.grid(True, lw=0.3, alpha=0.6, which="both" if panel.log else "major")
        if len(panel.labels) > 1 or panel.kind not in ("position_residual", "velocity_residual"):
            a.legend(
                fontsize="small",
                loc="upper left",
                bbox_to_anchor=(1.01, 1.0),
                borderaxespad=0.0,
                ncol=1 + len(panel.labels) // 13,
            )
    axes[-1].set_xlabel("t [s]")
    if ax is None:
        for a in axes[:-1]:
            a.tick_params(labelbottom=False)
    if title:
        if ax is None:
            fig.suptitle(title)
        else:
            axes[0].set_title(title, fontsize=10)
    if result.error:
        axes[0].text(
            0.0,
            1.12,
            textwrap.shorten(f"run stopped early: {result.error}", 110),
            transform=axes[0].transAxes,
            fontsize=8,
            color="C3",
        )
    if path is not None:
        fig.savefig(path, dpi=110)
    if ax is None:
        return fig
    return axes[0] if len(axes) == 1 and not isinstance(ax, (list, tuple, np.ndarray)) else axes


def _stop_events(ax: Axes, result: _SimulationResult, panel: _Panel) -> None:
    """The located stop events of the panel's joints (``result.events["limits"]``) as ×
    markers on the time axis, in the colour of the joint's line (the impacts are impulses,
    not in ``limit_forces``)."""
    events = result.events.get("limits", {}) if isinstance(result.events, dict) else {}
    t_ev, joint_ev = np.asarray(events.get("t", []), dtype=float), list(events.get("joint", []))
    lines = ax.get_lines()[-len(panel.labels) :] if panel.labels else []
    for line, joint in zip(lines, panel.joints, strict=True):
        at = t_ev[[j == joint for j in joint_ev]] if len(t_ev) else t_ev
        if len(at):
            ax.plot(at, np.zeros_like(at), "x", ms=6, color=line.get_color(), label="_events")


def work_precision_figure(
    wp: _WorkPrecisionResult,
    path: _PathLike | None = None,
    title: str | None = None,
    ax: Axes | None = None,
) -> Figure | Axes:
    """Log-log error against CPU seconds, one line per integrator (and formulation) in the
    sweep's order, the references' estimated error as a dotted vertical line. See
    :meth:`armdyn.WorkPrecisionResult.plot`."""
    fig, ax_ = _figure_and_axes(ax, (7.5, 4.8))
    tab: Any = wp.table  # a pandas DataFrame
    ok = tab[(tab["status"] == "ok") & np.isfinite(tab["error"]) & (tab["error"] > 0)]
    for (integ, coords), rows in ok.groupby(["integrator", "coordinates"], sort=False):
        label = integ if coords == "cartesian" else f"{integ} ({coords})"
        ax_.loglog(rows["error"], rows["cpu_s"], "-o", ms=4, label=label)
    floor = wp.floor()
    if np.isfinite(floor) and floor > 0:
        ax_.axvline(floor, color="grey", lw=0.8, ls=":", label="reference's estimated error")
    ax_.set_xlabel(textwrap.fill(f"error: {wp.error_measure}", 90), fontsize=9)
    ax_.set_ylabel("CPU time [s]")
    if title:
        ax_.set_title(title, fontsize=10)
    ax_.grid(True, which="both", alpha=0.3)
    ax_.legend(fontsize=8)
    if ax is None:
        fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig if ax is None else ax_


def _sizing_column(report, joint) -> int:
    names = list(report.table.index)
    if joint not in names:
        raise _core.ModelError(
            f"SizingReport.plot: unknown joint {joint!r}; the report's joints are {names}"
        )
    return names.index(joint)


def sizing_torque_figure(
    report: _SizingReport, joint: str, ax: Axes | None = None
) -> Figure | Axes:
    """``joint``'s torque/force against time with its effort limit (±, dashed) where finite:
    the figure of :meth:`armdyn.SizingReport.save`."""
    k = _sizing_column(report, joint)
    tau = report.torque[:, k]
    if np.all(np.isnan(tau)):
        raise _core.ModelError(
            f"SizingReport.plot: the run has no torque for {joint!r} (no drive, torque input "
            "or motor acts on it)"
        )
    fig, ax_ = _figure_and_axes(ax, (6.0, 3.0))
    ax_.plot(report.t, tau, lw=1.0, label="joint torque/force")
    limit = report.table["effort_limit"].iloc[k]
    if np.isfinite(limit):
        peak = float(np.nanmax(np.abs(tau)))
        # a limit far above the torque would flatten its curve: the axis spans the torque and
        # the legend gives the limit
        off_scale = 0.0 < peak and limit > 3.0 * peak
        label = f"effort limit ±{limit:g} (off scale)" if off_scale else "effort limit"
        ax_.axhline(limit, color="r", ls="--", lw=0.8, label=label)
        ax_.axhline(-limit, color="r", ls="--", lw=0.8)
        if off_scale:
            ax_.set_ylim(-1.3 * peak, 1.3 * peak)
    ax_.set_xlabel("t [s]")
    ax_.set_ylabel("torque [N m] or force [N]")
    ax_.set_title(str(joint))
    ax_.legend(loc="best", fontsize="small")
    if ax is None:
        fig.tight_layout()
    return fig if ax is None else ax_


def _num(value) -> float:
    return np.nan if value is None else float(value)


def sizing_envelope_figure(
    report: _SizingReport, joint: str, ax: Axes | None = None
) -> Figure | Axes:
    """The operating points (ω, T) of ``joint``'s motor over its continuous torque (±,
    dotted), peak torque (±, dashed), speed limit and speed–torque envelope
    (:func:`armdyn.sizing.motor_envelope`), where the datasheet gives them. Returns the
    Figure, or with ``ax`` that Axes."""
    if joint not in report.motors:
        _sizing_column(report, joint)  # an unknown joint
        raise _core.ModelError(
            f"SizingReport.plot: joint {joint!r} has no motor in the report (the joints with "
            f"one: {list(report.motors)}; pass actuators= to sizing_report)"
        )
    side, motor = report.motors[joint], report.envelopes.get(joint)
    fig = None
    if ax is None:
        fig = _matplotlib_figure()(figsize=(7.5, 4.0))
        ax = fig.subplots()
    ax.plot(side.speed, side.torque, ".", ms=2.0, color="C0", label="operating points")
    w_max = float(np.max(np.abs(side.speed))) or 1.0
    t0, w0 = report._motor_envelope(joint)  # armdyn.sizing.motor_envelope of its motor
    if np.isfinite(t0) and np.isfinite(w0) and t0 > 0 and w0 > 0:
        ws = np.array([-2.0 * w0, 0.0, 2.0 * w0])
        for sign in (1.0, -1.0):
            ax.plot(
                ws,
                sign * t0 - t0 * ws / w0,
                color="k",
                lw=1.0,
                label="envelope" if sign > 0 else None,
            )
        w_max = max(w_max, w0)
    for attr, style, label in (
        ("continuous_torque", ":", "continuous"),
        ("peak_torque", "--", "peak"),
    ):
        value = _num(getattr(motor, attr, None))
        if np.isfinite(value):
            ax.axhline(value, color="r", ls=style, lw=0.9, label=label)
            ax.axhline(-value, color="r", ls=style, lw=0.9)
    speed_lim = _num(getattr(motor, "max_speed", None))
    if np.isfinite(speed_lim):
        ax.axvline(speed_lim, color="g", ls="--", lw=0.9, label="max speed")
        ax.axvline(-speed_lim, color="g", ls="--", lw=0.9)
        w_max = max(w_max, speed_lim)
    ax.set_xlim(-1.1 * w_max, 1.1 * w_max)
    t_top = float(np.max(np.abs(side.torque))) or 1.0
    # the torque axis spans the operating points and the rated torques (the stall torque
    # of the envelope is often far above both)
    for v in (_num(getattr(motor, "peak_torque", None)),):
        if np.isfinite(v):
            t_top = max(t_top, v)
    ax.set_ylim(-1.3 * t_top, 1.3 * t_top)
    ax.set_xlabel("motor speed [rad/s]")
    ax.set_ylabel("motor torque [N m]")
    ax.set_title(
        f"{joint}: motor speed-torque plane (N = {report.table.loc[joint, 'gear_ratio']:g})"
    )
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    ax.grid(lw=0.3)
    if fig is None:
        return ax
    fig.tight_layout()
    return fig


def sizing_figure(
    report: _SizingReport,
    joint: str | None = None,
    kind: str = "torque",
    ax: Axes | Sequence[Axes] | None = None,
    path: _PathLike | None = None,
) -> Figure | Axes | list[Axes]:
    """``SizingReport.plot``: ``kind="torque"`` (the joint torque against time and its effort
    limit) or ``"motor"`` (the motor's speed–torque plane); ``joint=None``: one panel per
    joint with a torque (``"torque"``) or with a motor (``"motor"``)."""
    if kind not in ("torque", "motor"):
        raise ValueError(f"SizingReport.plot: unknown kind {kind!r}; the kinds are torque, motor")
    if joint is None:
        if kind == "motor":
            names = list(report.motors)
        else:
            names = [
                n
                for k, n in enumerate(report.table.index)
                if not np.all(np.isnan(report.torque[:, k]) | (report.torque[:, k] == 0.0))
            ]
        if not names:
            raise _core.ModelError(
                "SizingReport.plot: no joint "
                + ("has a motor (pass actuators= to sizing_report)" if kind == "motor" else "")
                + ("has a non-zero torque in the run" if kind == "torque" else "")
            )
    else:
        names = [joint]
    one = joint is not None
    fig: Any
    if ax is None and joint is not None:
        if kind == "torque":
            fig = sizing_torque_figure(report, joint)
        else:
            fig = sizing_envelope_figure(report, joint)
        if path is not None:
            fig.savefig(path, dpi=110)
        return fig
    if ax is None:
        fig = _matplotlib_figure()(
            figsize=(
                7.5 if kind == "motor" else 6.5,
                (4.0 if kind == "motor" else 3.0) * len(names),
            ),
            layout="constrained",
        )
        axes = list(fig.subplots(len(names), 1, squeeze=False)[:, 0])
    else:
        axes = _axes_list(ax, len(names))
        fig = axes[0].figure
    for a, name in zip(axes, names, strict=True):
        if kind == "torque":
            sizing_torque_figure(report, name, ax=a)
        else:
            sizing_envelope_figure(report, name, ax=a)
    if path is not None:
        fig.savefig(path, dpi=110)
    if ax is None:
        return fig
    return axes[0] if one and not isinstance(ax, (list, tuple, np.ndarray)) else axes
