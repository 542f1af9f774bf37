"""armdyn.identification.report: the identification report's page, figure and tables (issue 35).

The identification is identify()'s on a synthetic log of a perturbed arm6 with known noise
(identification_synthetic.py)."""

import dataclasses
import html
import re
from pathlib import Path

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn.identification import identify, report
from armdyn.identification.validate import compare, validate
from identification_synthetic import synthetic_log, true_parameters

ARM6 = Path(__file__).resolve().parents[1] / "data" / "urdf" / "arm6.urdf"
NOISE = 0.05


@pytest.fixture(scope="module")
def case():
    model = ad.load_urdf(str(ARM6))
    pi_true = true_parameters(model)
    fit = synthetic_log(model, pi_true, noise=NOISE, seed=1)
    val = synthetic_log(model, pi_true, noise=NOISE, seed=2)
    ident = identify(model, fit)
    return model, ident, validate(ident, val), validate(model, val)


def _statuses(page: str) -> dict:
    return dict(re.findall(r'data-joint="([^"]+)" data-status="([a-z]+)"', page))


def test_write_report_files(case, tmp_path):
    model, ident, v, nominal = case
    logs = {"fit": "q <filtered> at 5 Hz", "validation": "given"}
    page = report.write_report(
        ident, tmp_path / "out", validation=v, nominal_validation=nominal, logs=logs
    )
    assert page == tmp_path / "out" / "report.html"
    text = page.read_text(encoding="utf-8")
    assert "q &lt;filtered&gt; at 5 Hz" in text  # the logs' processing, escaped
    # identified: the error is the noise (0.05 N m), under 10 % of every joint's torque RMS
    assert _statuses(text) == {j: "match" for j in model.dof_names}
    assert 'data-status="match"' in text.split('id="verdict-table"')[0]
    for j in range(model.n_dofs):  # the verdict shows both models' RMSE
        assert f"{v.rmse[j]:.4g}" in text and f"{nominal.rmse[j]:.4g}" in text
    params = pd.read_csv(tmp_path / "out" / "parameters.csv")
    assert params["name"].tolist() == ad.dynamic_parameter_names(model)
    np.testing.assert_array_equal(params["identified"].to_numpy(), ident.pi)
    np.testing.assert_array_equal(params["nominal"].to_numpy(), ad.dynamic_parameters(model))
    base = pd.read_csv(tmp_path / "out" / "base_parameters.csv", index_col=0)
    np.testing.assert_allclose(
        base["nominal"], ident.base.matrix @ ad.dynamic_parameters(model), rtol=1e-12, atol=1e-15
    )
    np.testing.assert_array_equal(base["poorly_identified"], ident.beta_std > 0.1 * abs(ident.beta))
    png = (tmp_path / "out" / "torques.png").read_bytes()
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    assert "data:image/png;base64," in text
    # the page loads nothing from elsewhere
    assert "<script" not in text and "http" not in text.replace("http-equiv", "")


def test_least_squares_column(case, tmp_path):
    """ls_validation: the unconstrained estimate's RMSE is a column of the verdict table."""
    model, ident, v, _ = case
    ls = compare(v.t, v.tau_measured, v.tau_predicted + 0.5, list(model.dof_names))
    text = report.write_report(ident, tmp_path, validation=v, ls_validation=ls).read_text()
    head = text.split('id="verdict-table"')[1].split("</thead>")[0]
    assert "<th>RMSE least squares</th>" in head
    row = text.split('data-joint="elbow_joint"')[1].split("</tr>")[0]
    cells = re.findall(r'<td class="num">([^<]*)</td>', row)
    assert cells[2] == f"{ls.rmse[2]:.4g}"  # after the identified RMSE and relative RMSE
    assert "RMSE least squares" not in report.write_report(ident, tmp_path / "b").read_text()


def test_verdict_no_match_and_not_validated(case, tmp_path):
    """The nominal model's validation as the 'identified' one: its rel. RMSE is above 10 % on
    the joints the perturbation moved and far above the fit's noise, so NO MATCH."""
    _, ident, _, nominal = case
    page = report.write_report(ident, tmp_path, validation=nominal).read_text(encoding="utf-8")
    statuses = _statuses(page)
    expected = ["match" if r <= 0.1 else "mismatch" for r in nominal.rel_rmse]
    assert list(statuses.values()) == expected and "mismatch" in expected
    assert 'id="overall" data-status="mismatch"' in page
    page = report.write_report(ident, tmp_path / "nv").read_text(encoding="utf-8")
    assert set(_statuses(page).values()) == {"unvalidated"}
    assert not (tmp_path / "nv" / "torques.png").exists()


def test_joint_status_rules():
    t = np.arange(4.0)
    meas = np.ones((4, 3)) * [10.0, 1.0, 1.0]
    # errors: 5 % of the RMS, 20 % (at 1.1 sigma), 20 % (at 2 sigma)
    pred = meas + np.array([0.5, 0.2, 0.2]) * [[1], [-1], [1], [-1]]
    v = compare(t, meas, pred, ["a", "b", "c"])
    sigma = np.array([0.01, 0.2 / 1.1, 0.1])
    assert report.joint_status(v, sigma) == ["match", "noise", "mismatch"]
    assert report.overall_status(["match", "noise"]) == "noise"
    assert report.overall_status(["match", "noise", "mismatch"]) == "mismatch"
    assert report.joint_status(None, sigma) == ["unvalidated"] * 3


def test_pseudo_inertia_closed_form():
    # a point mass m at c: J = m [c; 1][c; 1]^T (rank one, smallest eigenvalue 0)
    m, c = 2.0, np.array([0.1, -0.2, 0.3])
    inertia = m * (c @ c * np.eye(3) - np.outer(c, c))  # about the origin
    p10 = [m, *(m * c), inertia[0, 0], inertia[0, 1], inertia[1, 1], inertia[0, 2]]
    p10 += [inertia[1, 2], inertia[2, 2]]
    v = np.append(c, 1.0)
    np.testing.assert_allclose(report.pseudo_inertia(p10), m * np.outer(v, v), atol=1e-15)
    # a rod violating the triangle inequality (Izz > Ixx + Iyy) is not PSD
    bad = [1.0, 0, 0, 0, 0.1, 0, 0.1, 0, 0, 0.3]
    assert np.linalg.eigvalsh(report.pseudo_inertia(bad))[0] < 0


def test_body_and_joint_gap(case):
    """Scaling a body's 10 parameters by s keeps its centre of mass and scales its mass and its
    inertia about the centre of mass by s (closed form)."""
    model, ident, _, _ = case
    names = ad.dynamic_parameter_names(model)
    pi = ad.dynamic_parameters(model).copy()
    k = names.index("forearm_link.m")
    pi[k : k + 10] *= 1.5
    pi[names.index("elbow_joint.fv")] = 0.25
    fake = dataclasses.replace(ident, pi=pi)
    gap = report.body_gap(fake)
    assert gap.loc["forearm_link", "mass change [%]"] == pytest.approx(50.0, rel=1e-12)
    assert gap.loc["forearm_link", "com shift [m]"] == pytest.approx(0.0, abs=1e-15)
    assert gap.loc["forearm_link", "I_com change [%] (Frobenius)"] == pytest.approx(50.0)
    others = gap.drop(index="forearm_link")
    assert np.all(others["mass change [%]"] == 0.0)
    assert set(gap["physically consistent"]) == {"yes"}
    joints = report.joint_gap(fake)
    assert joints.loc["elbow_joint", "fv identified"] == 0.25
    assert joints.loc["elbow_joint", "fv nominal"] == 0.0


def test_solver_note(case, tmp_path):
    """A physically consistent identification's solver status in the fit section."""
    _, ident, v, _ = case
    fake = dataclasses.replace(ident, physical=True, info={"status": "optimal"})
    text = report.write_report(fake, tmp_path, validation=v).read_text(encoding="utf-8")
    text = html.unescape(text)
    assert "Solver status: optimal." in text


def test_write_report_bad_inputs(case, tmp_path):
    _, ident, v, _ = case
    afile = tmp_path / "file"
    afile.write_text("x")
    with pytest.raises(OSError):
        report.write_report(ident, afile, validation=v)
    wrong = compare(v.t, v.tau_measured, v.tau_predicted, [f"j{k}" for k in range(6)])
    with pytest.raises(ad.ModelError, match="validation's joints"):
        report.write_report(ident, tmp_path / "w", validation=wrong)
    assert not (tmp_path / "w").exists()


def test_round_off_shown_as_zero():
    """Display only: 1e-17 beside 2 is a zero's round-off; the CSVs keep every digit."""
    np.testing.assert_array_equal(report._clean([1e-17, -0.0, 2.0, -3e-11]), [0, 0, 2, -3e-11])
    assert report._vec([1e-17, -0.0, 0.0254]) == "0, 0, 0.0254"
    assert report._vec([0.0, 0.0, 0.0]) == "0, 0, 0"
