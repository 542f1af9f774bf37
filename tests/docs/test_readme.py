"""The README: its two commands as `.ci/run` and users read them, the quick start on the first
screen and its results against closed forms, the reproduce tables it quotes, its sizing example
against the motor-side closed form, and `armdyn verify` (whose output docs/benchmarks.md quotes)
within the documented bounds. The README's blocks are run once, by the session fixture
``doc_file_blocks``."""

from pathlib import Path

import armdyn as ad
import numpy as np
import pytest
from armdyn import verify
from doc_blocks import fenced_blocks, namespace_with

README = Path(__file__).resolve().parents[2] / "README.md"


@pytest.fixture(scope="module")
def doc_blocks(doc_file_blocks):
    """The README's blocks (the other files' are not needed here)."""
    return doc_file_blocks("README.md")


def test_the_two_commands():
    text = README.read_text()
    assert "\n    python -m pip install . && armdyn reproduce\n" in text
    assert '\n    python -m pip install ".[test]" && python -m pytest\n' in text
    ci = (README.parent / ".ci" / "run").read_text()
    assert 'python -m pip install ".[test]"' in ci and "\npython -m pytest" in ci


def test_quick_start_is_on_the_first_screen(doc_blocks):
    text = README.read_text()
    line, lang, code = fenced_blocks(text)[0]
    assert lang == "python" and "ad.simulate(" in code
    assert line <= 60  # within the first screen
    assert len(code.strip().splitlines()) <= 20  # a ~15-line quick start
    assert len(text) <= 16_000  # short: the benchmarks live in docs/benchmarks.md


def test_quick_start_runs_and_holds_the_static_torque(doc_blocks):
    ns = namespace_with(doc_blocks, "README.md", "res", "model")
    res, model = ns["res"], ns["model"]
    # at t = 0 the arm is at rest and horizontal: the drives hold gravity's moment about +y,
    # closed form -(sum of m g x_com) for the shoulder and -(m g (x_com - x_elbow)) for the elbow
    g = 9.81
    np.testing.assert_allclose(
        res.drive_forces[0], [-(2.0 * g * 0.4 + 1.0 * g * 1.0), -(1.0 * g * 0.2)], rtol=1e-10
    )
    assert res.position_residual.max() <= 1e-12
    assert model.drive_names == ["shoulder", "elbow"]


def test_verify_figures():
    for deg in (30.0, 170.0):
        sim, exact = verify.pendulum_period(np.radians(deg))
        assert abs(sim - exact) / exact <= 1e-8
    for value in verify.conservation().values():
        assert value <= 1e-9
    for _, rf, rv in verify.drift(steps=2000).values():
        assert rf <= 1e-12 and rv <= 1e-12
    assert verify.lagrange_crosscheck(n_arms=2) <= 1e-10


def test_cli_verify_entry_point(capsys):
    from armdyn.__main__ import main

    assert main(["verify"]) == 0
    out = capsys.readouterr().out
    assert "max relative difference in qdd" in out
    assert ad.__version__


def test_readme_quotes_the_reproduce_tables():
    """The tables quoted in the README are what `armdyn reproduce` prints now."""
    from armdyn.papers.reproduce import five_dof_study, table2

    text = README.read_text()
    assert "armdyn reproduce" in text
    for line in table2(five_dof_study()).splitlines():
        if "e-" in line:  # round-off columns vary in the last digit between machines
            line = line.rsplit("|", 3)[0]
        assert line in text, line


def test_sizing_example_runs(doc_blocks):
    """The README's sizing block, continuing the quick start: the motor-side torque of the
    shoulder equals the closed form from the run's own samples, T = J N q̈ + τ_gear/(N η) while
    the gear drives the arm (τ_gear q̇ ≥ 0), else J N q̈ + τ_gear η / N with τ_gear the drive's
    torque, and the report is written."""
    blocks = [b for b in doc_blocks if b.file == "README.md"]
    sizing = next(b for b in blocks if "sizing_report" in b.code)
    assert sizing.continues and len(sizing.code.strip().splitlines()) <= 12
    ns = namespace_with(doc_blocks, "README.md", "report", "sweep")
    res, row = ns["res"], ns["report"].table.loc["shoulder"]
    n, j, eta = 100.0, 5e-5, 0.85
    tau, qd, qdd = res.drive_forces[:, 0], res.qd[:, 0], res.qdd[:, 0]
    motor = j * n * qdd + np.where(tau * qd >= 0, tau / (n * eta), tau * eta / n)
    np.testing.assert_allclose(row["motor_peak_torque"], np.abs(motor).max(), rtol=1e-12)
    np.testing.assert_allclose(row["peak_torque"], np.abs(tau + n * n * j * qdd).max(), rtol=1e-12)
    assert (sizing.workdir / "sizing-report" / "report.html").is_file()
    assert (sizing.workdir / "sizing-report" / "motor_0.png").is_file()
    best = ns["sweep"].summary.loc["shoulder"]
    assert 20.0 <= best["ok_ratio_min"] <= 100.0 <= best["ok_ratio_max"] and bool(row["ok"])
