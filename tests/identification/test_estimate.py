"""armdyn.identification.identify: least squares, uncertainty, outliers and the physically
consistent estimate on synthetic logs of perturbed robots (issue 35).

The "measured" robot: the URDF with every link's mass, centre of mass and inertia perturbed,
viscous and Coulomb friction on every joint and a gear-reduced rotor (reflected inertia Ia) on
every revolute joint (benchmarks/identification_fit.robot); the log: a random Fourier motion
with exact q, qd, qdd and the true model's inverse_dynamics torques (plus Gaussian noise of a
known standard deviation per joint). The references are independent: the true model's
parameters (its own dynamic_parameters mapped by the base-parameter matrix) and its
inverse_dynamics on another motion.
"""

import armdyn as ad
import numpy as np
import pytest
from armdyn import identification
from armdyn.identification import identify, is_physical, physical_violations

from benchmarks import common
from benchmarks import identification_fit as F

pytestmark = pytest.mark.skipif(common.robots_dir() is None, reason="needs example-robot-data")


class _Robot:
    def __init__(self, name, seed=0):
        self.nominal, self.true, self.pi_true, self.limits = F.robot(name, seed)
        self.coords = list(self.nominal.coord_names)
        self.base = F.base_for(self.nominal)
        self.beta_true = self.base.beta(self.pi_true)
        _, clean = self.log(300, seed=11)
        # noise: 2 % of each joint's torque rms + 0.01 N m (different per joint: WLS matters)
        self.noise = 0.02 * np.sqrt(np.mean(clean**2, axis=0)) + 0.01

    def log(self, n, *, seed, noise=None):
        return F.synthetic_log(self.true, self.limits, self.coords, n, seed=seed, noise=noise)


_CACHE = {}


def _robot(name):
    if name not in _CACHE:
        _CACHE[name] = _Robot(name)
    return _CACHE[name]


def _rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


# ------------------------------------------------------------------------------ noise-free
@pytest.mark.parametrize("name", ["ur5", "panda"])
@pytest.mark.parametrize("method", ["ols", "wls"])
def test_noise_free_recovers_base_parameters(name, method):
    r = _robot(name)
    log, _ = r.log(400, seed=1)
    fit = identify(r.nominal, log, base=r.base, method=method, physical=False)
    assert _rel(fit.beta_ls, r.beta_true) < 1e-8
    big = np.abs(r.beta_true) > 1e-6 * np.abs(r.beta_true).max()
    np.testing.assert_allclose(fit.beta_ls[big], r.beta_true[big], rtol=1e-8)
    assert fit.outliers.size == 0  # an exact fit: no outlier rejection
    assert np.all(fit.rmse < 1e-9 * np.abs(log.tau).max())
    # the identified model predicts the true model's torques on another motion
    val, tau_val = r.log(50, seed=2)
    pred = fit.predict(val.q, val.qd, val.qdd)
    np.testing.assert_allclose(pred, tau_val, rtol=0, atol=1e-8 * np.abs(tau_val).max())
    np.testing.assert_allclose(
        fit.predict(val.q[3], val.qd[3], val.qdd[3]), tau_val[3], atol=1e-8 * np.abs(tau_val).max()
    )


def test_noise_free_physical_estimate_of_a_physical_truth():
    r = _robot("ur5")
    log, _ = r.log(400, seed=1)
    for solver in ("sdp", "log-cholesky"):
        fit = identify(r.nominal, log, base=r.base, solver=solver)
        assert is_physical(r.nominal, fit.pi), (solver, physical_violations(r.nominal, fit.pi))
        # the truth is feasible: the consistent estimate's torques stay at the truth's to
        # ~1e-6 of the torque scale (the regulariser, 1e-4 of the data's smallest curvature,
        # and the solver tolerance)
        assert np.all(fit.rmse < 1e-5 * np.sqrt(np.mean(log.tau**2))), (solver, fit.rmse)


# ---------------------------------------------------------------------------------- noise
def _noisy(name):
    key = name + "/noisy"
    if key not in _CACHE:
        r = _robot(name)
        log, _ = r.log(1500, seed=1, noise=r.noise)
        val, _ = r.log(1500, seed=2, noise=r.noise)
        ls = identify(r.nominal, log, base=r.base, physical=False)
        _CACHE[key] = r, log, val, ls
    return _CACHE[key]


@pytest.fixture(params=["ur5", "panda"])
def noisy(request):
    return _noisy(request.param)


def _val_rmse(fit, val):
    return np.sqrt(np.mean((val.tau - fit.predict(val.q, val.qd, val.qdd)) ** 2, axis=0))


def test_noise_validation_rmse_is_the_noise_level(noisy):
    r, _, val, ls = noisy
    ratio = _val_rmse(ls, val) / r.noise
    # the validation residual = the noise + the estimate's error (~ n_base / rows of it):
    # within 10 % of the noise level on every joint
    assert np.all(np.abs(ratio - 1.0) < 0.10), ratio
    # the per-joint noise the WLS estimated (Gautier's weights) is the true one: 1500 samples
    # give it to ~2 % (1 / sqrt(2 n)), the 3-sigma outlier rejection truncates ~1.5 %
    np.testing.assert_allclose(ls.sigma / r.noise, 1.0, atol=0.06)


def test_noise_true_base_parameters_within_three_std(noisy):
    r, _, _, ls = noisy
    z = (ls.beta_ls - r.beta_true) / ls.beta_std
    # z ~ N(0, 1) when beta_std is right (the errors are Gaussian, the regressor exact): a
    # |z| > 3 has probability 0.27 %, ~0.2 of 58 (UR5) or 78 (Panda) parameters; >= 95 %
    # within allows 2 / 3 such, and a beta_std too small by 2x would leave ~13 % outside
    assert np.mean(np.abs(z) <= 3.0) >= 0.95, np.sort(np.abs(z))[-5:]
    # and the std is not inflated: z's spread is that of a unit normal (58 or 78 draws)
    assert 0.7 < np.std(z) < 1.3


def test_beta_std_is_the_weighted_covariance(noisy):
    # second method: the covariance from the explicit stacked weighted regressor (numpy inv)
    r, log, _, ls = noisy
    keep = np.setdiff1d(np.arange(ls.n_samples), ls.outliers)
    y = ad.joint_torque_regressor(r.nominal, log.q[keep], log.qd[keep], log.qdd[keep])
    yb = y[..., r.base.independent]
    w = ls.info["weights"]
    a = (yb * w[None, :, None]).reshape(-1, yb.shape[2])
    res = (log.tau[keep] - yb @ ls.beta_ls) * w
    s2 = np.sum(res**2) / (a.shape[0] - a.shape[1])
    std = np.sqrt(s2 * np.diag(np.linalg.inv(a.T @ a)))
    np.testing.assert_allclose(ls.beta_std, std, rtol=1e-6)


@pytest.mark.parametrize(
    "name, solver",
    # log-Cholesky on the Panda: in benchmarks/identification_fit.py (tens of seconds loaded)
    [("ur5", "sdp"), ("panda", "sdp"), ("ur5", "log-cholesky")],
)
def test_noise_physical_estimate_consistent_and_close(name, solver):
    r, log, val, ls = _noisy(name)
    fit = identify(r.nominal, log, base=r.base, solver=solver)
    assert fit.physical and fit.solver == solver
    assert physical_violations(r.nominal, fit.pi) == []
    np.testing.assert_array_equal(fit.beta_ls, ls.beta_ls)
    np.testing.assert_allclose(fit.beta, r.base.beta(fit.pi), rtol=1e-12, atol=1e-12)
    # its RMSE within 5 % of the unconstrained one, on the fit data and on another motion
    assert np.all(fit.rmse <= 1.05 * ls.rmse), fit.rmse / ls.rmse
    assert np.all(_val_rmse(fit, val) <= 1.05 * _val_rmse(ls, val))


def test_physical_estimate_enforces_the_constraints():
    # torques of a non-physical pi (the elbow's viscous friction -0.5 N m s, identifiable on its
    # own): least squares recovers it, the consistent estimate holds fv at 0
    r = _robot("ur5")
    pi_bad = r.pi_true.copy()
    k = r.base.param_names.index("elbow_joint.fv")
    pi_bad[k] = -0.5
    log, _ = r.log(400, seed=1)
    y = ad.joint_torque_regressor(r.nominal, log.q, log.qd, log.qdd)
    bad = _log_with(log, tau=y @ pi_bad)
    ls = identify(r.nominal, bad, base=r.base, physical=False)
    assert "elbow_joint.fv = -0.5 is negative" in physical_violations(r.nominal, ls.pi)
    for solver in ("sdp", "log-cholesky"):
        fit = identify(r.nominal, bad, base=r.base, solver=solver)
        assert is_physical(r.nominal, fit.pi)
        assert abs(fit.pi[k]) < 1e-6
        assert fit.rmse[r.coords.index("elbow_joint")] > 1e-3


def test_outliers_removed_and_reported():
    r = _robot("ur5")
    log, _ = r.log(1500, seed=1, noise=r.noise)
    spikes = np.array([100, 555, 1203])
    tau = log.tau.copy()
    tau[spikes, 2] += 200.0 * r.noise[2]
    spiked = _log_with(log, tau=tau)
    clean = identify(r.nominal, log, base=r.base, physical=False)
    fit = identify(r.nominal, spiked, base=r.base, physical=False)
    raw = identify(r.nominal, spiked, base=r.base, physical=False, outlier_threshold=None)
    assert set(spikes) <= set(fit.outliers.tolist())
    assert raw.outliers.size == 0
    # the Gaussian tail's share: P(any of 6 joints beyond 3 sigma) = 1.6 % of 1500 = 24
    assert fit.outliers.size < 60
    # rejected, the spikes leave the estimate where the clean log's is (within a fraction of
    # its standard deviation); kept, they move it by several
    shift = np.abs(fit.beta_ls - clean.beta_ls) / clean.beta_std
    shift_raw = np.abs(raw.beta_ls - clean.beta_ls) / clean.beta_std
    assert shift.max() < 0.5 and shift_raw.max() > 2.0, (shift.max(), shift_raw.max())


def test_without_friction_and_offsets_columns():
    # a truth without friction or rotors: base parameters without the friction and offset
    # columns (Ia stays: an inertia); fv, fc and the offsets stay at the nominal model's (zero)
    r = _robot("ur5")
    b = ad.urdf_builder(F.perturbed_urdf(common.robot_urdf("ur5"), 0))
    true = b.finalize()
    base = F.base_for(r.nominal, friction=False, offsets=False)
    log, _ = F.synthetic_log(true, r.limits, r.coords, 300, seed=4)
    fit = identify(r.nominal, log, base=base, physical=False, friction=False, offsets=False)
    assert _rel(fit.beta_ls, base.beta(ad.dynamic_parameters(true))) < 1e-8
    held = [n.endswith((".fv", ".fc", ".offset")) for n in base.param_names]
    assert sum(held) == 3 * len(r.coords)
    np.testing.assert_array_equal(fit.pi[held], 0.0)


def test_tables():
    r = _robot("ur5")
    log, _ = r.log(300, seed=1, noise=r.noise)
    fit = identify(r.nominal, log, base=r.base)
    t = fit.table()
    assert list(t.columns) == ["name", "nominal", "ls", "std", "identified"]
    assert t["name"].tolist() == list(r.base.names)
    np.testing.assert_array_equal(t["ls"], fit.beta_ls)
    np.testing.assert_array_equal(t["std"], fit.beta_std)
    np.testing.assert_array_equal(t["identified"], fit.beta)
    np.testing.assert_allclose(t["nominal"], r.base.matrix @ ad.dynamic_parameters(r.nominal))
    p = fit.parameters()
    assert p["name"].tolist() == list(ad.dynamic_parameter_names(r.nominal))
    np.testing.assert_array_equal(p["identified"], fit.pi)


@pytest.mark.skipif(
    not hasattr(identification, "with_parameters"), reason="i35-model (export) not merged yet"
)
def test_identified_model_has_the_identified_parameters():
    r = _robot("ur5")
    log, _ = r.log(300, seed=1, noise=r.noise)
    fit = identify(r.nominal, log, base=r.base)
    model = fit.identified_model()
    pi = fit.pi.copy()
    pi[[n.endswith(".offset") for n in fit.base.param_names]] = 0.0
    np.testing.assert_allclose(ad.dynamic_parameters(model), pi, rtol=1e-12, atol=1e-12)


def test_default_base_is_base_parameters():
    r = _robot("ur5")
    log, _ = r.log(300, seed=1)
    fit = identify(r.nominal, log, physical=False, friction=False)
    assert fit.base.names == identification.base_parameters(r.nominal, friction=False).names
    assert not any(n.endswith((".fv", ".fc")) for n in fit.base.names)
    assert fit.base.names != r.base.names


# ------------------------------------------------------------------------- hostile inputs
def _log_with(log, **kw):
    fields = {k: getattr(log, k) for k in ("t", "q", "qd", "qdd", "tau", "joint_names")}
    fields.update(kw)
    return F.SyntheticLog(**fields)


def test_log_of_another_model():
    ur5, panda = _robot("ur5"), _robot("panda")
    log, _ = ur5.log(50, seed=1)
    with pytest.raises(ad.ModelError, match=r"log.joint_names .* do not match .*panda_joint1"):
        identify(panda.nominal, log, base=panda.base)


def test_base_of_another_model():
    ur5, panda = _robot("ur5"), _robot("panda")
    log, _ = ur5.log(50, seed=1)
    with pytest.raises(ad.ModelError, match="base parameters of another model"):
        identify(ur5.nominal, log, base=panda.base)


def test_too_few_samples_names_the_rank_deficiency():
    r = _robot("ur5")
    log, _ = r.log(5, seed=1)  # 5 samples x 6 joints = 30 rows < n_base
    with pytest.raises(
        ad.SolverError,
        match=rf"rank deficient: the log excites only 30 of the {r.base.rank} base parameters"
        r" \(.* over 5 samples, 30 rows; .*\)\; the least excited: .*fourier_excitation",
    ):
        identify(r.nominal, log, base=r.base)
    log, _ = r.log(12, seed=1)  # enough rows, not enough distinct states
    with pytest.raises(ad.SolverError, match=r"excites only \d+ of the 5\d base parameters"):
        identify(r.nominal, log, base=r.base)


def test_all_zero_motion_is_rank_deficient():
    r = _robot("ur5")
    log, _ = r.log(100, seed=1)
    z = np.zeros_like(log.qd)
    tau = np.array([ad.inverse_dynamics(r.true, q, z[0], z[0]) for q in np.zeros_like(log.q)])
    still = _log_with(log, q=np.zeros_like(log.q), qd=z, qdd=z, tau=tau)
    with pytest.raises(ad.SolverError, match=r"rank deficient.*least excited"):
        identify(r.nominal, still, base=r.base)


def test_nan_in_the_log_named():
    r = _robot("ur5")
    log, _ = r.log(100, seed=1)
    tau = log.tau.copy()
    tau[7, 2] = np.nan
    with pytest.raises(ad.ModelError, match=r"log.tau is not finite at row 7, joint elbow_joint"):
        identify(r.nominal, _log_with(log, tau=tau), base=r.base)
    with pytest.raises(ad.ModelError, match=r"log.qd must have shape \(100, 6\)"):
        identify(r.nominal, _log_with(log, qd=log.qd[:, :5]), base=r.base)


def test_a_joint_with_zero_residual():
    # noise on every joint but the wrist_3: its residual is zero to round-off, a weight of
    # 1/0; the floor (1e-3 of the largest sigma) keeps the fit finite and correct
    r = _robot("ur5")
    noise = r.noise.copy()
    noise[5] = 0.0
    log, _ = r.log(1500, seed=1, noise=noise)
    fit = identify(r.nominal, log, base=r.base, physical=False)
    assert np.all(np.isfinite(fit.beta_std)) and np.all(fit.beta_std > 0)
    assert fit.sigma[5] < 1e-3 * fit.sigma.max()
    z = (fit.beta_ls - r.beta_true) / fit.beta_std
    assert np.mean(np.abs(z) <= 3.0) >= 0.95, np.sort(np.abs(z))[-5:]


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"outlier_threshold": 0.0}, "outlier_threshold must be a number > 0"),
        ({"outlier_threshold": -3}, "outlier_threshold must be a number > 0"),
        ({"outlier_threshold": float("nan")}, "outlier_threshold must be a number > 0"),
        ({"outlier_threshold": "3"}, "outlier_threshold must be a number > 0"),
        ({"outlier_threshold": True}, "outlier_threshold must be a number > 0"),
        ({"method": "ridge"}, "method must be 'ols' or 'wls'"),
        ({"solver": "cvx"}, "solver must be one of"),
    ],
)
def test_bad_options(kw, match):
    r = _robot("ur5")
    log, _ = r.log(20, seed=1)
    with pytest.raises(ad.ModelError, match=match):
        identify(r.nominal, log, base=r.base, **kw)


def test_floating_base_refused():
    model = ad.load_urdf(str(common.robot_urdf("ur5")), fixed_base=False)
    r = _robot("ur5")
    log, _ = r.log(20, seed=1)
    with pytest.raises(ad.ModelError, match="floating base"):
        identify(model, log, base=r.base)
