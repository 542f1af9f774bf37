"""Identification fit (issue 35): armdyn.identification.identify on 10,000 logged samples of a
7-joint arm (the Panda, 7 arm joints + the mimic-coupled finger: 8 coordinates) and of the UR5,
"measured" by simulating a perturbed model (link masses, centres of mass and inertias changed,
joint friction and gear-reduced rotors added) along a random Fourier excitation, with Gaussian
noise on the torques. Per robot: the wall time of the whole fit (regressor batch, OLS + WLS,
outliers, standard deviations) without and with the physically consistent estimate, and the
two physically consistent solvers compared on the same problem (SDP through cvxpy/Clarabel and
log-Cholesky with scipy.optimize.least_squares): time, weighted cost, validation RMSE on another
motion, constraint satisfaction. Each robot twice: with Coulomb friction in the truth, and
without (the truth on the boundary fc = 0, where the constraints are active).

    python -m benchmarks.identification_fit [--samples 10000] [--repeats 3]
        [--out benchmarks/results/identification_fit.json]

The helpers (the perturbed model, the Fourier motion, the synthetic log) are also those of
tests/identification/test_estimate.py.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import armdyn as ad
import numpy as np

from benchmarks import common


# ------------------------------------------------------------------------ the synthetic robot
@dataclass(frozen=True)
class SyntheticLog:
    """The fields of armdyn.identification.MotionLog that identify reads, unvalidated (the
    tests' hostile logs: NaN, wrong shapes, that MotionLog itself refuses)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    joint_names: list
    processing: str = "synthetic: exact q, qd, qdd; Gaussian noise on tau"


def _fmt(x: float) -> str:
    return repr(float(x))


def perturbed_urdf(path, seed: int) -> str:
    """The URDF text with every link's mass x U(0.85, 1.15), centre of mass moved by up to 2 cm
    per axis and inertia tensor x U(0.8, 1.2) (a scaled real body stays a real body)."""
    rng = np.random.default_rng(seed)
    tree = ET.parse(str(path))
    for inertial in tree.getroot().iter("inertial"):
        mass = inertial.find("mass")
        mass.set("value", _fmt(float(mass.get("value")) * rng.uniform(0.85, 1.15)))
        origin = inertial.find("origin")
        if origin is None:
            origin = ET.SubElement(inertial, "origin", xyz="0 0 0")
        xyz = np.array([float(v) for v in origin.get("xyz", "0 0 0").split()])
        origin.set("xyz", " ".join(_fmt(v) for v in xyz + rng.uniform(-0.02, 0.02, 3)))
        inertia = inertial.find("inertia")
        s = rng.uniform(0.8, 1.2)
        for key, val in inertia.attrib.items():
            inertia.set(key, _fmt(float(val) * s))
    return ET.tostring(tree.getroot(), encoding="unicode")


def joint_limits(path, coords) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) of the URDF's joints named coords (+-pi without a limit)."""
    root = ET.parse(str(path)).getroot()
    lo, hi = np.full(len(coords), -np.pi), np.full(len(coords), np.pi)
    for j in root.iter("joint"):
        lim = j.find("limit")
        if j.get("name") in coords and lim is not None and lim.get("lower") is not None:
            k = coords.index(j.get("name"))
            lo[k], hi[k] = float(lim.get("lower")), float(lim.get("upper"))
    return lo, hi


def robot(name: str, seed: int = 0, coulomb: bool = True):
    """(nominal model, true model, true pi in the nominal's layout, (lower, upper)).

    The true model: the perturbed URDF, viscous and Coulomb friction on every coordinate (no
    Coulomb friction with coulomb=False: the truth on the boundary fc = 0 of the consistent
    set, so that noise puts half the least-squares fc below zero), a gear-reduced rotor
    (ratio 100) on every revolute coordinate."""
    path = common.robot_urdf(name)
    nominal = ad.load_urdf(str(path))
    rng = np.random.default_rng(seed + 1000)
    b = ad.urdf_builder(perturbed_urdf(path, seed))
    coords = list(nominal.coord_names)
    for c in coords:
        fc = rng.uniform(0.1, 1.0)
        b.add_joint_friction(c, rng.uniform(0.05, 0.5), fc if coulomb else 0.0)
        if not re.search("finger", c):
            b.add_actuator(c, 100.0, rng.uniform(1e-5, 5e-5))
    true = b.finalize()
    names = list(ad.dynamic_parameter_names(nominal))
    true_names = list(ad.dynamic_parameter_names(true))
    assert true_names == names, "the perturbed model's parameters differ in layout"
    return nominal, true, ad.dynamic_parameters(true), joint_limits(path, coords)


def fourier_motion(limits, t, *, seed: int, period: float = 10.0, harmonics: int = 5):
    """(q, qd, qdd) of a random finite Fourier series about the middle of the joint ranges,
    amplitude <= 40 % of the half range (<= 1.2 rad), closed-form derivatives."""
    rng = np.random.default_rng(seed)
    lo, hi = limits
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    amp = np.minimum(0.4 * half, 1.2)
    w = 2.0 * np.pi / period * np.arange(1, harmonics + 1)
    c = rng.normal(size=(lo.size, harmonics)) / np.arange(1, harmonics + 1)
    c *= (amp / np.abs(c).sum(axis=1))[:, None]
    phase = rng.uniform(0.0, 2.0 * np.pi, (lo.size, harmonics))
    arg = t[:, None, None] * w[None, None, :] + phase[None]
    q = mid + np.sum(c * np.sin(arg), axis=2)
    qd = np.sum(c * w * np.cos(arg), axis=2)
    qdd = -np.sum(c * w**2 * np.sin(arg), axis=2)
    return q, qd, qdd


def synthetic_log(true, limits, coords, n: int, *, seed: int, noise=None, period=10.0):
    """A log of n samples over two periods of a random Fourier motion, tau by inverse dynamics
    of the true model plus N(0, noise_j) per joint. Returns (log, noise-free tau)."""
    t = np.linspace(0.0, 2.0 * period, n, endpoint=False)
    q, qd, qdd = fourier_motion(limits, t, seed=seed, period=period)
    tau0 = np.array([ad.inverse_dynamics(true, *x) for x in zip(q, qd, qdd, strict=True)])
    tau = tau0.copy()
    if noise is not None:
        tau += np.random.default_rng(seed + 7).normal(size=tau.shape) * noise
    from armdyn.identification import MotionLog

    log = MotionLog(t, q, qd, qdd, tau, list(coords), SyntheticLog.processing)
    return log, tau0


def base_for(model, **kw):
    """armdyn.identification.base_parameters (the tests' and this benchmark's one call)."""
    from armdyn.identification import base_parameters

    return base_parameters(model, **kw)


# ------------------------------------------------------------------------------ measurement
def _timed(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def run_robot(name, n, repeats, coulomb=True):
    from armdyn.identification import identify, is_physical

    nominal, true, pi_true, limits = robot(name, coulomb=coulomb)
    coords = list(nominal.coord_names)
    _, clean = synthetic_log(true, limits, coords, 400, seed=11)
    noise = 0.02 * np.sqrt(np.mean(clean**2, axis=0)) + 0.01
    log, _ = synthetic_log(true, limits, coords, n, seed=1, noise=noise)
    val, _ = synthetic_log(true, limits, coords, 2000, seed=2, noise=noise)
    base = base_for(nominal)
    row = {
        "coulomb_friction": coulomb,
        "n_samples": n,
        "n_dofs": nominal.n_dofs,
        "n_params": pi_true.size,
        "n_base": base.rank,
    }
    row["noise"] = noise.tolist()
    t_ls, ls = _timed(lambda: identify(nominal, log, base=base, physical=False), repeats)
    row["least_squares"] = {"seconds": t_ls, **_quality(ls, val, base, pi_true, noise)}
    for solver in ("sdp", "log-cholesky"):
        t, fit = _timed(lambda s=solver: identify(nominal, log, base=base, solver=s), repeats)
        row[solver] = {
            "seconds": t,
            "cost": fit.info["cost"],
            "cost_ls": fit.info["cost_ls"],
            "status": str(fit.info["status"]),
            "is_physical": bool(is_physical(nominal, fit.pi)),
            "min_pseudo_inertia_eig": _min_eig(fit.pi, nominal),
            **_quality(fit, val, base, pi_true, noise),
        }
    return row


def _min_eig(pi, model):
    from armdyn.identification import pseudo_inertia
    from armdyn.identification.physical import parameter_layout

    bodies, _ = parameter_layout(list(ad.dynamic_parameter_names(model)))
    return min(
        float(np.linalg.eigvalsh(pseudo_inertia(pi[10 * k : 10 * k + 10]))[0])
        for k in range(len(bodies))
    )


def _quality(fit, val, base, pi_true, noise):
    pred = fit.predict(val.q, val.qd, val.qdd)
    rmse = np.sqrt(np.mean((val.tau - pred) ** 2, axis=0))
    z = (fit.beta_ls - base.beta(pi_true)) / fit.beta_std
    return {
        "validation_rmse": rmse.tolist(),
        "validation_rmse_over_noise": (rmse / noise).tolist(),
        "fit_rmse": fit.rmse.tolist(),
        "fraction_within_3_std": float(np.mean(np.abs(z) <= 3.0)),
        "outliers": int(fit.outliers.size),
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=str(common.RESULTS / "identification_fit.json"))
    args = ap.parse_args(argv)
    out = {
        "machine": common.machine(),
        "command": "python -m benchmarks.identification_fit " + " ".join(argv or sys.argv[1:]),
        # identify runs OpenBLAS on one thread (base.one_blas_thread); the machine's load is
        # recorded so the times can be read
        "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS", "(default)"),
        "load_average_before": os.getloadavg(),
    }
    cases = [(name, name, True) for name in ("panda", "ur5")]
    cases += [(name + "_no_coulomb", name, False) for name in ("panda", "ur5")]
    for key, name, coulomb in cases:
        out[key] = run_robot(name, args.samples, args.repeats, coulomb)
        r = out[key]
        print(
            f"{key}: n_base {r['n_base']}, LS {r['least_squares']['seconds']:.2f} s, "
            f"SDP {r['sdp']['seconds']:.2f} s (cost {r['sdp']['cost']:.6g}, physical "
            f"{r['sdp']['is_physical']}), log-Cholesky {r['log-cholesky']['seconds']:.2f} s "
            f"(cost {r['log-cholesky']['cost']:.6g}, physical {r['log-cholesky']['is_physical']})"
            f"; LS cost {r['sdp']['cost_ls']:.6g}"
        )
    out["load_average_after"] = os.getloadavg()
    print(common.write_json(args.out, out))


if __name__ == "__main__":
    main()
