"""The first paper's study on armdyn.scenes.geared_arm_6dof: 5 s runs with 1, 2, 3 and 4 motors
on the waist's driven gear (0.1 mm stage-2 backlash), plus the backlash-free arm. The waist turns
about the vertical, so its gear load reverses between acceleration and deceleration: that is
where the clearance shows. The first 0.3 s (the motors taking up the arm's weight from rest)
are excluded from the metrics. Writes
docs/figures/geared_arm_torque.png (in the style of the paper's Fig. 3 a–d) and
docs/results/geared_arm_study.json, and prints the table of docs/geared_arm.md.

    python benchmarks/geared_arm_study.py            (about 10 min on 2 cores)
"""

from __future__ import annotations

import json
import platform
import time
from pathlib import Path

import armdyn as ad
import matplotlib
import numpy as np
from armdyn.scenes.geared_arm import JOINTS

matplotlib.use("Agg")
import matplotlib.pyplot as plt

ROOT = Path(__file__).resolve().parents[1]
JOINT = "waist"
R2 = next(j[4] for j in JOINTS if j[0] == JOINT)
T_END, OUT_DT, BACKLASH = 5.0, 0.002, 1e-4


def driven_gear_torque(res):
    """Torque on the studied joint's driven gear from all its stage-2 meshes: −R2 Σ F."""
    names = res.gear_forces["names"]
    cols = [i for i, n in enumerate(names) if n.startswith(JOINT) and "stage_2" in n]
    return -R2 * res.gear_forces["force"][:, cols].sum(axis=1)


def run(n_motors, backlash):
    model = ad.scenes.geared_arm_6dof(n_motors=n_motors, backlash=backlash)
    t0 = time.perf_counter()
    res = ad.simulate(model, T_END, rtol=1e-6, atol=1e-8, output_dt=OUT_DT, max_steps=10**7)
    cpu = time.perf_counter() - t0
    tau = driven_gear_torque(res)
    settled = res.t >= 0.3
    moving = (res.t >= 0.5) & (res.t <= 4.5)
    impacts = sum(
        1
        for g, on, t in zip(res.events["gear"], res.events["onset"], res.events["t"], strict=True)
        if on and g.startswith(JOINT) and t >= 0.3
    )
    return (
        model,
        res,
        tau,
        {
            "n_motors": n_motors,
            "backlash_m": backlash,
            "bodies": model.nb,
            "peak_torque_Nm": float(np.max(np.abs(tau[settled]))),
            "rms_torque_moving_Nm": float(np.sqrt(np.mean(tau[moving] ** 2))),
            "tooth_impacts": impacts,
            "all_events": int(res.stats["events"]),
            "steps": int(res.stats["steps"]),
            "rejected": int(res.stats["rejected"]),
            "cpu_s": cpu,
            "ms_per_step": 1e3 * cpu / max(1, res.stats["steps"]),
            "max_residual": float(np.max(res.position_residual)),
        },
    )


def main():
    rows, curves = [], {}
    for n, bl in [(0, 0.0), (1, BACKLASH), (2, BACKLASH), (3, BACKLASH), (4, BACKLASH)]:
        _m, res, tau, row = run(max(n, 1), bl)
        row["case"] = "no backlash, 1 motor" if n == 0 else f"{n} motor(s)"
        rows.append(row)
        curves[row["case"]] = (res.t, tau)
        print(json.dumps(row))
    fig, axes = plt.subplots(2, 2, figsize=(11, 6), sharex=True, sharey=True)
    t0, tau0 = curves["no backlash, 1 motor"]
    for ax, case in zip(axes.flat, [f"{n} motor(s)" for n in (1, 2, 3, 4)], strict=True):
        t, tau = curves[case]
        keep, keep0 = t >= 0.3, t0 >= 0.3
        ax.plot(t[keep], tau[keep], lw=0.8, label=f"{case}, backlash 0.1 mm")
        ax.plot(t0[keep0], tau0[keep0], "k--", lw=1.2, label="no backlash")
        ax.set_title(case)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    for ax in axes[:, 0]:
        ax.set_ylabel(f"torque on the {JOINT} driven gear [N m]")
    fig.suptitle(
        f"Geared 6-DOF arm (44+ bodies): {JOINT} driven-gear torque, 1–4 motors sharing it"
    )
    fig.tight_layout()
    (ROOT / "docs" / "figures").mkdir(parents=True, exist_ok=True)
    fig.savefig(ROOT / "docs" / "figures" / "geared_arm_torque.png", dpi=110)
    out = {
        "command": "python benchmarks/geared_arm_study.py",
        "machine": {"platform": platform.platform(), "python": platform.python_version()},
        "t_end_s": T_END,
        "rtol": 1e-6,
        "rows": rows,
    }
    (ROOT / "docs" / "results").mkdir(parents=True, exist_ok=True)
    (ROOT / "docs" / "results" / "geared_arm_study.json").write_text(json.dumps(out, indent=1))
    print(
        "| case | bodies | peak torque [N m] | RMS torque in motion [N m] | tooth impacts | "
        "steps | CPU [s] | ms/step |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['case']} | {r['bodies']} | {r['peak_torque_Nm']:.2f} | "
            f"{r['rms_torque_moving_Nm']:.2f} | {r['tooth_impacts']} | {r['steps']} | "
            f"{r['cpu_s']:.1f} | {r['ms_per_step']:.2f} |"
        )


if __name__ == "__main__":
    main()
