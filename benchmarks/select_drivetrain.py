"""The drivetrain selection's screening speed (issue 33's target: 6 joints × 10,000 combinations
per joint in ≤ 10 s on the 2-core machine), through the public API.

    python -m benchmarks.select_drivetrain [--motors 100] [--gearboxes 100] [--drives 0]
        [--samples 201] [--repeats 3]

The UR5 (example-robot-data) moves every joint rest to rest (a quintic, 1.2 s) and holds the end
pose for a 0.5 s dwell, repeated forever (``armdyn.duty_cycle``); a synthetic catalog of
``--motors`` motors and ``--gearboxes`` gearboxes (``--drives`` drives; default none, i.e.
motor × gearbox combinations) spanning small to large parts is written as CSV files and read by
``armdyn.load_catalog``; ``armdyn.select_drivetrain`` screens every combination for every joint
with the coupled passes (the actuators' masses carried). Reported: the wall-clock and CPU time
of the selection (median of ``--repeats`` runs after one warm-up), the passes, the joint
screenings made and the choice. Written to ``benchmarks/results/select_drivetrain.json``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import armdyn as ad
import numpy as np
import pandas as pd

from benchmarks import common


def synthetic_catalog(folder: Path, n_motors: int, n_gearboxes: int, n_drives: int, seed=0):
    """CSV files of a catalog spanning small to large parts (log-spaced sizes, datasheet-like
    scaling laws, a little scatter), every row labelled ``source = synthetic``."""
    rng = np.random.default_rng(seed)
    s = np.geomspace(0.05, 8.0, n_motors) * rng.uniform(0.9, 1.1, n_motors)  # continuous torque
    kt = 0.05 * np.sqrt(s / 0.05) * rng.uniform(0.9, 1.1, n_motors)
    motors = pd.DataFrame(
        {
            "name": [f"M{i:04d}" for i in range(n_motors)],
            "torque_constant": kt,
            "resistance": 0.9 * (kt / 0.05) ** 2 / (s / 0.05),
            "rotor_inertia": 4e-6 * (s / 0.05) ** 1.3,
            "mass": 0.3 * (s / 0.05) ** 0.7,
            "no_load_speed": 48.0 / kt,
            "continuous_torque": s,
            "peak_torque": 3.2 * s,
            "max_speed": np.minimum(48.0 / kt, 800.0),
            "voltage": np.full(n_motors, 48.0),
            "thermal_resistance_winding": 1.2 * (s / 0.05) ** -0.3,
            "thermal_resistance_housing": 2.5 * (s / 0.05) ** -0.4,
            "thermal_time_constant_winding": 30.0 * (s / 0.05) ** 0.3,
            "thermal_time_constant_housing": 900.0 * (s / 0.05) ** 0.3,
            "max_winding_temperature": np.full(n_motors, 155.0),
            "cost": 120.0 * (s / 0.05) ** 0.6,
            "source": "synthetic",
        }
    )
    ratios = np.array([30.0, 50.0, 80.0, 100.0, 120.0, 160.0])
    size = np.geomspace(5.0, 2000.0, int(np.ceil(n_gearboxes / len(ratios))))
    rated = np.repeat(size, len(ratios))[:n_gearboxes] * rng.uniform(0.9, 1.1, n_gearboxes)
    ratio = np.tile(ratios, len(size))[:n_gearboxes]
    gearboxes = pd.DataFrame(
        {
            "name": [f"G{i:04d}" for i in range(n_gearboxes)],
            "ratio": ratio,
            "efficiency": np.full(n_gearboxes, 0.8),
            "input_inertia": 1e-6 * (rated / 5.0) ** 1.2,
            "mass": 0.2 * (rated / 5.0) ** 0.7,
            "rated_torque": rated,
            "rated_input_speed": np.full(n_gearboxes, 2000.0 * 2 * np.pi / 60),
            "rated_life": np.full(n_gearboxes, 7000.0),
            "repeated_peak_torque": 2.5 * rated,
            "momentary_peak_torque": 5.0 * rated,
            "momentary_peak_count": np.full(n_gearboxes, 1e4),
            "max_input_speed": np.full(n_gearboxes, 6000.0 * 2 * np.pi / 60),
            "bearing_moment_allowable": 15.0 * rated,
            "bearing_axial_allowable": 400.0 * rated**0.8,
            "bearing_radial_allowable": 300.0 * rated**0.8,
            "bearing_offset": 0.02 * (rated / 5.0) ** 0.3,
            "cost": 300.0 * (rated / 5.0) ** 0.5,
            "source": "synthetic",
        }
    )
    folder.mkdir(parents=True, exist_ok=True)
    motors.to_csv(folder / "motors.csv", index=False)
    gearboxes.to_csv(folder / "gearboxes.csv", index=False)
    if n_drives:
        current = np.geomspace(2.0, 60.0, n_drives)
        pd.DataFrame(
            {
                "name": [f"D{i:03d}" for i in range(n_drives)],
                "continuous_current": current,
                "peak_current": 3.0 * current,
                "bus_voltage": np.full(n_drives, 48.0),
                "cost": 100.0 * (current / 2.0) ** 0.5,
                "source": "synthetic",
            }
        ).to_csv(folder / "drives.csv", index=False)
    return ad.load_catalog(folder)


def ur5_cycle(model, samples: int):
    """Every joint rest to rest (quintic, 1.2 s) then a 0.5 s dwell, repeated forever."""
    t = np.linspace(0.0, 1.2, samples)
    q0 = np.array(common.UR5_Q0)
    q1 = q0 + np.array([1.2, -0.6, 0.9, -0.8, 1.0, 1.5])
    cols = [ad.profiles.quintic(a, b, 0.0, 1.2).eval(t) for a, b in zip(q0, q1, strict=True)]
    q, qd, qdd = (np.stack([c[i] for c in cols], axis=1) for i in range(3))
    run = ad.trajectory_run(model, t, q, qd, qdd)
    return ad.duty_cycle(model, run, dwell=0.5)


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--motors", type=int, default=100)
    p.add_argument("--gearboxes", type=int, default=100)
    p.add_argument("--drives", type=int, default=0)
    p.add_argument("--samples", type=int, default=201)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args(argv)
    path = common.robot_urdf("ur5")
    if path is None:
        raise SystemExit("example-robot-data is not installed (pip install '.[test]')")
    model = ad.load_urdf(str(path))
    # a 3 kg payload at the tool flange
    frame = "tool0" if "tool0" in model.frame_names else model.frame_names[-1]
    model = model.with_payload(frame, 3.0, com=(0.0, 0.0, 0.05))
    cycle = ur5_cycle(model, args.samples)
    with tempfile.TemporaryDirectory() as tmp:
        catalog = synthetic_catalog(Path(tmp), args.motors, args.gearboxes, args.drives)
    drives = args.drives > 0
    sel = ad.select_drivetrain(model, cycle, catalog, drives=drives)  # warm-up
    walls, cpus = [], []
    for _ in range(args.repeats):
        w0, c0 = time.perf_counter(), time.process_time()
        sel = ad.select_drivetrain(model, cycle, catalog, drives=drives)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    per_joint = args.motors * args.gearboxes * max(args.drives, 1)
    cols = ["motor", "gearbox", "ok", "binding_check", "margin", "mass"]
    print(sel.table[cols].to_string())
    print(
        f"{len(sel.table)} joints x {per_joint} combinations, {len(cycle.t)} samples per "
        f"period: wall {np.median(walls):.2f} s (runs {', '.join(f'{w:.2f}' for w in walls)}), "
        f"CPU {np.median(cpus):.2f} s, passes {sel.passes}"
    )
    common.write_json(
        common.RESULTS / "select_drivetrain.json",
        {
            "command": "python -m benchmarks.select_drivetrain " + " ".join(sys.argv[1:]),
            "machine": common.machine(),
            "joints": len(sel.table),
            "combinations_per_joint": per_joint,
            "samples_per_period": len(cycle.t),
            "wall_seconds": walls,
            "cpu_seconds": cpus,
            "passes": sel.passes,
            "choice": sel.table[cols].reset_index().to_dict("records"),
        },
    )


if __name__ == "__main__":
    main()
