"""Forward dynamics on long spatial chains (issue 20): how every path of armdyn's public
``forward_dynamics`` scales with the number of links, against Pinocchio's ABA and MuJoCo.

``python -m benchmarks.chain_scaling`` builds ``armdyn.scenes.random_chain(n)`` for
n = 10, 30, 100, 300, 1000, rebuilds the same chain in Pinocchio from the model's own data
(:func:`benchmarks.peers.pinocchio.pinocchio_tree`) and in MuJoCo (built from that Pinocchio
model with ``mujoco.MjSpec``: nested bodies, hinge joints about each joint frame's z axis, the
same inertias and gravity; no geoms, damping or armature), checks that the three give the same joint
accelerations at a random state, and times one call of each in the same process in interleaved
rounds (:func:`benchmarks.common.interleaved_times`):

- ``armdyn.forward_dynamics(model, q, qd, tau, method=m, data=d)`` for m = crba, aba,
  cartesian, auto (one state per call, through the Python API);
- ``pin.aba(model, data, q, v, tau)``;
- MuJoCo: ``qpos``, ``qvel``, ``qfrc_applied`` set and ``mj_forward`` (its full forward pass;
  the accelerations are ``qacc``).

and, for n <= 300, one RK4 step of ``armdyn.simulate`` (``dt`` = 1 ms, 100 steps per run, one
output) with ``coordinates="joint"``, ``"cartesian"`` and ``"auto"`` (the target: ``auto``
within 10 % of the faster of the other two). Each forward-dynamics time is reported as a ratio
to ``pin.aba`` (median over the rounds of the per-round ratio,
:func:`benchmarks.common.paired_ratio`). Writes ``benchmarks/results/chain_scaling.json`` and
a log-log plot ``benchmarks/results/chain_scaling.png``. ``--quick``: n up to 300, fewer rounds.
"""

from __future__ import annotations

import argparse

import armdyn
import numpy as np
from armdyn.scenes import random_chain

from .common import RESULTS, interleaved_times, machine, paired_ratio, write_json
from .peers.pinocchio import pinocchio_tree

SIZES = (10, 30, 100, 300, 1000)
METHODS = ("crba", "aba", "cartesian", "auto")


def mujoco_of(pin, pm):
    """The MjModel of a Pinocchio tree of revolute-z joints (one body per joint), built with
    ``mujoco.MjSpec`` (an MJCF of a 1000-link chain would nest deeper than its XML parser
    allows): each body at its joint placement, a hinge about z, the same inertia (explicit, not
    balanced), the same gravity; contacts and constraints disabled."""
    import mujoco

    spec = mujoco.MjSpec()
    spec.option.gravity = np.asarray(pm.gravity.linear, dtype=float)
    spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT) | int(
        mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    )
    spec.compiler.balanceinertia = False
    bodies = {0: spec.worldbody}
    for j in range(1, pm.njoints):  # parents before children
        m = pm.jointPlacements[j]
        x = pin.Quaternion(np.asarray(m.rotation))
        b = bodies[pm.parents[j]].add_body(
            name=f"b{j}", pos=np.asarray(m.translation), quat=[x.w, x.x, x.y, x.z]
        )
        b.add_joint(name=pm.names[j], type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0])
        inertia = pm.inertias[j]
        i = inertia.inertia
        b.explicitinertial = True
        b.mass = float(inertia.mass)
        b.ipos = np.asarray(inertia.lever, dtype=float)
        b.fullinertia = [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]
        bodies[j] = b
    return spec.compile()


def pinocchio_works(n: int) -> bool:
    """Whether Pinocchio can make a Data for the n-link chain: Pinocchio 4.1 crashes
    (segmentation fault in ``createData``) on chains of about 800 links and more, so the check
    runs in a child process."""
    import subprocess
    import sys

    code = (
        "from armdyn.scenes import random_chain\n"
        "from benchmarks.peers.pinocchio import pinocchio_tree\n"
        f"pinocchio_tree(random_chain({n}))[0].createData()\n"
    )
    return subprocess.run([sys.executable, "-c", code], capture_output=True).returncode == 0


def one_size(n: int, repeat: int, seed: int = 3) -> dict:
    import mujoco
    import pinocchio as pin

    model = random_chain(n)
    d = armdyn.Data(model)
    pm, idx = pinocchio_tree(model)
    with_pin = n <= 500 or pinocchio_works(n)
    pd = pm.createData() if with_pin else None
    mm = mujoco_of(pin, pm)
    md = mujoco.MjData(mm)
    # MuJoCo's joints are in Pinocchio's order (depth first; a chain: the same order)
    assert mm.nv == pm.nv == n
    rng = np.random.default_rng(seed)
    q, qd, tau = (rng.uniform(-1.0, 1.0, n) for _ in range(3))
    qp, vp, tp = (np.empty(n) for _ in range(3))
    qp[idx], vp[idx], tp[idx] = q, qd, tau
    md.qpos[:], md.qvel[:], md.qfrc_applied[:] = qp, vp, tp

    def mj():
        mujoco.mj_forward(mm, md)
        return md.qacc

    # the reference: pin.aba, or (where Pinocchio crashes) armdyn's ABA, ratios to it too
    if with_pin:
        ref = pin.aba(pm, pd, qp, vp, tp).copy()
    else:
        ref = np.empty(n)
        ref[idx] = armdyn.forward_dynamics(model, q, qd, tau, method="aba", data=d)
    base = "pin.aba" if with_pin else "aba"
    scale = np.abs(ref).max()
    err = {}
    for m in METHODS:
        a = armdyn.forward_dynamics(model, q, qd, tau, method=m, data=d)
        err[m] = float(np.abs(a - ref[idx]).max() / scale)
    err["mujoco"] = float(np.abs(mj() - ref).max() / scale)
    fns = {
        **{
            m: (lambda m=m: armdyn.forward_dynamics(model, q, qd, tau, method=m, data=d))
            for m in METHODS
        },
        "mujoco": mj,
    }
    if with_pin:
        fns["pin.aba"] = lambda: pin.aba(pm, pd, qp, vp, tp)
    # about 20 ms per function and round
    number = max(1, int(2e-2 / (1e-6 * (2.0 + 0.4 * n))))
    if n >= 300:  # the cubic CRBA path would dominate the run
        number = max(1, number // 4)
    t = interleaved_times(fns, number=number, repeat=repeat)
    cost = armdyn.dynamics_cost(model)
    return {
        "n": n,
        "us_per_call": {k: 1e6 * t[k] for k in fns},
        "ratios_to": base,
        "ratio_to_pin_aba": {k: paired_ratio(t, k, base) for k in fns},
        "rel_error_vs_pin_aba": err,
        "auto_takes": cost["auto"],
        "joint_takes": cost["joint"],
        "predicted_us": {k: cost[f"{k}_us"] for k in ("crba", "aba", "cartesian")},
        "calls_per_round": number,
        "rounds": repeat,
    }


def simulate_steps(n: int, repeat: int) -> dict:
    model = random_chain(n)
    steps, dt = 100, 1e-3
    forms = {}

    def run(c):
        r = armdyn.simulate(
            model, steps * dt, integrator="rk4", dt=dt, output_dt=steps * dt, coordinates=c
        )
        forms[c] = r.stats["formulation"]

    fns = {c: (lambda c=c: run(c)) for c in ("joint", "cartesian", "auto")}
    t = interleaved_times(fns, number=1, repeat=repeat)
    per_step = {c: 1e6 * t[c] / steps for c in fns}
    faster = "joint" if per_step["joint"] <= per_step["cartesian"] else "cartesian"
    return {
        "n": n,
        "us_per_rk4_step": per_step,
        "faster": faster,
        "auto_over_faster": paired_ratio(t, "auto", faster),
        "auto_formulation": forms["auto"],
    }


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ns = [r["n"] for r in rows]
    for k, style in [
        ("crba", "o-"),
        ("aba", "s-"),
        ("cartesian", "^-"),
        ("auto", "x--"),
        ("pin.aba", "k.-"),
        ("mujoco", "d-"),
    ]:
        pts = [(r["n"], r["us_per_call"][k]) for r in rows if k in r["us_per_call"]]
        ax.loglog(*zip(*pts, strict=True), style, label=k)
    ax.loglog(
        ns,
        [rows[0]["us_per_call"]["pin.aba"] * n / ns[0] for n in ns],
        ":",
        c="grey",
        label="slope 1",
    )
    ax.set_xlabel("links n")
    ax.set_ylabel("microseconds per forward-dynamics call")
    ax.set_title("random_chain(n): armdyn.forward_dynamics vs pin.aba, MuJoCo")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    sizes = [n for n in SIZES if n <= 300] if args.quick else SIZES
    repeat = 5 if args.quick else 11
    rows = []
    for n in sizes:
        r = one_size(n, repeat)
        rows.append(r)
        rat = r["ratio_to_pin_aba"]
        print(
            f"n={n:5d}  {r['ratios_to']} {r['us_per_call'][r['ratios_to']]:9.1f} us"
            f" | x {r['ratios_to']}: "
            + "  ".join(f"{k} {rat[k]:.2f}" for k in (*METHODS, "mujoco"))
            + f"  (auto: {r['auto_takes']}; worst rel. error "
            + f"{max(r['rel_error_vs_pin_aba'].values()):.1e})",
            flush=True,
        )
    sims = []
    for n in [n for n in sizes if n <= 300]:
        r = simulate_steps(n, repeat)
        sims.append(r)
        st = r["us_per_rk4_step"]
        print(
            f"n={n:5d}  RK4 step: joint {st['joint']:8.1f} us  cartesian {st['cartesian']:8.1f} us"
            f"  auto {st['auto']:8.1f} us ({r['auto_over_faster']:.2f}x the faster)"
            f"  [{r['auto_formulation']}]",
            flush=True,
        )
    out = {
        "command": "python -m benchmarks.chain_scaling" + (" --quick" if args.quick else ""),
        "machine": machine(),
        "rows": rows,
        "simulate_rk4": sims,
    }
    if not args.quick:
        write_json(RESULTS / "chain_scaling.json", out)
        plot(rows, RESULTS / "chain_scaling.png")
    else:
        print(out["command"], "(not written)")


if __name__ == "__main__":
    main()
