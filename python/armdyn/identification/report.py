"""The identification report: one self-contained HTML page that opens with the verdict.

:func:`write_report` writes into a folder:

- ``report.html``: the page (the sizing report's style and helpers, :mod:`armdyn.sizing.html`:
  figures embedded as ``data:`` URIs, no script, nothing loaded from elsewhere);
- ``torques.png``: measured against predicted joint torques on the validation data, per joint,
  the identified model's and the nominal one's (when a validation is given);
- ``parameters.csv``: one row per entry of pi (:func:`armdyn.dynamic_parameter_names`):
  ``name, nominal, identified`` — what the identified model and URDF are made of;
- ``base_parameters.csv``: one row per base parameter: ``name, nominal, identified,
  least_squares, std, rel_std, poorly_identified``.

The page, in order:

1. **Verdict**, per joint, on the validation data (data the fit did not use): the identified
   model's RMSE and relative RMSE (to the measured torque's RMS), the unconstrained
   least-squares estimate's RMSE (when given), the nominal model's, and the
   status: ``MATCH`` when the relative RMSE is at most :data:`MATCH_REL_RMSE` (10 %);
   ``AT NOISE LEVEL`` when it is larger but the RMSE is at most :data:`NOISE_FACTOR` (1.2) times
   the fit's residual noise ``sigma`` of that joint (the model predicts the new data as well as
   it fits the old; the torques are small against the noise, or something unmodelled is in both);
   ``NO MATCH`` otherwise; ``NOT VALIDATED`` without validation data. The overall status is the
   worst joint's.
2. The torque figure.
3. The base parameters: nominal, identified, the least-squares estimate, its standard deviation
   and relative standard deviation (std / |identified|); a parameter whose relative standard
   deviation exceeds :data:`POOR_REL_STD` (10 %) is flagged "poorly identified" (the data do not
   resolve it: more excitation, or a parameter near zero).
4. The gap between the nominal and the identified model per body (mass, centre of mass, inertia
   about the centre of mass, and the smallest eigenvalue of the pseudo-inertia, negative when the
   body is not physically consistent) and per joint (``fv, fc, offset, Ia``). Only the base
   parameters are identified: the rest of pi is the completion closest to the nominal
   (``BaseParameters.complete``), so a body's gap shows where the data moved the model, not a
   measurement of that body alone.
5. The fit (method, solver, samples, outliers, the logs and how they were processed, fit RMSE
   and sigma per joint) and the validation's largest errors with their times.
"""

from __future__ import annotations

import html
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from armdyn import _core
from armdyn.identification.physical import pseudo_inertia
from armdyn.identification.validate import Validation
from armdyn.sizing.html import _CSS, ReportFigure, Section, _esc, _fmt, _section_block, figure_png

if TYPE_CHECKING:
    import pandas as pd

#: a joint matches when its validation RMSE is at most this fraction of the measured torque's RMS
MATCH_REL_RMSE = 0.10
#: ... or, above that, is "at the noise level" when its RMSE is at most this times the fit's sigma
NOISE_FACTOR = 1.2
#: a base parameter is poorly identified when its std exceeds this fraction of |identified|
POOR_REL_STD = 0.10
#: a body is physically consistent when its pseudo-inertia's smallest eigenvalue is at least
#: -PHYSICAL_TOL times its largest parameter's magnitude
PHYSICAL_TOL = 1e-9

#: status -> (the sizing page's CSS class, the word shown)
_STATUS = {
    "match": ("pass", "\u2714 MATCH"),
    "noise": ("unchecked", "\u2248 AT NOISE LEVEL"),
    "mismatch": ("fail", "\u2718 NO MATCH"),
    "unvalidated": ("unchecked", "? NOT VALIDATED"),
}
_ORDER = ("mismatch", "unvalidated", "noise", "match")
_BODY_FIELDS = ("m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
_JOINT_FIELDS = ("fv", "fc", "offset", "Ia")


def joint_status(validation: Validation | None, sigma) -> list[str]:
    """Each joint's status (see the module notes) from the identified model's validation and
    the fit's per-joint residual ``sigma``."""
    if validation is None:
        return ["unvalidated"] * len(np.atleast_1d(sigma))
    sigma = np.broadcast_to(np.asarray(sigma, dtype=float), validation.rmse.shape)
    out = []
    for rel, rmse, s in zip(validation.rel_rmse, validation.rmse, sigma, strict=True):
        if rel <= MATCH_REL_RMSE:
            out.append("match")
        elif np.isfinite(s) and rmse <= NOISE_FACTOR * s:
            out.append("noise")
        else:
            out.append("mismatch")
    return out


def overall_status(statuses: list[str]) -> str:
    """The worst of the joints' statuses (no joint: not validated)."""
    for s in _ORDER:
        if s in statuses:
            return s
    return "unvalidated"


# ------------------------------------------------------------------------------ the tables


def base_table(identification) -> pd.DataFrame:
    """Per base parameter: ``nominal, identified, least_squares, std, rel_std,
    poorly_identified`` (see the module notes), indexed by the base parameter's name."""
    import pandas as pd

    ident = identification
    nominal = np.asarray(ident.base.beta(_core.dynamic_parameters(ident.model)), dtype=float)
    beta = np.asarray(ident.beta, dtype=float)
    std = np.asarray(ident.beta_std, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(np.abs(beta) > 0, std / np.abs(beta), np.inf)
    rel = np.where(std == 0, 0.0, rel)
    return pd.DataFrame(
        {
            "nominal": nominal,
            "identified": beta,
            "least_squares": np.asarray(ident.beta_ls, dtype=float),
            "std": std,
            "rel_std": rel,
            "poorly_identified": rel > POOR_REL_STD,
        },
        index=pd.Index(list(ident.base.names), name="base parameter"),
    )


def parameter_table(identification) -> pd.DataFrame:
    """Per entry of pi: ``name, nominal, identified``."""
    import pandas as pd

    model = identification.model
    return pd.DataFrame(
        {
            "name": list(_core.dynamic_parameter_names(model)),
            "nominal": _core.dynamic_parameters(model),
            "identified": np.asarray(identification.pi, dtype=float),
        }
    )


def _com_inertia(p10) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about the centre of mass) of 10 parameters; NaN for the
    last two when the mass is not positive."""
    m = float(p10[0])
    if not m > 0:
        return m, np.full(3, np.nan), np.full((3, 3), np.nan)
    c = np.asarray(p10[1:4], dtype=float) / m
    xx, xy, yy, xz, yz, zz = (float(v) for v in p10[4:])
    inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    # parallel axis: I_c = I_o - m (|c|^2 1 - c c^T)
    return m, c, inertia - m * (c @ c * np.eye(3) - np.outer(c, c))


def _clean(values, rel: float = 1e-12) -> np.ndarray:
    """For display: entries below ``rel`` times the largest magnitude (round-off of a zero, such
    as 1e-17 of a symmetric link's first moment) shown as 0."""
    v = np.asarray(values, dtype=float)
    finite = np.abs(v[np.isfinite(v)])
    scale = finite.max() if finite.size else 0.0
    return np.where(np.abs(v) < rel * scale, 0.0, v) + 0.0  # + 0.0: no "-0"


def _vec(v) -> str:
    return ", ".join(_fmt(float(x)) for x in _clean(list(v)))


def body_gap(identification) -> pd.DataFrame:
    """Per body: nominal and identified mass, centre of mass and inertia about it (xx, yy, zz,
    xy, xz, yz), the relative changes, and the pseudo-inertia's smallest eigenvalue."""
    import pandas as pd

    model = identification.model
    names = list(_core.dynamic_parameter_names(model))
    nominal = _core.dynamic_parameters(model)
    pi = np.asarray(identification.pi, dtype=float)
    rows = []
    for k, name in enumerate(names):
        if not name.endswith(".m") or names[k : k + 10] != _body_names(name[:-2]):
            continue
        least = float(np.linalg.eigvalsh(pseudo_inertia(pi[k : k + 10]))[0])
        scale = float(np.abs(pi[k : k + 10]).max())
        m0, c0, i0 = _com_inertia(nominal[k : k + 10])
        m1, c1, i1 = _com_inertia(pi[k : k + 10])
        d_i = np.linalg.norm(i1 - i0) / np.linalg.norm(i0) if np.linalg.norm(i0) > 0 else np.nan
        diag = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]
        rows.append(
            {
                "body": name[:-2],
                "mass nominal [kg]": m0,
                "mass identified [kg]": m1,
                "mass change [%]": 100 * (m1 - m0) / m0 if m0 > 0 else np.nan,
                "com nominal [m]": _vec(c0),
                "com identified [m]": _vec(c1),
                "com shift [m]": float(np.linalg.norm(c1 - c0)),
                "I_com nominal (xx, yy, zz, xy, xz, yz)": _vec(i0[a, b] for a, b in diag),
                "I_com identified": _vec(i1[a, b] for a, b in diag),
                "I_com change [%] (Frobenius)": 100 * d_i,
                "min eig. pseudo-inertia": least,
                "physically consistent": "yes" if least >= -PHYSICAL_TOL * scale else "\u2718 no",
            }
        )
    return pd.DataFrame(rows).set_index("body") if rows else pd.DataFrame()


def _body_names(body: str) -> list[str]:
    return [f"{body}.{f}" for f in _BODY_FIELDS]


def joint_gap(identification) -> pd.DataFrame:
    """Per joint coordinate: nominal and identified ``fv, fc, offset, Ia``."""
    import pandas as pd

    model = identification.model
    names = list(_core.dynamic_parameter_names(model))
    nominal = _core.dynamic_parameters(model)
    pi = np.asarray(identification.pi, dtype=float)
    index = {n: k for k, n in enumerate(names)}
    rows = {}
    for c in model.coord_names:
        row = {}
        for f in _JOINT_FIELDS:
            k = index.get(f"{c}.{f}")
            row[f"{f} nominal"] = nominal[k] if k is not None else np.nan
            row[f"{f} identified"] = pi[k] if k is not None else np.nan
        rows[c] = row
    return pd.DataFrame.from_dict(rows, orient="index").rename_axis("joint")


# ----------------------------------------------------------------------------- the figure


def torque_figure(validation: Validation, nominal: Validation | None = None):
    """Measured against predicted torque per joint (one panel each, two columns), the identified
    model's and, when given, the nominal one's: a matplotlib Figure (no pyplot)."""
    from armdyn.plotting import _matplotlib_figure

    n = len(validation.joint_names)
    cols = 2 if n > 1 else 1
    rows = -(-n // cols)
    fig = _matplotlib_figure()(figsize=(11.0, 2.3 * rows + 0.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols, sharex=True, squeeze=False)).reshape(-1)
    t = validation.t
    for j, name in enumerate(validation.joint_names):
        ax = axes[j]
        ax.plot(t, validation.tau_measured[:, j], color="0.6", lw=2.2, label="measured")
        ax.plot(
            t,
            validation.tau_predicted[:, j],
            color="C0",
            lw=1.0,
            label=f"identified (RMSE {validation.rmse[j]:.3g})",
        )
        if nominal is not None:
            ax.plot(
                t,
                nominal.tau_predicted[:, j],
                color="C1",
                lw=1.0,
                ls="--",
                label=f"nominal (RMSE {nominal.rmse[j]:.3g})",
            )
        ax.set_title(name, fontsize=10)
        ax.set_ylabel("torque [N m or N]", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right", framealpha=0.7)
    for ax in axes[n:]:
        ax.set_visible(False)
    for ax in axes[max(0, n - cols) : n]:
        ax.set_xlabel("t [s]")
    fig.suptitle("validation data: measured and predicted joint torques")
    return fig


# ------------------------------------------------------------------------------- the page


def _verdict_block(ident, validation, nominal, statuses, title, subtitle, ls=None) -> str:
    overall = overall_status(statuses)
    cls, word = _STATUS[overall]
    joints = list(ident.model.dof_names)
    sigma = np.broadcast_to(np.asarray(ident.sigma, dtype=float), (len(joints),))
    out = [
        '<section id="verdict">',
        f"<h1>{_esc(title)}</h1>",
        f'<p class="sub">{_esc(subtitle)}</p>' if subtitle else "",
        f'<div class="overall {cls}" id="overall" data-status="{overall}">Overall: {word}</div>',
        '<table class="verdict" id="verdict-table"><thead><tr><th>joint</th><th>verdict</th>'
        "<th>RMSE identified</th><th>rel. RMSE identified</th>"
        + ("<th>RMSE least squares</th>" if ls is not None else "")
        + "<th>RMSE nominal</th><th>rel. RMSE nominal</th><th>fit noise \u03c3</th>"
        "<th>largest error (at t)</th></tr></thead><tbody>",
    ]
    for j, joint in enumerate(joints):
        s = statuses[j]
        c, w = _STATUS[s]
        if validation is not None:
            cells = (
                f'<td class="num">{_fmt(validation.rmse[j])}</td>'
                f'<td class="num">{_pct(validation.rel_rmse[j])}</td>'
            )
            worst = f"{_fmt(validation.max_error[j])} (t = {_fmt(validation.max_error_time[j])} s)"
        else:
            cells, worst = '<td class="num">\u2013</td><td class="num">\u2013</td>', "\u2013"
        if ls is not None:
            cells += f'<td class="num">{_fmt(ls.rmse[j])}</td>'
        if nominal is not None:
            cells += (
                f'<td class="num">{_fmt(nominal.rmse[j])}</td>'
                f'<td class="num">{_pct(nominal.rel_rmse[j])}</td>'
            )
        else:
            cells += '<td class="num">\u2013</td><td class="num">\u2013</td>'
        out.append(
            f'<tr class="verdict-row" data-joint="{_esc(joint)}" data-status="{s}">'
            f'<td><b>{_esc(joint)}</b></td><td class="status {c}">{w}</td>{cells}'
            f'<td class="num">{_fmt(float(sigma[j]))}</td><td class="num">{worst}</td></tr>'
        )
    out.append("</tbody></table>")
    out.append(
        f'<p class="sub">On the validation data (not used by the fit). MATCH: the RMSE is at most '
        f"{MATCH_REL_RMSE:.0%} of the measured torque's RMS (rel. RMSE). AT NOISE LEVEL: larger, "
        f"but at most {NOISE_FACTOR:g} \u00d7 the fit's residual noise \u03c3 of the joint. "
        "Torques in N m (revolute) or N (prismatic)."
        + (
            " RMSE least squares: the unconstrained estimate's (the price of physical "
            "consistency is the difference)."
            if ls is not None
            else ""
        )
        + "</p>"
    )
    out.append("</section>")
    return "\n".join(p for p in out if p)


def _pct(x: float) -> str:
    return "\u221e" if np.isinf(x) else f"{100 * x:.3g} %"


def _sections(ident, validation, nominal, figure: ReportFigure | None, logs) -> list[Section]:
    import pandas as pd

    base = base_table(ident)
    poor = int(base["poorly_identified"].sum())
    shown = base.assign(
        poorly_identified=np.where(base["poorly_identified"], "\u2718 poorly identified", ""),
        **{c: _clean(base[c].to_numpy()) for c in ("nominal", "identified", "least_squares")},
    ).rename(
        columns={
            "least_squares": "least squares",
            "rel_std": "std / |identified|",
            "poorly_identified": "flag",
        }
    )
    sections = []
    if figure is not None:
        sections.append(Section("Measured and predicted torques", figures=[figure]))
    else:
        sections.append(Section("Measured and predicted torques", text="no validation data given"))
    sections.append(
        Section(
            "Base parameters",
            text=f"{len(base)} identifiable combinations of the parameters; {poor} poorly "
            f"identified (std > {POOR_REL_STD:.0%} of |identified|). identified: the "
            f"{'physically consistent' if ident.physical else 'least-squares'} estimate; std: "
            "the least-squares estimate's standard deviation.",
            tables=[("base parameters", shown)],
        )
    )
    sections.append(
        Section(
            "Nominal against identified model",
            text="Only the base parameters are identified: the rest of the parameter vector is "
            "the completion closest to the nominal one, so a body's change shows where the data "
            "moved the model, not a measurement of that body alone. Centre of mass and inertia "
            "in the body's parameter frame (the URDF link frame); a negative pseudo-inertia "
            "eigenvalue is a physically inconsistent body.",
            tables=[("per body", body_gap(ident)), ("per joint", joint_gap(ident))],
        )
    )
    fit = pd.DataFrame(
        {
            "fit RMSE": np.asarray(ident.rmse, dtype=float),
            "fit noise \u03c3": np.asarray(ident.sigma, dtype=float),
        },
        index=pd.Index(list(ident.model.dof_names), name="joint"),
    )
    tables = [("fit residuals", fit)]
    if logs:
        described = pd.DataFrame(
            {"how q, qd, qdd and tau were obtained": [str(v) for v in logs.values()]},
            index=pd.Index([str(k) for k in logs], name="log"),
        )
        tables.insert(0, ("the logs", described))
    if validation is not None:
        tables.append(
            (
                "largest validation errors (identified model)",
                validation.largest_errors(3).set_index("joint"),
            )
        )
    outliers = len(np.atleast_1d(getattr(ident, "outliers", [])))
    sections.append(
        Section(
            "Fit",
            text=f"method {ident.method}, solver {ident.solver}, physically consistent "
            f"estimate: {'yes' if ident.physical else 'no'}; {ident.n_samples} samples, "
            f"{outliers} rejected as outliers.{_solver_note(ident)}",
            tables=tables,
        )
    )
    return sections


def _solver_note(ident) -> str:
    """The consistent estimate's solver status (from ``Identification.info`` when it has one)."""
    info = getattr(ident, "info", None) or {}
    return f" Solver status: {info['status']}." if "status" in info else ""


def render_report(
    identification,
    validation=None,
    nominal_validation=None,
    *,
    urdf=None,
    figure=None,
    logs=None,
    ls_validation=None,
) -> str:
    """The HTML page (see the module notes); ``figure``: the torque figure's
    :class:`~armdyn.sizing.html.ReportFigure` (None: no figure); ``logs``: ``{role:
    description}`` of the logs (as :func:`write_report`)."""
    ident = identification
    statuses = joint_status(validation, ident.sigma)
    title = "Identification report" + (f": {Path(os.fspath(urdf)).name}" if urdf else "")
    subtitle = (
        f"{'physically consistent' if ident.physical else 'unconstrained'} {ident.method} "
        f"estimate of {len(ident.base.names)} base parameters from {ident.n_samples} samples"
        + ("" if validation is not None else "; no validation data: the verdict is not made")
    )
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
        _verdict_block(
            ident, validation, nominal_validation, statuses, title, subtitle, ls_validation
        ),
        *(
            _section_block(k, s)
            for k, s in enumerate(_sections(ident, validation, nominal_validation, figure, logs))
        ),
        "</body></html>",
    ]
    return "\n".join(parts)


def write_report(
    identification,
    out_dir,
    *,
    validation: Validation | None = None,
    nominal_validation: Validation | None = None,
    urdf=None,
    logs=None,
    ls_validation: Validation | None = None,
) -> Path:
    """Write ``report.html``, ``torques.png`` (with a validation), ``parameters.csv`` and
    ``base_parameters.csv`` of ``identification`` into ``out_dir`` (created if missing; see
    the module notes); returns the page's path. ``validation``: the identified model's
    :func:`~armdyn.identification.validate.validate` on data the fit did not use;
    ``nominal_validation``: the nominal model's on the same data; ``urdf``: the nominal URDF's
    path (named in the title); ``logs``: ``{role: description}`` shown in the fit section, e.g.
    ``{"fit": fit_log.processing, "validation": val_log.processing}`` (how q, qd, qdd and tau
    were obtained: :attr:`MotionLog.processing`); ``ls_validation``: the unconstrained
    least-squares estimate's validation on the same data (a column of the verdict table: what
    physical consistency costs). OSError when the folder cannot be written;
    ModelError when the validations' joints are not the model's."""
    joints = list(identification.model.dof_names)
    for name, v in (
        ("validation", validation),
        ("nominal_validation", nominal_validation),
        ("ls_validation", ls_validation),
    ):
        if v is not None and list(v.joint_names) != joints:
            raise _core.ModelError(
                f"write_report: {name}'s joints {list(v.joint_names)} are not the model's {joints}"
            )
    out = Path(os.fspath(out_dir))
    out.mkdir(parents=True, exist_ok=True)
    figure = None
    if validation is not None:
        png = figure_png(torque_figure(validation, nominal_validation))
        alt = "measured and predicted joint torques on the validation data, per joint"
        figure = ReportFigure("measured and predicted torques", png, alt, "torques.png")
        (out / "torques.png").write_bytes(png)
    parameter_table(identification).to_csv(out / "parameters.csv", index=False)
    base_table(identification).to_csv(out / "base_parameters.csv")
    page = out / "report.html"
    page.write_text(
        render_report(
            identification,
            validation,
            nominal_validation,
            urdf=urdf,
            figure=figure,
            logs=logs,
            ls_validation=ls_validation,
        ),
        encoding="utf-8",
    )
    return page
