"""The sizing report's files (:meth:`SizingReport.save`): ``table.csv``, the figures
``torque_<k>.png`` / ``motor_<k>.png`` and the HTML page ``report.html`` that shows them."""

from __future__ import annotations

import html
import os
from pathlib import Path
from typing import Any

import numpy as np

#: a SizingReport (armdyn.sizing.report imports this module)
_SizingReport = Any


def write_report(report: _SizingReport, directory: str | os.PathLike[str]) -> Path:
    """Write ``table.csv``, the figures and ``report.html`` of ``report`` into ``directory``
    (created if missing); returns the HTML page's path (see :meth:`SizingReport.save`)."""
    out = Path(os.fspath(directory))
    out.mkdir(parents=True, exist_ok=True)
    report.table.to_csv(out / "table.csv")
    figures = _write_figures(report, out)
    page = out / "report.html"
    page.write_text(_page(report, figures), encoding="utf-8")
    return page


def _write_figures(report: _SizingReport, out: Path) -> list[tuple[Any, list[tuple[str, str]]]]:
    """Save each joint's figures (its torque when non-zero, its motor's speed–torque plane when
    it has one); ``[(joint, [(png, alt text), ...]), ...]``."""
    # bare Figures (Agg canvas): no pyplot state, the user's backend is left alone
    from armdyn.plotting import sizing_envelope_figure, sizing_torque_figure

    figures = []
    for k, name in enumerate(report.table.index):
        tau = report.torque[:, k]
        if np.all(np.isnan(tau) | (tau == 0.0)):  # no actuation on this joint
            continue
        fig = sizing_torque_figure(report, name)
        png = f"torque_{k}.png"
        fig.savefig(out / png, dpi=100)
        items = [(png, f"torque of {name}")]
        if name in report.motors:
            png_m = f"motor_{k}.png"
            sizing_envelope_figure(report, name).savefig(out / png_m, dpi=100)
            items.append((png_m, f"speed-torque plane of the motor of {name}"))
        figures.append((name, items))
    return figures


def _page(report: _SizingReport, figures) -> str:
    """The HTML page: the table, then each joint's figures under its name."""
    parts = [
        "<!DOCTYPE html>",
        '<html><head><meta charset="utf-8"><title>armdyn sizing report</title></head><body>',
        "<h1>Sizing report</h1>",
        report.table.to_html(float_format=lambda v: f"{v:.6g}"),
    ]
    for name, items in figures:
        label = html.escape(str(name))
        parts.append(f"<h2>{label}</h2>")
        for png, alt in items:
            parts.append(f'<img src="{png}" alt="{html.escape(alt)}">')
    parts.append("</body></html>")
    return "\n".join(parts)
