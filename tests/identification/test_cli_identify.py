"""``armdyn identify``: the CLI run in-process on a small synthetic log (issue 35).

The log is "measured" on a two-joint arm whose parameters were perturbed (bodies scaled,
friction, offsets and rotor inertias added: identification_synthetic.true_parameters), with
Gaussian noise of known level; the CLI must write the identified URDF (its parameters those of
parameters.csv), the report and parameters.csv, exit 0, and refuse hostile inputs with one line
and exit code 2."""

import os
import re

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn.__main__ import main
from identification_synthetic import synthetic_log, true_parameters

pytest.importorskip("armdyn.identification.estimate", reason="needs the fit part (i35-fit)")
pytest.importorskip("armdyn.identification.log", reason="needs the log part (i35-log)")
pytest.importorskip("armdyn.identification.export", reason="needs the model part (i35-model)")

NOISE = 0.01

URDF = """<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <link name="upper">
    <inertial><origin xyz="0.2 0.01 0.02"/><mass value="2.0"/>
      <inertia ixx="0.004" ixy="0.0002" ixz="0.0001" iyy="0.03" iyz="0.0003" izz="0.031"/>
    </inertial>
  </link>
  <link name="lower">
    <inertial><origin xyz="0.15 0.0 0.01"/><mass value="1.0"/>
      <inertia ixx="0.002" ixy="0.0001" ixz="0.0" iyy="0.01" iyz="0.0001" izz="0.011"/>
    </inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="lower"/><origin xyz="0.4 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="5"/>
  </joint>
</robot>
"""


def _csv(path, model, log, derivatives=True):
    cols = {"t": log.t}
    for j, c in enumerate(model.coord_names):
        cols[c] = log.q[:, j]
        cols[f"{c}.tau"] = log.tau[:, j]
        if derivatives:
            cols[f"{c}.qd"] = log.qd[:, j]
            cols[f"{c}.qdd"] = log.qdd[:, j]
    pd.DataFrame(cols).to_csv(path, index=False)
    return str(path)


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    d = tmp_path_factory.mktemp("identify")
    urdf = d / "two.urdf"
    urdf.write_text(URDF)
    model = ad.load_urdf(str(urdf))
    names = ad.dynamic_parameter_names(model)
    pi_true = true_parameters(model, seed=4)
    for c in model.coord_names:  # rotors
        pi_true[names.index(f"{c}.Ia")] = 0.02
    fit = synthetic_log(model, pi_true, n=600, duration=12.0, noise=NOISE, seed=1)
    val = synthetic_log(model, pi_true, n=300, duration=6.0, noise=NOISE, seed=2)
    return {
        "dir": d,
        "urdf": str(urdf),
        "model": model,
        "pi": pi_true,
        "fit": _csv(d / "fit.csv", model, fit),
        "val": _csv(d / "val.csv", model, val),
        "val_log": val,
    }


def test_identify_writes_urdf_report_parameters(robot, tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["identify", robot["urdf"], "--log", robot["fit"], "--validate", robot["val"],
               "--out", str(out)])  # fmt: skip
    printed = capsys.readouterr()
    assert rc == 0, printed.err
    assert printed.err == ""
    for name in ("identified.urdf", "report.html", "parameters.csv", "torques.png"):
        assert (out / name).is_file(), name
        assert f"wrote {out / name}" in printed.out
    model = robot["model"]
    params = pd.read_csv(out / "parameters.csv")
    names = ad.dynamic_parameter_names(model)
    assert params["name"].tolist() == names
    identified = params["identified"].to_numpy()
    # the URDF carries the bodies and the friction of parameters.csv (not offsets and rotors)
    urdf_pi = ad.dynamic_parameters(ad.load_urdf(str(out / "identified.urdf")))
    kept = [k for k, n in enumerate(names) if not n.endswith((".offset", ".Ia"))]
    np.testing.assert_allclose(urdf_pi[kept], identified[kept], rtol=1e-9, atol=1e-12)
    # the identified parameters predict the validation log to the noise level (chi-square
    # bound of N samples of known sigma), the nominal ones do not
    log = robot["val_log"]
    y = ad.joint_torque_regressor(model, log.q, log.qd, log.qdd)
    rmse = np.sqrt(np.mean((y @ identified - log.tau) ** 2, axis=0))
    hi = np.sqrt(__import__("scipy").stats.chi2.ppf(1 - 1e-6, len(log.t)) / len(log.t))
    assert np.all(rmse < 1.1 * hi * NOISE), rmse / NOISE
    nominal = np.sqrt(
        np.mean((ad.inverse_dynamics(model, log.q, log.qd, log.qdd) - log.tau) ** 2, 0)
    )
    assert np.all(nominal > 10 * NOISE)
    # the printed verdict and the report's
    assert re.search(r"^\s+verdict\s+rmse\s+rel_rmse\s+ls_rmse\s+nominal_rmse", printed.out, re.M)
    rows = re.findall(r"^(shoulder|elbow)\s+(\w+)\s+(\S+)", printed.out, re.M)
    assert [(j, s) for j, s, _ in rows] == [("shoulder", "match"), ("elbow", "match")]
    page = (out / "report.html").read_text(encoding="utf-8")
    assert 'id="overall" data-status="match"' in page
    assert "fit (--log)" in page and "validation (--validate)" in page


def test_identify_splits_the_log_and_filters(robot, tmp_path, capsys):
    """No --validate: the log's last 30 % validates; no .qd/.qdd columns: --cutoff filters and
    differentiates."""
    model = robot["model"]
    log = synthetic_log(model, robot["pi"], n=800, duration=16.0, noise=0.0, seed=3)
    path = _csv(tmp_path / "nod.csv", model, log, derivatives=False)
    out = tmp_path / "split"
    rc = main(["identify", robot["urdf"], "--log", path, "--out", str(out), "--cutoff", "5",
               "--method", "ols"])  # fmt: skip
    printed = capsys.readouterr()
    assert rc == 0, printed.err
    m = re.search(r"from (\d+) samples .* validated on (\d+) samples \(last 30% of the log\)",
                  printed.out)  # fmt: skip
    assert m is not None, printed.out
    n_fit, n_val = int(m.group(1)), int(m.group(2))
    assert n_fit + n_val == 800 and abs(n_fit - 0.7 * 800) <= 1
    assert (out / "identified.urdf").is_file() and (out / "report.html").is_file()


def test_identify_from_currents(robot, tmp_path, capsys):
    """A log of motor currents (tau / (K N)) with --torque-constants K and --gear-ratios=N (a
    negative N: the = form) identifies what the torque log does."""
    model = robot["model"]
    k, n = 0.08, [-50.0, 30.0]
    for role in ("fit", "val"):
        table = pd.read_csv(robot[role])
        for j, c in enumerate(model.coord_names):
            table[f"{c}.current"] = table.pop(f"{c}.tau") / (k * n[j])
        table.to_csv(tmp_path / f"current_{role}.csv", index=False)
    options = ["--method", "ols", "--no-physical"]
    currents = ["--torque-constants", str(k), "--gear-ratios=-50,30"]
    runs = {}
    for name, fit, val, extra in (
        ("tau", robot["fit"], robot["val"], []),
        ("current", str(tmp_path / "current_fit.csv"), str(tmp_path / "current_val.csv"), currents),
    ):
        out = tmp_path / name
        argv = [robot["urdf"], "--log", fit, "--validate", val, "--out", str(out), *options]
        rc = main(["identify", *argv, *extra])
        assert rc in (0, 1), capsys.readouterr().err
        runs[name] = pd.read_csv(out / "parameters.csv")["identified"].to_numpy()
    capsys.readouterr()
    scale = np.abs(runs["tau"]).max()
    np.testing.assert_allclose(runs["current"], runs["tau"], rtol=0, atol=1e-9 * scale)


def _bad(tmp_path, robot):
    d = tmp_path
    empty = d / "empty.csv"
    empty.write_text("")
    header = d / "header.csv"
    header.write_text("t,shoulder,shoulder.tau,elbow,elbow.tau\n")
    text = open(robot["fit"]).read().splitlines()
    nan = d / "nan.csv"
    row = text[5].split(",")
    row[2] = "nan"
    nan.write_text("\n".join([*text[:5], ",".join(row), *text[6:]]) + "\n")
    unknown = d / "unknown.csv"
    unknown.write_text("\n".join([text[0].replace("elbow.qdd", "wrist.qdd"), *text[1:]]) + "\n")
    afile = d / "afile"
    afile.write_text("x")
    short = d / "short.csv"
    short.write_text("\n".join(text[:7]) + "\n")  # 6 samples: 4 to fit, 2 to validate
    current = d / "current.csv"
    current.write_text("\n".join([text[0].replace(".tau", ".current"), *text[1:]]) + "\n")
    fifo = d / "fifo.csv"
    os.mkfifo(fifo)
    fit, urdf = robot["fit"], robot["urdf"]
    return {
        "missing-urdf": ([str(d / "no.urdf"), "--log", fit], "no.urdf"),
        "missing-log": ([urdf, "--log", str(d / "no.csv")], "no.csv"),
        "log-directory": ([urdf, "--log", str(d)], "--log.*directory"),
        "log-fifo": ([urdf, "--log", str(fifo)], "FIFO|fifo"),
        "log-device": ([urdf, "--log", "/dev/zero"], "device"),
        "empty-csv": ([urdf, "--log", str(empty)], "empty"),
        "header-only": ([urdf, "--log", str(header)], "no data rows"),
        "nan": ([urdf, "--log", str(nan)], "row|nan|finite"),
        "unknown-joint": ([urdf, "--log", str(unknown)], "wrist.qdd"),
        "validate-directory": (
            [urdf, "--log", fit, "--validate", str(d)],
            "--validate.*directory",
        ),
        "out-is-a-file": ([urdf, "--log", fit, "--out", str(afile)], "not a folder"),
        "out-under-a-file": (
            [urdf, "--log", fit, "--out", str(afile / "x")],
            "--out.*afile",
        ),
        "cutoff": ([urdf, "--log", fit, "--cutoff", "-1"], "--cutoff"),
        "cutoff-nan": ([urdf, "--log", fit, "--cutoff", "nan"], "--cutoff"),
        "method": ([urdf, "--log", fit, "--method", "lasso"], "--method"),
        "short-to-split": ([urdf, "--log", str(short)], r"6 samples cannot be split.*--validate"),
        "current-no-ratios": (
            [urdf, "--log", str(current), "--torque-constants", "0.1"],
            "--gear-ratios is required",
        ),
        "torque-constants": ([urdf, "--log", fit, "--torque-constants", "a,b"], "'a'"),
        "gear-ratios-mixed": ([urdf, "--log", fit, "--gear-ratios", "elbow=2,3"], "none"),
    }


CASES = [
    "missing-urdf", "missing-log", "log-directory", "log-fifo", "log-device", "empty-csv",
    "header-only", "nan", "unknown-joint", "validate-directory", "out-is-a-file",
    "out-under-a-file", "cutoff", "cutoff-nan", "method", "torque-constants", "gear-ratios-mixed",
    "current-no-ratios", "short-to-split",
]  # fmt: skip


@pytest.mark.parametrize("case", CASES)
def test_identify_bad_input_exit_2(robot, tmp_path, capsys, case):
    argv, culprit = _bad(tmp_path, robot)[case]
    if "--out" not in argv:
        argv = [*argv, "--out", str(tmp_path / "out")]
    rc = main(["identify", *argv])
    printed = capsys.readouterr()
    assert rc == 2, (printed.out, printed.err)
    lines = printed.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("armdyn identify: "), printed.err
    assert "Traceback" not in printed.err
    assert re.search(culprit, lines[0]), lines[0]
    assert not (tmp_path / "out" / "report.html").exists()


def test_unconstrained_estimate_not_a_urdf_exit_1(robot, tmp_path, capsys, monkeypatch):
    """--no-physical: an estimate with a negative friction cannot be a URDF; the report is
    written, identified.urdf is not, exit code 1 with one line saying why."""
    from armdyn.identification import cli

    real = cli._identify

    def negative_friction(model, log, args):
        ident = real(model, log, args)
        ident.pi = ident.pi.copy()
        ident.pi[ad.dynamic_parameter_names(model).index("elbow.fv")] = -0.5
        return ident

    monkeypatch.setattr(cli, "_identify", negative_friction)
    out = tmp_path / "neg"
    rc = main(["identify", robot["urdf"], "--log", robot["fit"], "--validate", robot["val"],
               "--out", str(out), "--no-physical"])  # fmt: skip
    printed = capsys.readouterr()
    assert rc == 1
    lines = printed.err.strip().splitlines()
    assert len(lines) == 1 and "identified.urdf not written" in lines[0], printed.err
    assert "elbow" in lines[0]
    assert (out / "report.html").is_file() and not (out / "identified.urdf").exists()
