"""armdyn.identification.validate: predicted against measured torques (issue 35).

Closed-form cases: a model against its own inverse-dynamics torques (RMSE 0 to round-off), known
Gaussian noise (N RMSE^2 / sigma^2 is chi-square with N degrees of freedom), a known offset
(RMSE = max error = the offset), and an identification's offsets."""

from dataclasses import dataclass
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest
from armdyn.identification.validate import Validation, compare, validate
from scipy import stats

ARM6 = Path(__file__).resolve().parents[1] / "data" / "urdf" / "arm6.urdf"


@dataclass(frozen=True)
class Log:
    """A stand-in of MotionLog's fields."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    joint_names: list


@dataclass
class Ident:
    """A stand-in of Identification's fields validate reads: predict = Y @ pi."""

    model: object
    pi: np.ndarray

    def predict(self, q, qd, qdd):
        return ad.joint_torque_regressor(self.model, q, qd, qdd) @ self.pi


def _model():
    b = ad.urdf_builder(str(ARM6))
    b.add_joint_friction("elbow_joint", 0.4, 0.7, 0.01)
    return b.finalize()


def _motion(model, n=400, seed=0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 4.0, n)
    w = rng.uniform(0.5, 2.0, model.n_dofs)
    q = np.sin(np.outer(t, w))
    qd = np.cos(np.outer(t, w)) * w
    qdd = -np.sin(np.outer(t, w)) * w**2
    return t, q, qd, qdd


def _log(model, tau_extra=0.0, seed=0, n=400):
    t, q, qd, qdd = _motion(model, n, seed)
    tau = ad.inverse_dynamics(model, q, qd, qdd) + tau_extra
    return Log(t, q, qd, qdd, tau, list(model.dof_names))


def test_own_torques_rmse_zero():
    model = _model()
    log = _log(model, n=2500)  # more than two CHUNKs of samples
    v = validate(model, log)
    scale = np.sqrt(np.mean(log.tau**2, axis=0))
    assert v.label == "nominal"
    assert np.all(v.rmse <= 1e-13 * scale.max())
    assert np.all(v.rel_rmse <= 1e-12)
    # the regressor route: Y @ dynamic_parameters is the same prediction
    w = validate(model, log, pi=ad.dynamic_parameters(model))
    assert np.all(w.rmse <= 1e-12 * scale.max())
    assert v.table().index.tolist() == list(model.dof_names)


def test_known_noise_within_chi_square_bounds():
    model = _model()
    n, sigma = 2000, np.array([0.5, 0.2, 0.1, 0.05, 0.02, 0.01])
    rng = np.random.default_rng(7)
    noise = rng.normal(size=(n, 6)) * sigma
    v = validate(model, _log(model, noise, n=n))
    # N rmse^2 / sigma^2 ~ chi2(N): inside its 1e-6 and 1 - 1e-6 quantiles
    lo, hi = stats.chi2.ppf([1e-6, 1 - 1e-6], n)
    ratio = n * v.rmse**2 / sigma**2
    assert np.all((ratio > lo) & (ratio < hi)), ratio / n
    # and exactly the RMS of the noise that was added
    np.testing.assert_allclose(v.rmse, np.sqrt(np.mean(noise**2, axis=0)), rtol=1e-10)
    k = np.argmax(np.abs(noise), axis=0)
    np.testing.assert_allclose(v.max_error, np.abs(noise[k, range(6)]), rtol=1e-9)
    np.testing.assert_array_equal(v.max_error_time, v.t[k])


def test_known_offset():
    model = _model()
    offset = np.array([0.3, -0.2, 0.1, 0.0, 0.05, -0.01])
    log = _log(model, offset)
    v = validate(model, log)
    np.testing.assert_allclose(v.rmse, np.abs(offset), rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(v.max_error, np.abs(offset), rtol=1e-9, atol=1e-12)
    rms = np.sqrt(np.mean(log.tau**2, axis=0))
    np.testing.assert_allclose(v.rel_rmse, np.abs(offset) / rms, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(v.error, -np.broadcast_to(offset, log.tau.shape), atol=1e-12)


def test_identification_offsets_included():
    """An identification whose pi carries the log's offsets predicts it to round-off; the
    nominal model (no offset) misses by the offset."""
    model = _model()
    offset = np.array([0.3, -0.2, 0.1, 0.4, 0.05, -0.01])
    log = _log(model, offset)
    names = ad.dynamic_parameter_names(model)
    pi = ad.dynamic_parameters(model).copy()
    for j, c in enumerate(model.coord_names):
        pi[names.index(f"{c}.offset")] = offset[j]
    v = validate(Ident(model, pi), log)
    assert v.label == "identified"
    assert np.all(v.rmse <= 1e-12 * np.abs(log.tau).max())
    # pi= with a model: the same
    assert np.all(validate(model, log, pi=pi).rmse <= 1e-12 * np.abs(log.tau).max())
    np.testing.assert_allclose(validate(model, log).rmse, np.abs(offset), rtol=1e-10)


def test_largest_errors_and_table():
    t = np.arange(5.0)
    meas = np.zeros((5, 2))
    meas[:, 0] = [1.0, 2.0, 3.0, 4.0, 5.0]
    meas[:, 1] = 1.0
    pred = meas.copy()
    pred[3, 0] += 0.5
    pred[1, 0] -= 0.25
    pred[4, 1] -= 2.0
    v = compare(t, meas, pred, ["a", "b"])
    tab = v.table()
    assert tab.loc["a", "max_error"] == 0.5 and tab.loc["a", "max_error_time"] == 3.0
    assert tab.loc["b", "max_error"] == 2.0 and tab.loc["b", "max_error_time"] == 4.0
    assert tab.loc["a", "rmse"] == pytest.approx(np.sqrt((0.25 + 0.0625) / 5))
    assert tab.loc["a", "rel_rmse"] == pytest.approx(np.sqrt(0.3125 / 5) / np.sqrt(55 / 5))
    top = v.largest_errors(2)
    assert top[top.joint == "a"].t.tolist() == [3.0, 1.0]
    assert top[top.joint == "a"].error.tolist() == [0.5, -0.25]


def test_zero_measured_torque():
    v = compare([0.0, 1.0], np.zeros((2, 2)), [[0.0, 1.0], [0.0, 0.0]], ["a", "b"])
    assert v.rel_rmse[0] == 0.0 and v.rel_rmse[1] == np.inf
    assert isinstance(v, Validation)


@pytest.mark.parametrize(
    "change, match",
    [
        (lambda log: {"joint_names": list(reversed(log.joint_names))}, "are not the model's"),
        (lambda log: {"q": log.q[:, :3]}, r"log\.q has shape"),
        (lambda log: {"tau": log.tau[:-1]}, r"log\.tau has shape"),
        (lambda log: {"qd": np.where(np.arange(6) == 2, np.nan, log.qd)}, r"log\.qd is not finite"),
        (lambda log: {"tau": np.where(np.arange(6) == 4, np.inf, log.tau)}, "wrist_2_joint"),
    ],
    ids=["joints", "q-shape", "tau-rows", "qd-nan", "tau-inf"],
)
def test_bad_logs_are_named(change, match):
    model = _model()
    log = _log(model, n=20)
    bad = Log(**{**log.__dict__, **change(log)})
    with pytest.raises(ad.ModelError, match=match):
        validate(model, bad)


def test_bad_pi_and_source():
    model = _model()
    log = _log(model, n=10)
    n = len(ad.dynamic_parameters(model))
    with pytest.raises(ad.ModelError, match=f"pi has 3 entries, the model {n}"):
        validate(model, log, pi=np.ones(3))
    pi = ad.dynamic_parameters(model).copy()
    pi[5] = np.nan
    with pytest.raises(ad.ModelError, match=r"pi\[5\] is not finite"):
        validate(model, log, pi=pi)
    with pytest.raises(ad.ModelError, match=r"expected an armdyn\.Model"):
        validate("robot.urdf", log)
    with pytest.raises(ad.ModelError, match="must be a MotionLog"):
        validate(model, object())
