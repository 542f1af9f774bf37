"""How soon Ctrl-C stops armdyn's compiled loops: the time from SIGINT to the KeyboardInterrupt.

    python -m benchmarks.interrupt_latency [--repeats 5]

Each case runs in a child Python that prints "ready" just before the long call; the parent
sleeps, sends SIGINT and reads back the time (``time.time()``, one clock for both processes)
at which the child caught the KeyboardInterrupt. Latency = caught − sent. The cases:

- ``simulate`` with each integrator (rk4 at dt 1e-5; dopri5/dop853 at rtol = atol = 1e-13;
  trbdf2 at 1e-9/1e-11; the kinematic path of a driven pendulum), t_end = 1e4 s;
- ``inverse_dynamics`` on a batch of 4e6 states of a two-link arm, and
  ``driven_inverse_dynamics`` at 3e6 times;
- ``load_urdf`` of a 12,000-link chain.

Prints the median and the largest latency per case over ``--repeats`` runs and the machine's
load average, and writes ``benchmarks/results/interrupt_latency.json``. The stepping loops poll
for signals every 5 ms of wall time, so an idle machine shows a few milliseconds; a loaded one
adds its scheduling delay (the child has to be given a core to notice). The tests
(tests/simulate/test_interrupt.py) check that the interrupt stops the work inside the call and
keeps the partial result, without timing it.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

from benchmarks import common

PROLOGUE = textwrap.dedent(
    """
    import json, signal, sys, time
    import numpy as np
    import armdyn as ad

    signal.signal(signal.SIGINT, signal.default_int_handler)
    case = sys.argv[1]
    """
)

SIMULATE = PROLOGUE + textwrap.dedent(
    """
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("bob", 1.0, np.eye(3) * 1e-3, position=(-0.5, 0.0, -0.8))
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    opts = dict(max_steps=10**10, output_dt=0.01)
    if case == "rk4":
        opts.update(integrator="rk4", dt=1e-5)
    elif case == "kinematic":
        b.add_drive("hinge", lambda t: (np.sin(t), np.cos(t), -np.sin(t)))
        opts.update(integrator="kinematic")
    elif case == "trbdf2":
        opts.update(integrator="trbdf2", rtol=1e-9, atol=1e-11)
    else:
        opts.update(integrator=case, rtol=1e-13, atol=1e-13)
    model = b.finalize()
    print("ready", flush=True)
    try:
        ad.simulate(model, 1e4, **opts)
        print(json.dumps({"completed": True}), flush=True)
    except KeyboardInterrupt:
        print(json.dumps({"caught": time.time()}), flush=True)
    """
)

INVERSE = PROLOGUE + textwrap.dedent(
    """
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("a", 1.0, np.eye(3) * 1e-2, position=(0.5, 0.0, 0.0))
    b.add_body("b", 1.0, np.eye(3) * 1e-2, position=(1.5, 0.0, 0.0))
    b.add_revolute("j1", "ground", "a", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_revolute("j2", "a", "b", (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    if case == "driven":
        b.add_drive("j1", lambda t: (np.sin(t), np.cos(t), -np.sin(t)))
        b.add_drive("j2", lambda t: (0.5 * t, 0.5, 0.0))
    model = b.finalize()
    rng = np.random.default_rng(1)
    if case == "batch":
        q, qd, qdd = (rng.standard_normal((4_000_000, 2)) for _ in range(3))
    else:
        ts = np.linspace(0.0, 1e4, 3_000_000)
    print("ready", flush=True)
    try:
        while True:
            if case == "batch":
                ad.inverse_dynamics(model, q, qd, qdd)
            else:
                ad.driven_inverse_dynamics(model, ts)
    except KeyboardInterrupt:
        print(json.dumps({"caught": time.time()}), flush=True)
    """
)

URDF = PROLOGUE + textwrap.dedent(
    """
    inertial = (
        '<inertial><origin xyz="0 0 0.05"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
        'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
    )
    parts = ['<robot name="chain">', f'<link name="l0">{inertial}</link>']
    for i in range(1, 12001):
        parts.append(f'<link name="l{i}">{inertial}</link>')
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
            f'<child link="l{i}"/><origin xyz="0 0 0.1"/><axis xyz="0 {i % 2} {1 - i % 2}"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
        )
    parts.append("</robot>")
    xml = "\\n".join(parts)
    print("ready", flush=True)
    try:
        while True:
            ad.load_urdf(xml)
    except KeyboardInterrupt:
        print(json.dumps({"caught": time.time()}), flush=True)
    """
)

#: (label, child code, argument, delay before the signal [s])
CASES = [
    *[(f"simulate {m}", SIMULATE, m, 1.0) for m in ("rk4", "dopri5", "dop853", "trbdf2")],
    ("simulate kinematic", SIMULATE, "kinematic", 1.0),
    ("inverse_dynamics batch", INVERSE, "batch", 0.25),
    ("driven_inverse_dynamics", INVERSE, "driven", 0.25),
    ("load_urdf 12000 links", URDF, "urdf", 0.5),
]


def latency(code: str, arg: str, delay: float) -> float:
    """Seconds from SIGINT to the child's KeyboardInterrupt (one run)."""
    proc = subprocess.Popen(
        [sys.executable, "-c", code, arg], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        if proc.stdout.readline().strip() != "ready":
            raise RuntimeError(proc.stderr.read())
        time.sleep(delay)
        sent = time.time()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=600)
    finally:
        if proc.poll() is None:
            proc.kill()
    report = json.loads(out.strip().splitlines()[-1])
    if "caught" not in report:
        raise RuntimeError(f"{arg}: the work ended before the signal: {report} {err}")
    return report["caught"] - sent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    rows = {}
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; {args.repeats} runs per case")
    print(f"{'case':28s} {'median ms':>10s} {'max ms':>10s}")
    for label, code, arg, delay in CASES:
        times = [latency(code, arg, delay) for _ in range(args.repeats)]
        rows[label] = {"median_s": float(np.median(times)), "max_s": max(times), "runs": times}
        print(f"{label:28s} {1e3 * np.median(times):10.1f} {1e3 * max(times):10.1f}")
    out = common.write_json(
        Path(__file__).parent / "results" / "interrupt_latency.json",
        {
            "command": "python -m benchmarks.interrupt_latency --repeats " + str(args.repeats),
            "machine": common.machine(),
            "load_average": load,
            "cases": rows,
        },
    )
    print(f"written {out}")


if __name__ == "__main__":
    main()
