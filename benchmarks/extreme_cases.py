"""Figures and numbers of docs/extreme_cases.md.

    python -m benchmarks.extreme_cases   (from the repository root; writes docs/figures/*.png and
                                          benchmarks/results/extreme_cases.json)

Each case is also a test (tests/simulate/test_stiff.py, tests/simulate/test_extreme.py); this
script measures the cost side (steps, CPU time) and draws the figures.
"""

from __future__ import annotations

import json
import platform
import time

import armdyn as ad
import matplotlib
import numpy as np
from armdyn import _core

from benchmarks.common import RESULTS, ROOT
from tests.oracles.numpy_rne import serial_chain

matplotlib.use("Agg")
import matplotlib.pyplot as plt

FIG, RES = ROOT / "docs" / "figures", RESULTS


def timed(fn, repeat=3):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def stiff_sweep():
    ks = [1e2, 1e4, 1e6, 1e8, 1e10]
    rows = []
    for k in ks:
        model = ad.scenes.spring_mass_pendulum(stiffness=k)
        ref = ad.simulate(model, 2.0, rtol=1e-11, atol=1e-13, output_dt=0.5, max_steps=10**8)
        row = {"k": k}
        for integ in ("dopri5", "trbdf2"):
            res, cpu = timed(
                lambda integ=integ, model=model: ad.simulate(
                    model, 2.0, integrator=integ, rtol=1e-6, atol=1e-8, output_dt=0.5
                )
            )
            row[integ] = {
                "steps": res.stats["steps"],
                "rejected": res.stats["rejected"],
                "rhs_evals": res.stats["rhs_evals"],
                "jacobians": res.stats["jacobians"],
                "cpu_s": cpu,
                "error_angle": float(np.max(np.abs(res.q[:, 0] - ref.q[:, 0]))),
            }
        auto = ad.simulate(model, 2.0, integrator="auto", output_dt=0.5)
        row["auto"] = auto.stats["integrator"]
        row["auto_reason"] = auto.stats["integrator_reason"]
        rows.append(row)
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.6))
    for integ, style in (("dopri5", "o-"), ("trbdf2", "s-")):
        ax[0].loglog(ks, [r[integ]["steps"] for r in rows], style, label=integ)
        ax[1].loglog(ks, [r[integ]["cpu_s"] for r in rows], style, label=integ)
        ax[2].loglog(ks, [r[integ]["error_angle"] for r in rows], style, label=integ)
    for a, lab in zip(ax, ("steps", "CPU time [s]", "max |Δθ| vs reference [rad]"), strict=True):
        a.set_xlabel("spring stiffness k [N/m]")
        a.set_ylabel(lab)
        a.grid(True, which="both", alpha=0.3)
    ax[0].legend()
    fig.suptitle("Spring-mass pendulum, 2 s, rtol 1e-6: explicit DOPRI5 vs implicit TR-BDF2")
    fig.tight_layout()
    fig.savefig(FIG / "stiff_sweep.png", dpi=110)
    plt.close(fig)
    return rows


def bricard_case():
    model = ad.scenes.bricard()
    res, cpu = timed(lambda: ad.simulate(model, 2.0, rtol=1e-10, atol=1e-12, output_dt=0.01), 1)
    energy = res.total_energy
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.4))
    ax[0].plot(res.t, res.q)
    ax[0].legend(model.coord_names, fontsize=7, ncol=2)
    ax[0].set_title("joint angles (J0 = J2 = J4, J1 = J3 = J5)")
    ax[1].semilogy(res.t[1:], np.abs(energy[1:] - energy[0]) + 1e-18, label="|ΔE| [J]")
    ax[1].semilogy(res.t, res.position_residual + 1e-18, label="max |f|")
    ax[1].legend()
    for a in ax:
        a.set_xlabel("t [s]")
    fig.suptitle("Bricard 6R: mobility 1 (Grübler: 0), one redundant row")
    fig.tight_layout()
    fig.savefig(FIG / "bricard.png", dpi=110)
    plt.close(fig)
    return {
        "mobility": model.mobility,
        "redundant_rows": list(model.redundant_rows),
        "energy_error": float(np.max(np.abs(energy - energy[0]))),
        "max_residual": float(np.max(res.position_residual)),
        "symmetry_error": float(np.max(np.abs(res.q[:, [2, 4]] - res.q[:, [0]]))),
        "steps": res.stats["steps"],
        "cpu_s": cpu,
    }


def parallelogram_case():
    drive = _core.profiles.spline([0.0, 1.0], [0.0, np.pi])
    model = ad.scenes.four_bar(
        a=0.3, b_len=0.7, c=0.3, d=0.7, crank_angle=np.pi / 2, crank_drive=drive, gravity=0.0
    )
    res = ad.simulate(model, 1.0, rtol=1e-9, atol=1e-10, output_dt=0.01)
    names = list(model.coord_names)
    fig, ax = plt.subplots(figsize=(6, 3.4))
    for n in names:
        ax.plot(res.t, res.q[:, names.index(n)], label=n)
    ax.axvline(0.5, color="k", ls=":", label="change point (collinear)")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("joint angle [rad]")
    ax.legend(fontsize=7)
    ax.set_title("Parallelogram four-bar driven through its change point")
    fig.tight_layout()
    fig.savefig(FIG / "parallelogram.png", dpi=110)
    plt.close(fig)
    return {
        "singular_evaluations": res.stats["singular_evaluations"],
        "singular_note": res.stats["singular_note"],
        "branch_error": float(np.max(np.abs(res.q[:, 0] + res.q[:, 1]))),
    }


def heavy_top_case():
    model, u0, v0, omega_p = ad.scenes.heavy_top()
    n_steps, dt = 1_000_000, 1e-5
    res, cpu = timed(
        lambda: ad.simulate(
            model, n_steps * dt, integrator="rk4", dt=dt, output_dt=0.01, u0=u0, v0=v0
        ),
        1,
    )
    x = res.u[:, :3]
    phi = np.unwrap(np.arctan2(x[:, 1], x[:, 0]))
    energy = res.total_energy
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.4))
    ax[0].plot(res.t, phi - phi[0], label="simulated precession angle")
    ax[0].plot(res.t, omega_p * res.t, "--", label="m g l / (I₃ ω) t")
    ax[0].legend()
    ax[1].semilogy(res.t, res.position_residual + 1e-18, label="max |f|")
    ax[1].semilogy(res.t[1:], np.abs(energy[1:] - energy[0]) / energy[0] + 1e-18, label="|ΔE| / E")
    ax[1].legend()
    for a in ax:
        a.set_xlabel("t [s]")
    fig.suptitle("Heavy top, 1000 rad/s, 10⁶ RK4 steps")
    fig.tight_layout()
    fig.savefig(FIG / "heavy_top.png", dpi=110)
    plt.close(fig)
    return {
        "steps": res.stats["steps"],
        "cpu_s": cpu,
        "max_residual": float(np.max(res.position_residual)),
        "energy_rel_error": float(np.max(np.abs(energy - energy[0])) / energy[0]),
        "precession_rate": float((phi[-1] - phi[0]) / res.t[-1]),
        "precession_closed_form": omega_p,
    }


def mass_ratio_case():
    rng = np.random.default_rng(0)
    ratios = [1.0, 1e2, 1e4, 1e6, 1e8, 1e10]
    fd_err = []
    for r in ratios:
        arm = ad.scenes.mass_ratio_chain(r)
        chain, perm = serial_chain(arm), arm.perm
        worst = 0.0
        for _ in range(5):
            q_ref, qd_ref, tau_ref = rng.normal(size=(3, len(perm)))
            q, qd, tau = (np.empty(len(perm)) for _ in range(3))
            q[perm], qd[perm], tau[perm] = q_ref, qd_ref, tau_ref
            qdd = ad.forward_dynamics(arm.model, q, qd, tau)
            ref = chain.forward(q_ref, qd_ref, tau_ref)
            worst = max(worst, float(np.max(np.abs(qdd[perm] - ref)) / np.max(np.abs(ref))))
        fd_err.append(worst)
    model = ad.scenes.mass_ratio_chain(1e6).model
    runs = {}
    for integ in ("dopri5", "trbdf2"):
        res, cpu = timed(
            lambda integ=integ: ad.simulate(
                model, 1.0, integrator=integ, rtol=1e-8, atol=1e-10, output_dt=0.005
            ),
            1,
        )
        e = res.total_energy
        runs[integ] = {
            "t": res.t,
            "energy_error": np.abs(e - e[0]) / np.max(res.kinetic_energy),
            "residual": res.position_residual,
            "steps": res.stats["steps"],
            "cpu_s": cpu,
        }
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.4))
    ax[0].loglog(ratios, np.maximum(fd_err, 1e-17), "o-")
    ax[0].set_xlabel("mass ratio of neighbouring links")
    ax[0].set_ylabel("forward dynamics: rel. error vs numpy RNEA/CRBA")
    ax[0].grid(alpha=0.3, which="both")
    for integ, r in runs.items():
        ax[1].semilogy(r["t"], r["energy_error"] + 1e-18, label=f"{integ}: |ΔE| / max KE")
        ax[1].semilogy(r["t"], r["residual"] + 1e-18, ":", label=f"{integ}: max |f|")
    ax[1].set_xlabel("t [s]")
    ax[1].set_title("mass ratio 1e6, 1 s free motion, rtol 1e-8", fontsize=9)
    ax[1].legend(fontsize=7)
    fig.suptitle("Chain of 5 revolute links with alternating masses")
    fig.tight_layout()
    fig.savefig(FIG / "mass_ratio.png", dpi=110)
    plt.close(fig)
    return {
        "ratios": ratios,
        "fd_rel_error": fd_err,
        "runs_ratio_1e6": {
            k: {
                "steps": v["steps"],
                "cpu_s": v["cpu_s"],
                "max_energy_error": float(np.max(v["energy_error"])),
                "max_residual": float(np.max(v["residual"])),
            }
            for k, v in runs.items()
        },
    }


def nan_case():
    """A user force that turns NaN after t = 0.31 s: each integrator stops with a SolverError
    naming the body and the time, and returns the outputs before it."""

    full = ad.simulate(
        ad.scenes.nan_force_pendulum(), 0.31, rtol=1e-10, atol=1e-12, output_dt=0.005
    )
    out = {}
    fig, ax = plt.subplots(figsize=(6, 3.4))
    ax.plot(full.t, full.q[:, 0], "k-", lw=3, alpha=0.3, label="reference (stopped at 0.31 s)")
    for integ, mark in (("dopri5", "o"), ("trbdf2", "s"), ("rk4", "^")):
        try:
            ad.simulate(
                ad.scenes.nan_force_pendulum(), 1.0, integrator=integ, dt=0.01, output_dt=0.05
            )
            raise RuntimeError("the NaN force was not caught")
        except ad.SolverError as e:
            res = e.result
            out[integ] = {"message": str(e).splitlines()[0], "last_output_t": float(res.t[-1])}
            ax.plot(
                res.t,
                res.q[:, 0],
                mark,
                ms=4,
                label=f"{integ}: stops, last output t={res.t[-1]:.2f}",
            )
    ax.axvline(0.31, color="r", ls=":", label="force becomes NaN")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("pendulum angle [rad]")
    ax.set_xlim(0, 0.5)
    ax.legend(fontsize=7)
    ax.set_title("NaN force mid-run: SolverError + the result up to the last good output")
    fig.tight_layout()
    fig.savefig(FIG / "nan_force.png", dpi=110)
    plt.close(fig)
    return out


def main():
    FIG.mkdir(parents=True, exist_ok=True)
    RES.mkdir(parents=True, exist_ok=True)
    out = {
        "machine": {
            "platform": platform.platform(),
            "processor": platform.processor(),
            "python": platform.python_version(),
        },
        "command": "python -m benchmarks.extreme_cases",
        "stiff_sweep": stiff_sweep(),
        "bricard": bricard_case(),
        "parallelogram": parallelogram_case(),
        "heavy_top": heavy_top_case(),
        "mass_ratio": mass_ratio_case(),
        "nan_force": nan_case(),
    }
    (RES / "extreme_cases.json").write_text(json.dumps(out, indent=1), encoding="utf-8")
    print("k | dopri5 steps, CPU s, error | trbdf2 steps, CPU s, error | auto")
    for r in out["stiff_sweep"]:
        d, t = r["dopri5"], r["trbdf2"]
        print(
            f"{r['k']:.0e} | {d['steps']}, {d['cpu_s']:.3f}, {d['error_angle']:.1e} | "
            f"{t['steps']}, {t['cpu_s']:.3f}, {t['error_angle']:.1e} | {r['auto']}"
        )
    for key in ("bricard", "parallelogram", "heavy_top", "mass_ratio", "nan_force"):
        print(key, json.dumps(out[key]))


if __name__ == "__main__":
    main()
