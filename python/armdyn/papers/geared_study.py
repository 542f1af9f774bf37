"""The first paper's study on :func:`armdyn.papers.geared_arm.geared_arm_6dof`: 5 s runs with 1, 2,
3 and 4 motors on the waist's driven gear (0.1 mm stage-2 backlash), without and with anti-backlash
preload between the motors, plus the backlash-free arm. The waist turns about the vertical, so its
gear load reverses between acceleration and deceleration: that is where the clearance shows. The
first 0.3 s (the motors taking up the arm's weight from rest) are excluded from the metrics.

Run by ``armdyn reproduce`` (into the report folder) and by ``python
benchmarks/geared_arm_study.py`` (into ``docs/``).
"""

from __future__ import annotations

import json
import os
import platform
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from armdyn.papers.geared_arm import JOINTS, geared_arm_6dof
from armdyn.simulation import simulate

JOINT = "waist"
R2 = next(j[4] for j in JOINTS if j[0] == JOINT)
T_END, OUT_DT, BACKLASH, PRELOAD, RTOL, ATOL = 5.0, 0.002, 1e-4, 0.1, 1e-6, 1e-8
T_SETTLED, T_MOVE = 0.3, (0.5, 4.5)

# (case label, motors on the waist gear, backlash [m], preload [N m at each rotor])
CASES = [
    ("no backlash, 1 motor", 1, 0.0, 0.0),
    ("1 motor", 1, BACKLASH, 0.0),
    ("2 motors", 2, BACKLASH, 0.0),
    ("3 motors", 3, BACKLASH, 0.0),
    ("4 motors", 4, BACKLASH, 0.0),
    ("2 motors, preload", 2, BACKLASH, PRELOAD),
    ("3 motors, preload", 3, BACKLASH, PRELOAD),
    ("4 motors, preload", 4, BACKLASH, PRELOAD),
]


def driven_gear_torque(res, joint=JOINT, radius=R2):
    """Torque on a joint's driven gear from all its stage-2 meshes (−R2 Σ F); None when the
    joint's stage 2 is an ideal gear (no gear-pair forces)."""
    names = res.gear_forces["names"]
    cols = [i for i, n in enumerate(names) if n.startswith(joint) and "stage_2" in n]
    return -radius * res.gear_forces["force"][:, cols].sum(axis=1)


def run_case(case, t_end=T_END, coordinates="cartesian"):
    """One case: returns (row of metrics, t, driven-gear torque). ``coordinates`` is
    :func:`armdyn.simulate`'s: ``"cartesian"`` (the paper's formulation, 44–56 bodies) or
    ``"joint"`` (the same tree in 13–16 independent joint coordinates: the same metrics, about
    fifty times faster)."""
    label, n_motors, backlash, preload = case
    model = geared_arm_6dof(n_motors=n_motors, backlash=backlash, preload=preload)
    t0 = time.perf_counter()
    res = simulate(
        model,
        t_end,
        rtol=RTOL,
        atol=ATOL,
        output_dt=OUT_DT,
        max_steps=10**7,
        coordinates=coordinates,
    )
    cpu = time.perf_counter() - t0
    tau = driven_gear_torque(res)
    settled = res.t >= T_SETTLED
    moving = (res.t >= T_MOVE[0]) & (res.t <= T_MOVE[1])
    impacts = sum(
        1
        for g, on, t in zip(res.events["gear"], res.events["onset"], res.events["t"], strict=True)
        if on and g.startswith(JOINT) and t >= T_SETTLED
    )
    row = {
        "case": label,
        "n_motors": n_motors,
        "backlash_m": backlash,
        "preload_Nm": preload,
        "bodies": model.nb,
        "coordinates": coordinates,
        "peak_torque_Nm": float(np.max(np.abs(tau[settled]))),
        "rms_torque_moving_Nm": float(np.sqrt(np.mean(tau[moving] ** 2))) if moving.any() else 0.0,
        "tooth_impacts": impacts,
        "all_events": int(res.stats["events"]),
        "steps": int(res.stats["steps"]),
        "rejected": int(res.stats["rejected"]),
        "cpu_s": cpu,
        "ms_per_step": 1e3 * cpu / max(1, res.stats["steps"]),
        "max_residual": float(np.max(res.position_residual)),
    }
    return row, res.t, tau


def table(rows) -> str:
    lines = [
        "| case | bodies | peak torque [N m] | RMS torque in motion [N m] | tooth impacts | "
        "steps | CPU [s] | ms/step |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['bodies']} | {r['peak_torque_Nm']:.2f} | "
            f"{r['rms_torque_moving_Nm']:.2f} | {r['tooth_impacts']} | {r['steps']} | "
            f"{r['cpu_s']:.1f} | {r['ms_per_step']:.2f} |"
        )
    return "\n".join(lines)


def figure(path: Path, curves: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 6), sharex=True, sharey=True)
    t0, tau0 = curves.get("no backlash, 1 motor", (None, None))
    for ax, n in zip(axes.flat, (1, 2, 3, 4), strict=True):
        label = f"{n} motor" + ("s" if n > 1 else "")
        for case, style in ((label, "-"), (f"{label}, preload", "-")):
            if case in curves:
                t, tau = curves[case]
                keep = t >= T_SETTLED
                ax.plot(t[keep], tau[keep], style, lw=0.8, label=case)
        if t0 is not None:
            keep0 = t0 >= T_SETTLED
            ax.plot(t0[keep0], tau0[keep0], "k--", lw=1.0, label="no backlash")
        ax.set_title(f"{label}, backlash {BACKLASH * 1e3:g} mm")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    # one label for the shared y axis (one per row overlapped the other at this height)
    fig.supylabel(f"torque on the {JOINT} driven gear [N m]", fontsize="medium")
    fig.suptitle(
        f"Geared 6-DOF arm (44+ bodies): {JOINT} driven-gear torque, 1–4 motors sharing it"
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run_study(
    figure_path=None,
    json_path=None,
    cases=CASES,
    t_end=T_END,
    command="",
    workers=None,
    coordinates="cartesian",
):
    """Run the cases (in parallel processes, one per core, for the Cartesian formulation),
    write the figure and the JSON when paths are given; returns the rows."""
    workers = workers or min(len(cases), os.cpu_count() or 1)
    if coordinates == "cartesian" and workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            n = len(cases)
            out = list(pool.map(run_case, cases, [t_end] * n, [coordinates] * n))
    else:
        out = [run_case(c, t_end, coordinates) for c in cases]
    rows = [o[0] for o in out]
    if figure_path is not None:
        figure(Path(figure_path), {o[0]["case"]: (o[1], o[2]) for o in out})
    if json_path is not None:
        path = Path(json_path)
        path.parent.mkdir(parents=True, exist_ok=True)
        doc = {
            "command": command,
            "machine": {
                "platform": platform.platform(),
                "python": platform.python_version(),
                "cpus": os.cpu_count(),
            },
            "t_end_s": t_end,
            "rtol": RTOL,
            "atol": ATOL,
            "rows": rows,
        }
        path.write_text(json.dumps(doc, indent=1), encoding="utf-8")
    return rows
