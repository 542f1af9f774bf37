"""The least-energy motion of the UR5 example (armdyn.motion.least_energy): copper loss of the
pick-to-place swing against the quintic of the same duration, the limits that bind, and the
solve's iterations and CPU time, at a few durations; the same move with the elbow kept near
its pick pose (within ±0.35 rad, by joint limits: how much of the saving comes from folding the
arm, a shorter lever for gravity) and with lossless gears (efficiency 1: how much comes from the
gear's efficiency, whose holding branch at standstill, motor_side's conservative convention,
the quintic pays on the joints it keeps still); and the home-to-pick move, where every joint
moves.

    python -m benchmarks.least_energy [--out benchmarks/results/least_energy.json]

The model: the UR5 of example-robot-data with a 3 kg payload 5 cm beyond tool0 and an actuator
on every joint from the example catalog (:data:`UR5_DRIVES`: motor rotor plus the gear's input
inertia, the gear's ratio and efficiency, the motor's datasheet); tests/motion/test_energy.py
takes it from here.
"""

from __future__ import annotations

import argparse
import os
import sys

import armdyn as ad
import numpy as np

from benchmarks import common

#: the UR5's drivetrains from the example catalog: (motor, strain-wave gear) per joint
UR5_DRIVES = {
    "shoulder_pan_joint": ("FL-85x23", "SW-32-100"),
    "shoulder_lift_joint": ("FL-85x23", "SW-32-100"),
    "elbow_joint": ("FL-85x13", "SW-25-100"),
    "wrist_1_joint": ("FL-50x14", "SW-14-100"),
    "wrist_2_joint": ("FL-50x14", "SW-14-100"),
    "wrist_3_joint": ("FL-50x14", "SW-14-100"),
}
#: the home, pick and place poses of notebooks/sizing_ur5.ipynb (pick to place: a 1.6 rad
#: swing about the base, the wrist following; home to pick: every joint moves)
HOME = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])
PICK = np.array([0.7, -1.05, 1.85, -2.37, -1.57, 0.7])
PLACE = np.array([-0.9, -1.05, 1.85, -2.37, -1.57, -0.9])


def ur5_actuated(
    friction: bool = False, joint_limits: dict | None = None, efficiency: float | None = None
):
    """The actuated UR5 with its payload (None without example-robot-data); ``friction`` adds
    motor-side viscous (2e-5 N m s/rad) and Coulomb (0.01 N m) friction; ``joint_limits``
    {joint: (lower, upper)} replaces those position limits; ``efficiency`` replaces every
    gear's."""
    path = common.robot_urdf("ur5")
    if path is None:
        return None
    cat = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG)
    bare = ad.load_urdf(path)
    at = (ad.frame_pose(bare, np.zeros(6), "tool0") @ [0.0, 0.0, 0.05, 1.0])[:3]
    b = ad.urdf_builder(str(path))
    b.add_body("payload", 3.0, [3.0 * 0.1**2 / 6] * 3, position=at)
    b.add_fixed("payload_mount", bare.frame("tool0")["body"], "payload")
    for joint, (motor, gear) in UR5_DRIVES.items():
        m, g = cat.motors.loc[motor], cat.gearboxes.loc[gear]
        b.add_actuator(
            joint,
            gear_ratio=float(g["ratio"]),
            rotor_inertia=float(m["rotor_inertia"] + g["input_inertia"]),
            efficiency=float(g["efficiency"]) if efficiency is None else efficiency,
            friction_viscous=2e-5 if friction else 0.0,
            friction_coulomb=0.01 if friction else 0.0,
            motor=cat.motor(motor),
        )
    for joint, (lo, hi) in (joint_limits or {}).items():
        k = list(bare.dof_names).index(joint)
        b.set_joint_limits(
            joint, lo, hi, effort=bare.coord_effort_limit[k], velocity=bare.coord_velocity_limit[k]
        )
    return b.finalize()


def _case(model, duration: float, move=(PICK, PLACE)) -> dict:
    from armdyn.motion import least_energy

    seconds, _, traj = common.cpu_time(lambda: least_energy(model, *move, duration), 1)
    i = traj.info
    return {
        "move": "pick -> place" if move[0] is PICK else "home -> pick",
        "duration_s": duration,
        "copper_J": i["value"],
        "quintic_copper_J": i["baseline"],
        "saving_percent": i["saving_percent"],
        "quintic_within_limits": bool(
            all(np.nanmax(list(v.values())) <= 1.0 for v in i["baseline_limit_usage"].values())
        ),
        "active_limits": [list(a) for a in i["active_limits"]],
        "largest_usage": {
            k: float(np.nanmax(list(v.values()))) for k, v in i["limit_usage"].items()
        },
        "elbow_range_rad": [float(traj.q[:, 2].min()), float(traj.q[:, 2].max())],
        "iterations": i["iterations"],
        "cpu_s": seconds,
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="benchmarks/results/least_energy.json")
    args = parser.parse_args(argv)
    model = ur5_actuated()
    if model is None:
        print("example-robot-data is not installed")
        return 1
    elbow = {"elbow_joint": (PICK[2] - 0.35, PICK[2] + 0.35)}
    kept = ur5_actuated(joint_limits=elbow)
    lossless = ur5_actuated(efficiency=1.0)
    cases = [dict(_case(model, d), variant="as built") for d in (1.2, 1.45, 2.0)]
    cases.append(dict(_case(kept, 1.45), variant="elbow within its pick pose +- 0.35 rad"))
    cases.append(dict(_case(lossless, 1.45), variant="every gear's efficiency 1"))
    cases.append(dict(_case(model, 1.2, (HOME, PICK)), variant="as built"))
    cases.append(dict(_case(lossless, 1.2, (HOME, PICK)), variant="every gear's efficiency 1"))
    for c in cases:
        print(
            f"{c['move']} in {c['duration_s']:.2f} s, {c['variant']}: copper "
            f"{c['copper_J']:.4g} J, quintic {c['quintic_copper_J']:.4g} J (within limits: "
            f"{c['quintic_within_limits']}), saving {c['saving_percent']:.1f} %, active "
            f"{c['active_limits']}, {c['iterations']} iterations, {c['cpu_s']:.2f} s CPU"
        )
    out = {
        "command": "python -m benchmarks.least_energy " + " ".join(argv or sys.argv[1:]),
        "machine": common.machine(),
        # a shared machine: the 1-minute load average when the run ended (2 cores)
        "load_average_1min": os.getloadavg()[0],
        "cases": cases,
    }
    print("written", common.write_json(args.out, out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
