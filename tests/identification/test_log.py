"""armdyn.identification.log: measured motions read with strict checks, filtered (zero-phase
Butterworth) and differentiated (central differences) against closed-form derivatives (issue 35).
"""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn import _core
from armdyn.identification import MotionLog, differentiate, load_log, log_from_arrays
from armdyn.identification.log import LOG_MAX_BYTES, UNIFORM_TOLERANCE

DATA = Path(__file__).resolve().parents[1] / "data" / "urdf"
I3 = np.diag([0.01, 0.02, 0.025])
JOINTS = ["hinge", "elbow"]


def _two_links():
    """Two links on parallel hinges (coordinates 'hinge', 'elbow')."""
    b = ad.ModelBuilder()
    b.add_body("link", 1.0, I3, position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    b.add_body("forearm", 1.0, I3, position=(0.0, 0.0, -1.5))
    b.add_revolute("elbow", "link", "forearm", (0, 0, -1.0), (0, 1, 0))
    return b.finalize()


MODEL = _two_links()

# a finite Fourier series per joint: q = q0 + sum_k a_k sin(w_k t) + b_k cos(w_k t)
W = 2 * np.pi * np.array([0.2, 0.4, 0.6])
A = np.array([[0.5, -0.2, 0.1], [-0.3, 0.25, 0.05]])
B = np.array([[0.1, 0.3, -0.1], [0.2, -0.1, 0.15]])
Q0 = np.array([0.1, -0.4])


def fourier(t):
    """(q, qd, qdd, max|q'''|, max|q''''|) in closed form; the bounds per joint."""
    s, c = np.sin(np.outer(t, W)), np.cos(np.outer(t, W))
    q = Q0 + s @ A.T + c @ B.T
    qd = c @ (A * W).T - s @ (B * W).T
    qdd = -(s @ (A * W**2).T + c @ (B * W**2).T)
    amp = np.hypot(A, B)
    return q, qd, qdd, amp @ W**3, amp @ W**4


def test_differentiation_within_the_truncation_bounds():
    """Unfiltered: qd and qdd within the stencils' truncation bounds of the module docstring
    (h**2/6 |q'''| and h**2/12 |q''''| inside, h**2/3 |q'''| and 11 h**2/12 |q''''| at the
    ends), with 2 % for the higher-order terms; and the bounds are tight (the errors reach a
    third of them), so the test would see a first-order stencil."""
    h = 0.02
    t = np.arange(0.0, 10.0 + h / 2, h)
    q, qd, qdd, d3, d4 = fourier(t)
    q_f, qd_n, qdd_n = differentiate(t, q)
    np.testing.assert_array_equal(q_f, q)
    e1, e2 = np.abs(qd_n - qd), np.abs(qdd_n - qdd)
    inner1, inner2 = slice(1, -1), slice(2, -2)
    assert (e1[inner1] <= 1.02 * h**2 / 6 * d3).all()
    assert (e1[[0, -1]] <= 1.02 * h**2 / 3 * d3).all()
    assert (e2[inner2] <= 1.02 * h**2 / 12 * d4).all()
    assert (e2[[0, 1, -2, -1]] <= 1.02 * 11 * h**2 / 12 * d4).all()
    assert (e1[inner1].max(axis=0) > h**2 / 6 * d3 / 3).all()
    assert (e2[inner2].max(axis=0) > h**2 / 12 * d4 / 3).all()
    # 1-D input gives 1-D output, the same numbers
    one = differentiate(t, q[:, 1])
    np.testing.assert_allclose(one[2], qdd_n[:, 1], rtol=0, atol=1e-12)


def test_second_order_on_a_non_uniform_grid():
    """Jittered sampling (no filter: allowed): halving the step divides the qd error by ~4
    (numpy.gradient: second order on any grid), the qdd error by ~2 (first order there)."""
    rng = np.random.default_rng(3)
    errors = []
    for h in (0.02, 0.01):
        t = np.arange(0.0, 10.0, h) + rng.uniform(-0.2, 0.2, round(10.0 / h)) * h
        t[0] = 0.0
        q, qd, qdd, _, _ = fourier(t)
        _, qd_n, qdd_n = differentiate(t, q)
        errors.append((np.abs(qd_n - qd).max(), np.abs(qdd_n - qdd)[2:-2].max()))
    assert errors[0][0] / errors[1][0] > 3.0
    # the three-point second difference on a jittered grid: first order (error ~ h q''')
    assert 1.4 < errors[0][1] / errors[1][1] < 2.8


def test_filter_is_zero_phase_and_trim_removes_edge_transients():
    """A 10 Hz cutoff at 200 Hz sampling on the noise-free motion (0.2-0.6 Hz): inside, q, qd
    and qdd as the closed form (the pass band is flat there); at the ends the filter's
    transient is large (measured: 24 % of the peak qdd within 0.5 / cutoff of the start), and
    trimming 3 / cutoff brings qdd within 0.1 % of its peak (measured: 0.086 %), the reason for
    the trim the docstring suggests."""
    h, cutoff = 0.005, 10.0
    t = np.arange(0.0, 10.0 + h / 2, h)
    q, qd, qdd, _, _ = fourier(t)
    q_f, qd_n, qdd_n = differentiate(t, q, cutoff=cutoff)
    peak = np.abs(qdd).max()
    edge = np.abs(qdd_n - qdd)[: int(0.5 / cutoff / h)].max()
    assert edge > 0.05 * peak  # the transient the trim is for
    keep = (t >= 3 / cutoff) & (t <= t[-1] - 3 / cutoff)
    assert np.abs(q_f - q)[keep].max() <= 1e-5
    assert np.abs(qd_n - qd)[keep].max() <= 1e-4
    assert np.abs(qdd_n - qdd)[keep].max() <= 1e-3 * peak
    # zero phase: no lag between the filtered and the true q (a delay of one sample would
    # show as |qd| h = 0.5 % error)
    lag = np.abs(q_f - q)[keep].max() / (np.abs(qd).max() * h)
    assert lag < 0.01
    # the same through log_from_arrays with trim
    log = log_from_arrays(MODEL, t, q, q * 2.0, cutoff=cutoff, trim=3 / cutoff, filter_tau=True)
    np.testing.assert_array_equal(log.t, t[keep])
    np.testing.assert_allclose(log.qdd, qdd_n[keep], rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.tau, 2.0 * q_f[keep], rtol=0, atol=1e-12)  # same filter
    assert "cutoff 10 Hz" in log.processing and "trimmed" in log.processing


def test_filtering_reduces_the_noise_in_qdd():
    """Encoder-like noise (sigma 1e-4 rad) at 200 Hz: unfiltered, qdd is noise (sqrt(6) sigma /
    h**2 ~ 10 rad/s**2); filtered at 5 Hz (trim 3 / cutoff) it is within 1 % of the peak
    acceleration. Measured (this seed): RMS qdd error 9.75 unfiltered, 0.0086 filtered, a
    factor 1130 (asserted > 500); largest filtered error 0.69 % of the peak. The tau noise
    (sigma 0.5 N m) falls by the same filter: RMS 0.50 -> 0.12, a factor 4.2 (white noise over
    100 Hz kept over ~5 Hz: sqrt(20) = 4.5; asserted > 3.5)."""
    rng = np.random.default_rng(0)
    h = 0.005
    t = np.arange(0.0, 10.0 + h / 2, h)
    q, _, qdd, _, _ = fourier(t)
    tau = np.column_stack([np.sin(t), np.cos(2 * t)])
    qn = q + rng.normal(0.0, 1e-4, q.shape)
    taun = tau + rng.normal(0.0, 0.5, tau.shape)
    raw = log_from_arrays(MODEL, t, qn, taun)
    filt = log_from_arrays(MODEL, t, qn, taun, cutoff=5.0, trim=0.6, filter_tau=True)
    keep = (t >= 0.6) & (t <= t[-1] - 0.6)
    rms_raw = np.sqrt(np.mean((raw.qdd[keep] - qdd[keep]) ** 2))
    rms_filt = np.sqrt(np.mean((filt.qdd - qdd[keep]) ** 2))
    assert rms_raw / rms_filt > 500.0, (rms_raw, rms_filt)
    assert np.abs(filt.qdd - qdd[keep]).max() <= 0.01 * np.abs(qdd).max()
    tau_raw = np.sqrt(np.mean((raw.tau[keep] - tau[keep]) ** 2))
    tau_filt = np.sqrt(np.mean((filt.tau - tau[keep]) ** 2))
    assert tau_raw / tau_filt > 3.5


def test_filtering_tau_biases_a_fit_with_coulomb_friction():
    """The reason for filter_tau=False: the two-link arm with Coulomb friction (2 and 1 N m),
    its exact torques along the Fourier motion at 100 Hz, q filtered at 4 Hz, and a
    least-squares fit of pi on the regressor. With tau filtered too, the Coulomb steps are
    smeared and the fit cannot follow (measured residual RMS 0.33 and 0.17 N m per joint); with
    tau as logged it can (0.0039 and 0.0015 N m, the differentiation error of q)."""
    b = ad.ModelBuilder()
    b.add_body("link", 1.0, I3, position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    b.add_body("forearm", 1.0, I3, position=(0.0, 0.0, -1.5))
    b.add_revolute("elbow", "link", "forearm", (0, 0, -1.0), (0, 1, 0))
    b.add_joint_friction("hinge", viscous=0.5, coulomb=2.0)
    b.add_joint_friction("elbow", viscous=0.3, coulomb=1.0)
    rough = b.finalize()
    h = 0.01
    t = np.arange(0.0, 10.0 + h / 2, h)
    q, qd, qdd, _, _ = fourier(t)
    tau = ad.inverse_dynamics(rough, q, qd, qdd)
    residual = {}
    for filter_tau in (True, False):
        log = log_from_arrays(rough, t, q, tau, cutoff=4.0, trim=0.75, filter_tau=filter_tau)
        y = ad.joint_torque_regressor(rough, log.q, log.qd, log.qdd).reshape(-1, 28)
        fit = np.linalg.lstsq(y, log.tau.reshape(-1), rcond=None)[0]
        r = (y @ fit - log.tau.reshape(-1)).reshape(-1, 2)
        residual[filter_tau] = np.sqrt(np.mean(r**2, axis=0))
        if not filter_tau:
            np.testing.assert_allclose(log.tau, tau[(t >= 0.75) & (t <= t[-1] - 0.75)])
            assert "q low-pass filtered" in log.processing
    assert (residual[True] > 0.1).all()
    assert (residual[False] < 0.01).all()


def _log_frame(n=50, h=0.01):
    t = np.arange(n) * h
    q, qd, qdd, _, _ = fourier(t)
    cols = {"t": t}
    for j, name in enumerate(JOINTS):
        cols[name] = q[:, j]
    for j, name in enumerate(JOINTS):
        cols[f"{name}.tau"] = 3.0 * q[:, j] + 0.5
    return pd.DataFrame(cols), q, qd, qdd


def test_round_trip_through_csv(tmp_path):
    frame, q, _, _ = _log_frame()
    log = load_log(frame, MODEL, cutoff=None)
    assert isinstance(log, MotionLog) and log.joint_names == JOINTS
    np.testing.assert_array_equal(log.q, q)
    path = tmp_path / "log.csv"
    log.to_csv(path)
    back = load_log(path, MODEL)
    for name in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(getattr(back, name), getattr(log, name))
    assert "qd, qdd as given" in back.processing
    # a dict of arrays reads the same
    same = load_log({c: frame[c].to_numpy() for c in frame.columns}, MODEL)
    np.testing.assert_array_equal(same.qdd, log.qdd)
    with pytest.raises(ValueError):
        log.q[0, 0] = 1.0  # read-only


def test_split_and_select():
    frame, _, _, _ = _log_frame(n=100)
    log = load_log(frame, MODEL)
    fit, val = log.split(0.7)
    assert len(fit) + len(val) == 100
    assert fit.t[-1] < 0.7 * 0.99 <= val.t[0]
    np.testing.assert_array_equal(np.concatenate([fit.tau, val.tau]), log.tau)
    part = log.select(slice(10, 20))
    np.testing.assert_array_equal(part.q, log.q[10:20])
    with pytest.raises(ad.ModelError, match="fraction must be in"):
        log.split(1.0)
    with pytest.raises(ad.ModelError, match="no sample selected"):
        log.select(np.zeros(100, dtype=bool))
    with pytest.raises(ad.ModelError, match="mask has shape"):
        log.select(np.ones(5, dtype=bool))
    with pytest.raises(ad.ModelError, match=r"at least 4 samples, got 2"):
        log.select(slice(0, 2))
    with pytest.raises(ad.ModelError, match=r"tau must have shape \(100, 2\)"):
        MotionLog(log.t, log.q, log.qd, log.qdd, log.tau[:, :1], JOINTS, "by hand")
    with pytest.raises(ad.ModelError, match=r"t must be strictly increasing"):
        MotionLog(log.t[::-1], log.q, log.qd, log.qdd, log.tau, JOINTS, "by hand")


def test_current_to_torque():
    """tau = gear_ratio * k_t * current [* efficiency]; dict or per-coordinate arrays; a negative
    ratio reverses the motor; a joint may log torque while another logs current."""
    frame, _, _, _ = _log_frame()
    frame = frame.rename(columns={"hinge.tau": "hinge.current", "elbow.tau": "elbow.current"})
    cur = frame[["hinge.current", "elbow.current"]].to_numpy()
    log = load_log(
        frame, MODEL, torque_constants=[0.1, 0.2], gear_ratios={"hinge": 100, "elbow": -50}
    )
    np.testing.assert_allclose(log.tau, cur * [10.0, -10.0], rtol=1e-15)
    log = load_log(
        frame,
        MODEL,
        torque_constants={"hinge": 0.1, "elbow": 0.2},
        gear_ratios=[100, 50],
        efficiency=0.9,
    )
    np.testing.assert_allclose(log.tau, cur * [9.0, 9.0], rtol=1e-15)
    assert "* efficiency" in log.processing
    mixed = frame.rename(columns={"elbow.current": "elbow.tau"})
    log = load_log(mixed, MODEL, torque_constants={"hinge": 0.1}, gear_ratios={"hinge": 100})
    np.testing.assert_allclose(log.tau, cur * [10.0, 1.0], rtol=1e-15)


def test_model_with_actuators_is_taken():
    """A model with a gear-reduced actuator (its rotor a body of the model, so not a
    joint-space tree for the simulator) logs its coordinates as any fixed-base model."""
    b = ad.ModelBuilder()
    b.add_body("link", 1.0, I3, position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    b.add_body("forearm", 1.0, I3, position=(0.0, 0.0, -1.5))
    b.add_revolute("elbow", "link", "forearm", (0, 0, -1.0), (0, 1, 0))
    b.add_actuator("elbow", 50.0, 1e-4)
    geared = b.finalize()
    assert not geared.joint_space and geared.coord_names == JOINTS
    frame, q, _, _ = _log_frame()
    np.testing.assert_array_equal(load_log(frame, geared).q, q)


def test_floating_base_is_refused():
    floating = ad.urdf_builder(str(DATA / "arm6.urdf"), fixed_base=False).finalize()
    frame, _, _, _ = _log_frame()
    with pytest.raises(ad.ModelError, match="floating base"):
        load_log(frame, floating)
    with pytest.raises(ad.ModelError, match="floating base"):
        log_from_arrays(floating, [0, 1, 2, 3], np.zeros((4, 13)), np.zeros((4, 12)))


# --- hostile input --------------------------------------------------------------------------


def _csv(tmp_path, text, name="log.csv", mode="w"):
    path = tmp_path / name
    if mode == "wb":
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return path


GOOD = "t,hinge,elbow,hinge.tau,elbow.tau\n" + "".join(
    f"{0.01 * i},{0.1 * i},{-0.1 * i},{i},{2 * i}\n" for i in range(8)
)


def _bad(tmp_path, text, pattern, **kw):
    with pytest.raises(ad.ModelError, match=pattern):
        load_log(_csv(tmp_path, text), MODEL, **kw)


def test_good_csv_reads(tmp_path):
    log = load_log(_csv(tmp_path, GOOD), MODEL)
    np.testing.assert_allclose(log.tau[:, 1], 2 * np.arange(8))
    np.testing.assert_allclose(log.qd, [[10.0, -10.0]] * 8, rtol=1e-9)  # exact for a line


@pytest.mark.parametrize(
    ("edit", "pattern"),
    [
        (lambda s: s.replace("elbow.tau", "wrist.tau"), r"unknown column 'wrist.tau'"),
        (lambda s: s.replace(",elbow,", ",hinge,"), r"column 'hinge' more than once"),
        (lambda s: s.replace("t,", "time,", 1), r"unknown column 'time'"),
        (
            lambda s: s.replace("elbow.tau", "elbow.current").replace("hinge.tau", "elbow.tau"),
            r"joint 'hinge' needs one of the columns 'hinge.tau' or 'hinge.current'",
        ),
        (
            lambda s: s.replace("0.03,", "nan,", 1),
            r"column 't', row 3 \(line 5\) is 'nan', not finite",
        ),
        (lambda s: s.replace(",0.2,", ",inf,", 1), r"column 'hinge', row 2 \(line 4\) is 'inf'"),
        (lambda s: s.replace(",0.2,", ",,", 1), r"column 'hinge', row 2 \(line 4\) is empty"),
        (lambda s: s.replace(",0.2,", ",abc,", 1), r"row 2 \(line 4\) is 'abc', not a number"),
        (lambda s: s.replace("0.03,", "0.02,", 1), r"strictly increasing, but row 3 \(t = 0.02\)"),
        (lambda s: s.replace(",", ";"), r"comma-separated; .* separated by ';'"),
        (lambda s: s.replace(",", "\t"), r"comma-separated; .* separated by '\\t'"),
        (lambda s: s.split("\n")[0] + "\n", r"header but no data rows"),
        (lambda s: "", r"is empty"),
        (lambda s: "\n \n", r"is empty"),
        (lambda s: s + "0.08,1,2,3,4,5\n", r"not a valid CSV table"),
        (lambda s: s.replace("\n", ",\n", 1), r"unknown column ''"),
        (
            lambda s: s.replace("\n", "\n\n", 3).replace("0.03,", "x,", 1),
            r"row 3 \(line 8\) is 'x'",  # blank lines skipped, the file's line named
        ),
    ],
    ids=[
        "unknown-joint",
        "duplicate",
        "no-t",
        "no-torque",
        "nan-t",
        "inf-cell",
        "empty-cell",
        "text-cell",
        "t-not-increasing",
        "semicolon",
        "tab",
        "header-only",
        "empty",
        "blank",
        "ragged",
        "extra-header",
        "blank-lines",
    ],
)
def test_hostile_csv(tmp_path, edit, pattern):
    _bad(tmp_path, edit(GOOD), pattern)


def test_missing_and_partial_columns(tmp_path):
    _bad(tmp_path, GOOD.replace(",elbow,", ",elbow.qd,"), r"missing column 'elbow'")
    frame, _, _, _ = _log_frame()
    frame["hinge.qd"] = 0.0
    with pytest.raises(ad.ModelError, match=r"column 'elbow.qd' is missing"):
        load_log(frame, MODEL)
    frame = frame.drop(columns="hinge.qd")
    frame["elbow.current"] = 1.0
    with pytest.raises(ad.ModelError, match=r"joint 'elbow' .* the log has both"):
        load_log(frame, MODEL)


def test_current_needs_constants(tmp_path):
    text = GOOD.replace("hinge.tau", "hinge.current")
    _bad(tmp_path, text, r"current columns \(hinge\): torque_constants is required")
    _bad(tmp_path, text, r"gear_ratios is required", torque_constants=[0.1, 0.1])
    _bad(
        tmp_path,
        text,
        r"torque_constants\['hinge'\] = -0.1 must be > 0",
        torque_constants=[-0.1, 0.1],
        gear_ratios=[1, 1],
    )
    _bad(
        tmp_path,
        text,
        r"gear_ratios\['hinge'\] = 0.0 must be finite and non-zero",
        torque_constants=[0.1, 0.1],
        gear_ratios=[0, 1],
    )
    _bad(
        tmp_path,
        text,
        r"efficiency\['hinge'\] = 1.5 must be in \(0, 1\]",
        torque_constants=[0.1, 0.1],
        gear_ratios=[1, 1],
        efficiency=1.5,
    )
    _bad(
        tmp_path,
        text,
        r"torque_constants has the key 'elbow', not a joint with a current",
        torque_constants={"hinge": 0.1, "elbow": 0.1},
        gear_ratios=[1, 1],
    )
    _bad(
        tmp_path,
        text,
        r"torque_constants needs 2 values",
        torque_constants=[0.1],
        gear_ratios=[1, 1],
    )
    _bad(
        tmp_path,
        GOOD,
        r"torque_constants given, but the log has no current column",
        torque_constants=[0.1, 0.1],
    )


def test_non_utf8(tmp_path):
    path = _csv(tmp_path, GOOD.replace("hinge", "h\xe9", 1).encode("latin-1"), mode="wb")
    with pytest.raises(ad.ModelError, match=r"is not UTF-8 text \(byte 3, line 1\)"):
        load_log(path, MODEL)


def test_filtering_checks(tmp_path):
    t = np.arange(100) * 0.01
    q = np.zeros((100, 2))
    with pytest.raises(
        ad.ModelError, match=r"cutoff 50.0 Hz is not below the Nyquist frequency 50 Hz"
    ):
        log_from_arrays(MODEL, t, q, q, cutoff=50.0)
    with pytest.raises(ad.ModelError, match=r"cutoff must be a positive"):
        log_from_arrays(MODEL, t, q, q, cutoff=-1.0)
    with pytest.raises(ad.ModelError, match=r"filter order must be an integer"):
        log_from_arrays(MODEL, t, q, q, cutoff=5.0, filter_order=2.5)
    jitter = t.copy()
    jitter[40:] += 0.0002  # the interval 39 -> 40 is 2 % long
    with pytest.raises(
        ad.ModelError, match=r"uniform sampling, but the interval from row 39 .* to row 40"
    ):
        log_from_arrays(MODEL, jitter, q, q, cutoff=5.0)
    jitter[40:] -= 0.0002 - UNIFORM_TOLERANCE * 0.01 * 0.5  # within the tolerance: accepted
    log_from_arrays(MODEL, jitter, q, q, cutoff=5.0)
    log_from_arrays(MODEL, jitter + np.r_[0, 0.004 * np.ones(99)], q, q)  # no filter: any grid
    with pytest.raises(ad.ModelError, match=r"needs more than 15 samples, the log has 10"):
        log_from_arrays(MODEL, t[:10], q[:10], q[:10], cutoff=5.0)
    with pytest.raises(ad.ModelError, match=r"at least 4 samples, got 3"):
        log_from_arrays(MODEL, t[:3], q[:3], q[:3])
    with pytest.raises(ad.ModelError, match=r"trim 0.6 s at each end leaves 0 samples"):
        log_from_arrays(MODEL, t, q, q, trim=0.6)
    with pytest.raises(ad.ModelError, match=r"tau must have shape \(100, 2\), got \(100, 3\)"):
        log_from_arrays(MODEL, t, q, np.zeros((100, 3)))
    bad = q.copy()
    bad[7, 1] = np.nan
    with pytest.raises(ad.ModelError, match=r"q at row 7, column 1 is nan, not finite"):
        log_from_arrays(MODEL, t, bad, q)


def test_special_files_are_refused(tmp_path):
    with pytest.raises(ad.ModelError, match=r"is a directory, not a regular file"):
        load_log(tmp_path, MODEL)
    with pytest.raises(ad.ModelError, match=r"'/dev/zero' is a character device, not a regular"):
        load_log("/dev/zero", MODEL)
    with pytest.raises(FileNotFoundError):
        load_log(tmp_path / "missing.csv", MODEL)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_fifo_is_refused_without_blocking(tmp_path):
    """In a child process with a timeout: opening the FIFO would wait for a writer forever."""
    fifo = tmp_path / "log.csv"
    os.mkfifo(fifo)
    script = textwrap.dedent(
        f"""
        import armdyn as ad
        from armdyn.identification import load_log
        b = ad.ModelBuilder()
        b.add_body("link", 1.0, [[1, 0, 0], [0, 1, 0], [0, 0, 1]], position=(0, 0, -0.5))
        b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
        try:
            load_log({str(fifo)!r}, b.finalize())
        except ad.ModelError as err:
            print(err)
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "PYTHONPATH": str(Path(ad.__file__).resolve().parents[1])},
        check=True,
    ).stdout
    assert "log.csv' is a FIFO (named pipe), not a regular file" in out


def test_file_over_the_size_cap_is_refused(tmp_path):
    path = tmp_path / "huge.csv"
    with open(path, "wb") as f:
        f.truncate(LOG_MAX_BYTES + 1)  # sparse: no disk space used, and never read
    assert LOG_MAX_BYTES == _core.URDF_MAX_BYTES == 64 * 2**20
    with pytest.raises(ad.ModelError, match=rf"{LOG_MAX_BYTES + 1} bytes, more than the limit"):
        load_log(path, MODEL)


def test_bad_sources_and_models():
    with pytest.raises(ad.ModelError, match=r"source must be a CSV path, a pandas DataFrame"):
        load_log(42, MODEL)
    with pytest.raises(ad.ModelError, match=r"model must be an armdyn.Model"):
        load_log({}, "robot.urdf")
    frame = pd.DataFrame(np.zeros((5, 5)), columns=["t", "hinge", "hinge", "a", "b"])
    with pytest.raises(ad.ModelError, match=r"DataFrame has the column 'hinge' more than once"):
        load_log(frame, MODEL)
    with pytest.raises(ad.ModelError, match=r"column 't' must be 1-dimensional"):
        load_log({"t": np.zeros((2, 2))}, MODEL)
    frame, _, _, _ = _log_frame()
    frame.loc[4, "elbow.tau"] = np.inf
    with pytest.raises(ad.ModelError, match=r"DataFrame: column 'elbow.tau', row 4 is 'inf'"):
        load_log(frame, MODEL)
