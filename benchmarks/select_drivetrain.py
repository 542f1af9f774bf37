"""The drivetrain selection's screening speed (issue 33's target: 6 joints × 10,000 combinations
per joint in ≤ 10 s on the 2-core machine), through the public API.

    python -m benchmarks.select_drivetrain [--motors 100] [--gearboxes 100] [--drives 0]
        [--samples 201] [--repeats 3]

The UR5 (example-robot-data) with a 3 kg payload moves every joint rest to rest (a quintic,
1.2 s) and holds the end pose for a 0.5 s dwell, repeated forever (``armdyn.duty_cycle``); a
synthetic catalog of ``--motors`` motors and ``--gearboxes`` gearboxes (``--drives`` drives;
default none: motor × gearbox combinations) spanning small to large parts
(``armdyn.sizing.catalog.synthetic_catalog``); ``armdyn.select_drivetrain`` screens every
combination for every joint with the coupled passes (the actuators' masses carried). Reported:
the wall-clock and CPU time of the selection (median of ``--repeats`` runs after one warm-up),
the passes and the choice. Written to ``benchmarks/results/select_drivetrain.json``.
"""

from __future__ import annotations

import argparse
import sys
import time

import armdyn as ad
import numpy as np
from armdyn.sizing.catalog import synthetic_catalog

from benchmarks import common


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
    catalog = synthetic_catalog(args.motors, args.gearboxes, args.drives)
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
