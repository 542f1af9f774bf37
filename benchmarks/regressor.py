"""The cost of armdyn's joint torque regressor (issue 35), in one run, as ratios.

    python -m benchmarks.regressor [--number 500] [--rows 1000] [--repeat 15]
        [--cpp build-bench/regressor_cost]

Per robot (example-robot-data: the UR5 and the Panda on a fixed base, solo12 on a free flyer;
each ``<mimic>`` joint its own coordinate, as in Pinocchio):

* "From C++": the per-row time of the 2-D batch ``armdyn.joint_torque_regressor`` (``--rows``
  states in one call, the loop in C++ without the GIL, each Y written into the output array) over
  the per-row time of the 2-D batch ``armdyn.inverse_dynamics`` on the same states (the issue's
  target: <= 3, ``meets_target``); the batch ``energy_regressor`` likewise. The batch regressor
  also writes n_dofs x n_params numbers per row where inverse_dynamics writes n_dofs: on solo12
  25 kB per row, which the time includes.
* From Python, one state per call: ``armdyn.joint_torque_regressor`` against Pinocchio's
  ``computeJointTorqueRegressor`` (and each library's regressor over its own inverse dynamics
  call), timed in interleaved rounds on the process's CPU clock, the ratio taken round by round.
* With ``--cpp PATH`` (the executable of benchmarks/cpp/regressor_cost.cpp, built as
  benchmarks/cpp/CMakeLists.txt says), its lines: the per-call time in C++ on one Data, without
  Python or output arrays, against one ``inverse_dynamics`` call.
* The answers against Pinocchio's in the same run (worst relative error of the body columns over
  the batch's first states, after the reordering of
  ``tests/identification/test_regressor_pinocchio.py``, which asserts it).

Written to ``benchmarks/results/regressor.json`` with the command and the machine.
"""

from __future__ import annotations

import argparse
import subprocess
import sys

import armdyn as ad
import numpy as np

from benchmarks import common
from benchmarks.derivatives import (
    ROBOTS,
    DerivativePair,
    interleaved_cpu_times,
    rel_error,
    robot_path,
)

TARGET_CPP = 3.0  # batch joint_torque_regressor per row / batch inverse_dynamics per row


def body_columns(pair: DerivativePair) -> tuple[np.ndarray, np.ndarray]:
    """(armdyn columns, Pinocchio columns) of the bodies' parameters: body ``B``'s block is
    Pinocchio's block of the joint whose child link is ``B``."""
    pm = pair.pm
    ours, theirs = [], []
    for k, name in enumerate(ad.dynamic_parameter_names(pair.am)):
        if name.endswith(".m"):
            joint = pm.frames[pm.getFrameId(name[:-2])].parentJoint
            ours += range(k, k + 10)
            theirs += range(10 * (joint - 1), 10 * joint)
    return np.array(ours), np.array(theirs)


def python_timings(pair: DerivativePair, number: int, repeat: int) -> dict:
    """Microseconds per call from Python, one state per call, and the ratios."""
    pin, pm, pd, am = pair.pin, pair.pm, pair.pd, pair.am
    q, qd, x = pair.random_state(np.random.default_rng(1))
    qp, vp, xp = pair.q_pin(q), pair.v_pin(qd), pair.v_pin(x)
    t = interleaved_cpu_times(
        {
            "pin_regressor": lambda: pin.computeJointTorqueRegressor(pm, pd, qp, vp, xp),
            "armdyn_regressor": lambda: ad.joint_torque_regressor(am, q, qd, x),
            "pin_rnea": lambda: pin.rnea(pm, pd, qp, vp, xp),
            "armdyn_inverse_dynamics": lambda: ad.inverse_dynamics(am, q, qd, x),
            "armdyn_energy_regressor": lambda: ad.energy_regressor(am, q, qd),
        },
        number,
        repeat,
    )
    r = {f"{name}_us": 1e6 * t[name] for name in t if name != "rounds"}
    r["ratio_regressor_to_pinocchio"] = common.paired_ratio(t, "armdyn_regressor", "pin_regressor")
    r["armdyn_regressor_over_inverse_dynamics"] = common.paired_ratio(
        t, "armdyn_regressor", "armdyn_inverse_dynamics"
    )
    r["pin_regressor_over_rnea"] = common.paired_ratio(t, "pin_regressor", "pin_rnea")
    return r


def batch_timings(pair: DerivativePair, rows: int, number: int, repeat: int) -> dict:
    """Per-row microseconds of the 2-D batch calls, their ratios to the batch inverse_dynamics,
    and the batch regressor's worst error against Pinocchio on the first states."""
    am = pair.am
    q, qd, x = pair.random_state(np.random.default_rng(2), rows)
    t = interleaved_cpu_times(
        {
            "inverse_dynamics": lambda: ad.inverse_dynamics(am, q, qd, x),
            "joint_torque_regressor": lambda: ad.joint_torque_regressor(am, q, qd, x),
            "energy_regressor": lambda: ad.energy_regressor(am, q, qd),
        },
        number,
        repeat,
    )
    r = {"rows": rows, "n_params": len(ad.dynamic_parameters(am))}
    r.update({f"{name}_us_per_row": 1e6 * t[name] / rows for name in t if name != "rounds"})
    r["ratio_regressor_to_inverse_dynamics"] = common.paired_ratio(
        t, "joint_torque_regressor", "inverse_dynamics"
    )
    r["ratio_energy_regressor_to_inverse_dynamics"] = common.paired_ratio(
        t, "energy_regressor", "inverse_dynamics"
    )
    ours, theirs = body_columns(pair)
    y = ad.joint_torque_regressor(am, q[:20], qd[:20], x[:20])
    worst = 0.0
    for i in range(len(y)):
        ref = pair.pin.computeJointTorqueRegressor(
            pair.pm, pair.pd, pair.q_pin(q[i]), pair.v_pin(qd[i]), pair.v_pin(x[i])
        )
        worst = max(worst, rel_error(y[i][:, ours], np.asarray(ref)[pair.iv][:, theirs]))
    r["regressor_rel_error_vs_pinocchio"] = worst
    return r


def cpp_lines(exe: str, rounds: int = 200) -> dict:
    """The C++ benchmark's line per robot (its own median over interleaved rounds)."""
    out = {}
    for name, (_, fixed) in ROBOTS.items():
        cmd = [exe, robot_path(name), *([] if fixed else ["--floating"]), "--rounds", str(rounds)]
        line = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.strip()
        out[name] = {"command": " ".join(cmd), "output": line}
    return out


def run(number: int = 500, rows: int = 1000, repeat: int = 15, echo: bool = True) -> dict:
    """Every robot's timings and errors (:func:`python_timings`, :func:`batch_timings`)."""
    out = {}
    for name, (_, fixed) in ROBOTS.items():
        pair = DerivativePair(robot_path(name), fixed_base=fixed)
        rec = {
            "fixed_base": fixed,
            "n_dofs": pair.am.n_dofs,
            "cpp": batch_timings(pair, rows, 3, repeat),
            "python": python_timings(pair, number, repeat),
        }
        rec["meets_target"] = rec["cpp"]["ratio_regressor_to_inverse_dynamics"] <= TARGET_CPP
        out[name] = rec
        if echo:
            print(summary_line(name, rec), flush=True)
    return out


def summary_line(name: str, rec: dict) -> str:
    p, c = rec["python"], rec["cpp"]
    return (
        f"{name:7s} n={rec['n_dofs']:2d} p={c['n_params']:3d}  batch per row: ID "
        f"{c['inverse_dynamics_us_per_row']:.2f} us, regressor "
        f"{c['joint_torque_regressor_us_per_row']:.2f} us = "
        f"{c['ratio_regressor_to_inverse_dynamics']:.2f}x, energy "
        f"{c['energy_regressor_us_per_row']:.2f} us = "
        f"{c['ratio_energy_regressor_to_inverse_dynamics']:.2f}x  |  Python: regressor "
        f"{p['armdyn_regressor_us']:.2f} us / pin {p['pin_regressor_us']:.2f} us = "
        f"{p['ratio_regressor_to_pinocchio']:.2f}x  |  error vs pin "
        f"{c['regressor_rel_error_vs_pinocchio']:.1e}"
    )


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--number", type=int, default=500, help="calls per round (Python side)")
    p.add_argument("--rows", type=int, default=1000, help="states in the batch calls")
    p.add_argument("--repeat", type=int, default=15, help="interleaved rounds")
    p.add_argument("--cpp", help="the regressor_cost executable (benchmarks/cpp)")
    args = p.parse_args(argv)
    robots = run(args.number, args.rows, args.repeat)
    record = {
        "command": " ".join(["python -m benchmarks.regressor", *sys.argv[1:]]),
        "machine": common.machine(),
        "targets": {"cpp_batch_ratio_to_inverse_dynamics": TARGET_CPP},
        "robots": robots,
    }
    if args.cpp:
        record["cpp_per_call"] = cpp_lines(args.cpp)
        for name, rec in record["cpp_per_call"].items():
            print(f"{name:7s} C++: {rec['output'].split(': ', 1)[-1]}", flush=True)
    common.write_json(common.RESULTS / "regressor.json", record)


if __name__ == "__main__":
    main()
