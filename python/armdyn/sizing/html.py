"""The sizing report's page: one self-contained HTML file that opens with the verdict.

The renderer (:func:`render_page`) knows nothing of runs or catalogs: it takes a small,
explicit :class:`ReportModel` — the verdict rows (one per joint: its parts, pass/fail, the
binding check and its margin), the per-check details (a long table: joint, part, check, value,
allowable, unit, margin) and the sections of figures and tables that follow — so that
:class:`armdyn.SizingReport` (:func:`armdyn.sizing.report.report_model`) and a drivetrain
selection (:func:`selection_report_model`) feed the same page.

The page, in order: the overall verdict and one row per joint (colour-coded, and readable
without colour: each status is also a word and a symbol), the checks grouped by part (motor,
gearbox, output bearing, drive, brake; "not checked" where a part's data is missing), then the
model's sections (histories, envelopes, sweeps, rankings). Figures are PNG embedded as
``data:`` URIs; the page loads nothing (no script, font, style sheet or image from elsewhere).
Printing puts each section on its own page and keeps the verdict table whole.
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from armdyn.sizing.checks import CHECKS, CHECKS_BY_NAME, Check, verdict

if TYPE_CHECKING:
    import pandas as pd

#: the parts whose checks the details group, in page order (``joint``: the URDF's own limits)
PARTS: tuple[str, ...] = ("joint", "motor", "gearbox", "bearing", "drive", "brake")
#: the part kinds a verdict row names (where known)
ROW_PARTS: tuple[str, ...] = ("motor", "gearbox", "drive")
#: a verdict status: every made check passes; some check fails; every made check passes but a
#: required one could not be made
STATUSES: tuple[str, ...] = ("pass", "fail", "unchecked")
DASH = "\u2013"
_STATUS_TEXT = {"pass": "\u2714 PASS", "fail": "\u2718 FAIL", "unchecked": "? NOT CHECKED"}


@dataclass(frozen=True)
class VerdictRow:
    """One joint's verdict.

    Attributes:
        joint: the joint's name.
        parts: ``{kind: name}`` of its parts where known (kinds of :data:`ROW_PARTS`; a gear
            ratio alone is given as ``{"gearbox": "N = 100"}``).
        status: ``"pass"``, ``"fail"`` or ``"unchecked"`` (:data:`STATUSES`).
        binding_check: the check of least margin ('' when nothing was checked).
        margin: its margin (NaN when nothing was checked).
        note: one line shown under the status (e.g. what could not be checked).
    """

    joint: str
    parts: Mapping[str, str]
    status: str
    binding_check: str
    margin: float
    note: str = ""

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"VerdictRow: status must be one of {STATUSES}, got {self.status!r}")


@dataclass(frozen=True)
class ReportFigure:
    """A figure of the page: PNG bytes, its title and alt text; ``file``: the name it is also
    saved under next to the page ('' = embedded only)."""

    title: str
    png: bytes
    alt: str
    file: str = ""


@dataclass(frozen=True)
class Section:
    """A section after the verdict: a title, an optional paragraph, figures and tables
    (``(caption, DataFrame)``)."""

    title: str
    text: str = ""
    figures: Sequence[ReportFigure] = ()
    tables: Sequence[tuple[str, Any]] = ()


@dataclass
class ReportModel:
    """What the page shows (see the module notes).

    Attributes:
        title: the page's heading.
        rows: one :class:`VerdictRow` per joint, in page order.
        checks: long DataFrame, one row per (joint, check): ``joint, part, check, value,
            allowable, unit, margin, doc`` (:func:`check_details`); NaN margin = not checked.
        sections: what follows the checks.
        subtitle: one line under the heading (the run, the objective...).
    """

    title: str
    rows: list[VerdictRow]
    checks: Any
    sections: list[Section] = field(default_factory=list)
    subtitle: str = ""

    @property
    def status(self) -> str:
        """The overall status: fail when a joint fails, else unchecked when one is, else pass
        (no joint at all: unchecked)."""
        found = {r.status for r in self.rows}
        if "fail" in found:
            return "fail"
        if "unchecked" in found or not self.rows:
            return "unchecked"
        return "pass"


def row_status(ok: bool, margin: float) -> str:
    """The status of a joint from its ``ok`` and its least margin: fail when a made check
    fails (margin < 1), unchecked when nothing was checked (margin NaN: no limit and no part
    data) or when ``ok`` is False only because a required check could not be made, else
    pass."""
    if margin < 1.0:
        return "fail"
    if np.isnan(margin):
        return "unchecked"
    return "pass" if ok else "unchecked"


#: checks whose margin is not allowable / value (or value / allowable): their allowable is
#: never derived from the margin
_NOT_A_QUOTIENT = ("winding_temperature",)


def check_details(
    joints: Sequence[str],
    values: Mapping[str, Any],
    checks: Sequence[Check] = CHECKS,
    derive_allowable: bool = False,
) -> pd.DataFrame:
    """The long details table from wide per-joint columns: ``values`` maps column names to
    per-joint arrays (or a DataFrame indexed by joint); for each check, ``value`` is the
    check's value column, ``allowable`` its allowable column and ``margin`` its margin column
    — or :func:`armdyn.sizing.checks.margin` of the two when the margin column is absent. A
    missing column is NaN (a NaN margin: not checked). ``derive_allowable``: where the
    allowable column is absent, it is the margin's definition solved for it (margin × value
    for an upper limit, value / margin for a lower one) where both are finite and positive —
    not for the winding temperature, whose margin compares rises above the ambient."""
    import pandas as pd

    from armdyn.sizing.checks import margin as check_margin

    n = len(joints)

    def column(name: str) -> np.ndarray:
        if name not in values:
            return np.full(n, np.nan)
        v = np.asarray(values[name], dtype=float).reshape(-1)
        return np.broadcast_to(v, (n,)) if v.size == 1 else v

    rows = []
    for c in checks:
        value, allowable = column(c.value), column(c.allowable)
        if c.margin_column in values:
            m = column(c.margin_column)
        else:
            m = check_margin(value, allowable, c.lower)
        if derive_allowable and c.allowable not in values and c.name not in _NOT_A_QUOTIENT:
            with np.errstate(all="ignore"):
                solved = value / m if c.lower else m * value
            usable = np.isfinite(m) & np.isfinite(value) & (m > 0) & (value > 0)
            allowable = np.where(usable, solved, np.nan)
        for k, joint in enumerate(joints):
            rows.append(
                (str(joint), c.part, c.name, value[k], allowable[k], c.unit, float(m[k]), c.doc)
            )
    cols = ["joint", "part", "check", "value", "allowable", "unit", "margin", "doc"]
    return pd.DataFrame(rows, columns=cols)


def verdict_of(details: pd.DataFrame, joint: str) -> tuple[bool, str, float]:
    """:func:`armdyn.sizing.checks.verdict` of one joint's rows of ``details``."""
    mine = details[details["joint"] == joint]
    if mine.empty:
        return True, "", float("nan")
    ok, binding, least = verdict(
        {c: np.array([m]) for c, m in zip(mine["check"], mine["margin"], strict=True)}
    )
    return bool(ok[0]), str(binding[0]), float(least[0])


def figure_png(fig, dpi: int = 100) -> bytes:
    """A matplotlib Figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


# ----------------------------------------------------------------------------- rendering

_CSS = """
:root { --pass: #1b7f3b; --fail: #c62828; --unchecked: #b26a00; --ink: #1d1d1d; }
* { box-sizing: border-box; }
body { font: 14px/1.35 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       color: var(--ink); margin: 0 auto; padding: 12px 20px; max-width: 1360px; }
h1 { font-size: 20px; margin: 0 0 2px; }
h2 { font-size: 17px; margin: 22px 0 8px; border-bottom: 1px solid #ccc; }
h3 { font-size: 15px; margin: 14px 0 6px; }
.sub { color: #555; margin: 0 0 8px; }
.overall { display: inline-block; font-weight: 700; font-size: 18px; padding: 4px 14px;
           border-radius: 4px; margin: 4px 0 8px; color: #fff; }
table { border-collapse: collapse; }
td, th { padding: 3px 9px; border: 1px solid #d0d0d0; text-align: left; vertical-align: top; }
th { background: #f1f1f1; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
table.verdict td { font-size: 15px; white-space: nowrap; }
.part { color: #555; font-size: 12px; }
.status { font-weight: 700; white-space: nowrap; color: #fff; }
.pass { background: var(--pass); color: #fff; }
.fail { background: var(--fail); color: #fff; }
.unchecked { background: var(--unchecked); color: #fff; }
td.m-fail { color: var(--fail); font-weight: 700; }
td.m-pass { color: var(--pass); }
td.m-none { color: #777; font-style: italic; }
.note { font-weight: 400; font-size: 12px; display: block; }
.figs { display: flex; flex-wrap: wrap; gap: 10px; }
.figs.grid figure { max-width: calc(50% - 5px); }
figure { margin: 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { font-size: 12px; color: #444; }
.wide { overflow-x: auto; max-width: 100%; }
.wide table td, .wide table th { font-size: 12px; padding: 2px 5px; }
@media print {
  @page { size: A4 landscape; margin: 12mm; }
  body { max-width: none; padding: 0; font-size: 11px; }
  * { -webkit-print-color-adjust: exact; print-color-adjust: exact; }
  section.page { break-before: page; }
  table.verdict td { font-size: 12px; }
  table.verdict, figure, tr { break-inside: avoid; }
  h2, h3 { break-after: avoid; }
  .wide { overflow: visible; }
  .wide table td, .wide table th { font-size: 8px; padding: 1px 3px; }
  figure img { max-height: 170mm; }
}
"""


def _esc(text: Any) -> str:
    return html.escape(str(text), quote=True)


def _fmt(x: Any) -> str:
    if isinstance(x, (float, np.floating)):
        if np.isnan(x):
            return "\u2013"
        if np.isinf(x):
            return "\u221e" if x > 0 else "\u2212\u221e"
        return f"{x:.4g}"
    return _esc(x)


def _margin_cell(m: float) -> str:
    if np.isnan(m):
        return '<td class="num m-none">not checked</td>'
    cls, mark = ("m-pass", "") if m >= 1.0 else ("m-fail", "\u2718 ")
    return f'<td class="num {cls}">{mark}{_fmt(float(m))}</td>'


def _verdict_block(model: ReportModel) -> str:
    overall = model.status
    details = model.checks
    extra = {}  # the model's own checks (e.g. the joint limits): name -> Check-like row
    if len(details):
        for r in details.drop_duplicates("check").itertuples():
            extra[r.check] = Check(r.check, r.part, "", "", False, r.unit, r.doc)
    counts = {s: sum(r.status == s for r in model.rows) for s in STATUSES}
    summary = ", ".join(f"{counts[s]} {s.replace('unchecked', 'not checked')}" for s in STATUSES)
    out = [
        '<section id="verdict">',
        f"<h1>{_esc(model.title)}</h1>",
        f'<p class="sub">{_esc(model.subtitle)}</p>' if model.subtitle else "",
        f'<div class="overall {overall}" id="overall" data-status="{overall}">'
        f"Overall: {_STATUS_TEXT[overall]}</div> "
        f'<span class="sub">{len(model.rows)} joint(s): {summary}</span>',
        '<table class="verdict" id="verdict-table"><thead><tr><th>joint</th>',
        *(f"<th>{k}</th>" for k in ROW_PARTS),
        "<th>verdict</th><th>binding check</th><th>margin</th></tr></thead><tbody>",
    ]
    for r in model.rows:
        note = f'<span class="note">{_esc(r.note)}</span>' if r.note else ""
        cells = "".join(f"<td>{_esc(r.parts.get(k, '') or DASH)}</td>" for k in ROW_PARTS)
        check = _esc(r.binding_check) if r.binding_check else DASH
        known = CHECKS_BY_NAME.get(r.binding_check) or extra.get(r.binding_check)
        if known is not None:
            check = (
                f'<span title="{_esc(known.doc)}">{check}</span> '
                f'<span class="part">({known.part})</span>'
            )
        out.append(
            f'<tr class="verdict-row" data-joint="{_esc(r.joint)}" data-status="{r.status}">'
            f"<td><b>{_esc(r.joint)}</b></td>{cells}"
            f'<td class="status {r.status}">{_STATUS_TEXT[r.status]}{note}</td>'
            f"<td>{check}</td>{_margin_cell(r.margin)}</tr>"
        )
    out.append("</tbody></table>")
    out.append(
        '<p class="sub">margin = allowable / value (a lower limit such as a life: value / '
        "allowable); \u2265 1 passes. The binding check is the check of least margin.</p>"
    )
    out.append("</section>")
    return "\n".join(out)


def _checks_block(model: ReportModel) -> str:
    details = model.checks
    out = ['<section id="checks" class="page"><h2>Checks by part</h2>']
    joints = [r.joint for r in model.rows]
    for part in PARTS:
        rows = details[details["part"] == part] if len(details) else details
        if part == "joint" and rows.empty:
            continue
        out.append(f'<h3 id="part-{part}">{"joint limits" if part == "joint" else part}</h3>')
        if rows.empty or (rows["margin"].isna().all() and rows["allowable"].isna().all()):
            out.append(
                f'<p class="m-none part-unchecked" data-part="{part}">not checked: no {part} '
                "data (no allowable values given)</p>"
            )
            continue
        out.append("<table><thead><tr><th>joint</th><th>check</th><th>value</th>")
        out.append("<th>allowable</th><th>unit</th><th>margin</th></tr></thead><tbody>")
        for joint in joints:
            mine = rows[rows["joint"] == joint]
            if mine.empty:
                continue
            if mine["margin"].isna().all() and mine["value"].isna().all():
                out.append(
                    f'<tr><td>{_esc(joint)}</td><td colspan="5" class="m-none">not checked: '
                    f"no {part} data for this joint</td></tr>"
                )
                continue
            for r in mine.itertuples():
                out.append(
                    f'<tr><td>{_esc(joint)}</td><td title="{_esc(r.doc)}">{_esc(r.check)}</td>'
                    f'<td class="num">{_fmt(r.value)}</td><td class="num">{_fmt(r.allowable)}'
                    f"</td><td>{_esc(r.unit)}</td>{_margin_cell(r.margin)}</tr>"
                )
        out.append("</tbody></table>")
    out.append("</section>")
    return "\n".join(out)


def _table_html(df) -> str:
    return df.to_html(float_format=lambda v: f"{v:.4g}", na_rep="\u2013", border=0)


def _section_block(k: int, s: Section) -> str:
    out = [f'<section id="section-{k}" class="page"><h2>{_esc(s.title)}</h2>']
    if s.text:
        out.append(f"<p>{_esc(s.text)}</p>")
    if s.figures:
        out.append('<div class="figs grid">' if len(s.figures) > 1 else '<div class="figs">')
        for f in s.figures:
            data = base64.b64encode(f.png).decode("ascii")
            out.append(
                f'<figure><img src="data:image/png;base64,{data}" alt="{_esc(f.alt)}">'
                f"<figcaption>{_esc(f.title)}</figcaption></figure>"
            )
        out.append("</div>")
    for caption, df in s.tables:
        out.append(f"<h3>{_esc(caption)}</h3><div class=wide>{_table_html(df)}</div>")
    out.append("</section>")
    return "\n".join(out)


def render_page(model: ReportModel) -> str:
    """The HTML page of ``model`` (see the module notes): self-contained, no script."""
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{_esc(model.title)}</title><style>{_CSS}</style></head><body>",
        _verdict_block(model),
        _checks_block(model),
        *(_section_block(k, s) for k, s in enumerate(model.sections)),
        "</body></html>",
    ]
    return "\n".join(p for p in parts if p)
