"""``python -m benchmarks.rollout``: armdyn.rollout of 64 UR5 falls on 1 and 2 threads, and
against MuJoCo's ``mujoco.rollout`` on the same problem at equal final error.

The problem: the UR5 of example-robot-data released from 64 starts around ``UR5_Q0`` (each joint
perturbed by up to +-0.3 rad, at rest) and falling under gravity for ``T_END`` seconds, joint
limits ignored on both sides (MuJoCo's import keeps the URDF limits; ``mujoco_from_urdf`` turns
them off, as it turns off damping and armature, which the URDF does not have).

1. Threads: ``armdyn.rollout(..., threads=1)`` and ``threads=2`` (median of REPEATS, interleaved);
   the ratio t(2) / t(1), target <= 0.65 on a 2-core machine; every run compared with a serial
   ``armdyn.simulate`` of the same inputs (max |difference| over all tables, target <= 1e-12).
   The machine is shared: its two-process ratio (two busy processes vs one) is recorded
   before and after, with the CPU seconds per wall second of the 2-thread batches.
2. Against MuJoCo at equal final error: the reference is armdyn DOP853 at rtol 1e-12 (joint
   coordinates) per run; each side's final error is the largest |q(T_END) - q_ref(T_END)| over
   runs and joints. armdyn: the cheapest (integrator, rtol) of a short list that reaches
   ``TARGET`` (1e-6 rad); MuJoCo: RK4 at the largest time step of a halving list that reaches it
   (its Euler and implicit methods are first order: far more steps). Both batches then run on
   2 threads; the ratio of runs per second (armdyn / MuJoCo) is recorded (goal >= 2).

Results: benchmarks/results/rollout.json.
"""

from __future__ import annotations

import subprocess
import sys
import time

import armdyn as ad
import numpy as np

from benchmarks import common
from benchmarks.peers.mujoco import mujoco_from_urdf

N_RUNS = 64
T_END = 2.0
TARGET = 1e-6
REPEATS = 5
OPTS = dict(limits="ignore")
ARMDYN_SETTINGS = [
    (integ, coords, rtol)
    for coords in ("joint", "cartesian")
    for integ, rtols in (("dop853", (1e-7, 1e-8, 1e-9, 1e-10)), ("dopri5", (1e-8, 1e-9, 1e-10)))
    for rtol in rtols
]
MUJOCO_STEPS = [T_END / n for n in (250, 500, 1000, 2000, 4000, 8000, 16000)]


def starts(model):
    rng = np.random.default_rng(23)
    q0 = np.array(common.UR5_Q0)[None, :] + rng.uniform(-0.3, 0.3, size=(N_RUNS, model.n_coords))
    return q0, np.zeros((N_RUNS, model.n_dofs))


def wall(fn, repeat=REPEATS):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def final_error(q_final, ref_final):
    return float(np.abs(common.wrap(q_final - ref_final)).max())


def max_table_difference(a, b):
    worst = 0.0
    for name in ("t", "u", "v", "q", "qd", "qdd", "reaction_forces", "reaction_torques"):
        x, y = getattr(a, name), getattr(b, name)
        if x.shape != y.shape:
            return float("inf")
        if x.size:
            worst = max(worst, float(np.abs(x - y).max()))
    return worst


def machine_parallelism() -> float:
    """Wall time of two busy single-threaded processes side by side over that of one: 1.0 when
    two cores are free, 2.0 when the machine's load leaves one (a shared machine: what any
    two-thread batch can reach at the moment of the measurement)."""
    cmd = [sys.executable, "-c", "sum(range(3 * 10**7))"]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True)
    one = time.perf_counter() - t0
    t0 = time.perf_counter()
    procs = [subprocess.Popen(cmd) for _ in range(2)]
    for p in procs:
        p.wait()
    return (time.perf_counter() - t0) / one


def threads_part(model, q0, qd0, opts):
    fns = {k: (lambda k=k: ad.rollout(model, q0, qd0, T_END, threads=k, **opts)) for k in (1, 2)}
    times = {1: [], 2: []}
    cpu = {1: [], 2: []}
    probes = [machine_parallelism()]
    for _ in range(REPEATS):  # interleaved: the machine's load hits both alike
        for k, fn in fns.items():
            t0, c0 = time.perf_counter(), time.process_time()
            runs = fn()
            times[k].append(time.perf_counter() - t0)
            cpu[k].append(time.process_time() - c0)
    probes.append(machine_parallelism())
    t1, t2 = float(np.median(times[1])), float(np.median(times[2]))
    worst = max(
        max_table_difference(r, ad.simulate(model, T_END, q0=q0[k], qd0=qd0[k], **opts))
        for k, r in enumerate(runs)
    )
    return {
        "settings": opts,
        "seconds_1_thread": t1,
        "seconds_2_threads": t2,
        "ratio_2_over_1": t2 / t1,
        "target_ratio": 0.65,
        # process CPU seconds per wall second during the 2-thread batches (2.0: both threads
        # ran all along), and the machine's two-process ratio before and after (see
        # machine_parallelism): on a loaded machine the thread ratio cannot beat it
        "cpu_per_wall_2_threads": float(np.median(np.array(cpu[2]) / np.array(times[2]))),
        "machine_two_process_ratio_before_after": probes,
        "max_difference_to_serial_simulate": worst,
        "target_difference": 1e-12,
        "failed_runs": sum(r.error is not None for r in runs),
    }


def mujoco_batch(mj, perm, q0, h, nthread):
    import mujoco
    from mujoco import rollout

    mj.opt.timestep = h
    mj.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    datas = [mujoco.MjData(mj) for _ in range(nthread)]
    size = mujoco.mj_stateSize(mj, spec)
    state0 = np.empty((len(q0), size))
    for k in range(len(q0)):
        d = datas[0]
        mujoco.mj_resetData(mj, d)
        d.qpos[perm] = q0[k]
        mujoco.mj_getState(mj, d, state0[k], spec)
    nstep = round(T_END / h)

    def run():
        state, _ = rollout.rollout(mj, datas, state0, nstep=nstep)
        return state[:, -1, 1 : 1 + mj.nq][:, perm]

    return run


def main(argv=None) -> int:
    path = common.robot_urdf("ur5")
    if path is None:
        print("example-robot-data is not installed", file=sys.stderr)
        return 1
    model = ad.load_urdf(path)
    q0, qd0 = starts(model)
    out = {"problem": f"UR5 falls: {N_RUNS} starts, {T_END} s, limits ignored", "n_runs": N_RUNS}
    out["machine"] = common.machine()

    # reference: armdyn DOP853 at rtol 1e-12 per run
    ref_opts = dict(integrator="dop853", rtol=1e-12, atol=1e-14, coordinates="joint", **OPTS)
    ref = np.array([r.q[-1] for r in ad.rollout(model, q0, qd0, T_END, **ref_opts)])
    # a check of the reference itself: Cartesian DOP853 at rtol 1e-12 agrees with it
    cart = ad.rollout(model, q0[:4], qd0[:4], T_END, **{**ref_opts, "coordinates": "cartesian"})
    out["reference"] = {
        "settings": ref_opts,
        "cartesian_vs_joint_final_difference": final_error(
            np.array([r.q[-1] for r in cart]), ref[:4]
        ),
    }

    # armdyn: the cheapest setting reaching TARGET (timed on 2 threads)
    tried = []
    for integ, coords, rtol in ARMDYN_SETTINGS:
        opts = dict(integrator=integ, coordinates=coords, rtol=rtol, atol=rtol * 1e-2, **OPTS)
        runs = ad.rollout(model, q0, qd0, T_END, threads=2, **opts)
        err = final_error(np.array([r.q[-1] for r in runs]), ref)
        if err > TARGET:
            tried.append({"settings": opts, "final_error": err})
            continue
        sec, _ = wall(lambda opts=opts: ad.rollout(model, q0, qd0, T_END, threads=2, **opts), 3)
        tried.append({"settings": opts, "final_error": err, "seconds_2_threads": sec})
    reached = [t for t in tried if "seconds_2_threads" in t]
    best = min(reached, key=lambda t: t["seconds_2_threads"])
    out["armdyn_settings_tried"] = tried
    out["armdyn"] = best

    # threads: the chosen setting on 1 and 2 threads
    out["threads"] = threads_part(model, q0, qd0, best["settings"])

    # MuJoCo: RK4 at the largest step reaching TARGET
    mj, _ = mujoco_from_urdf(path)
    names = [mj.joint(i).name for i in range(mj.njnt)]
    perm = np.array([mj.jnt_qposadr[names.index(n)] for n in model.coord_names])
    mj_tried = []
    chosen = None
    for h in MUJOCO_STEPS:
        fn = mujoco_batch(mj, perm, q0, h, 2)
        err = final_error(fn(), ref)
        mj_tried.append({"timestep": h, "final_error": err})
        if err <= TARGET:
            chosen = h
            break
    out["mujoco_settings_tried"] = mj_tried
    if chosen is None:
        out["mujoco"] = {"note": f"RK4 did not reach {TARGET} rad down to h = {MUJOCO_STEPS[-1]}"}
    else:
        # interleaved rounds: the machine's load hits armdyn and MuJoCo alike
        mj2, mj1 = mujoco_batch(mj, perm, q0, chosen, 2), mujoco_batch(mj, perm, q0, chosen, 1)
        ours = best["settings"]
        t_mj2, t_mj1, t_ad = [], [], []
        for _ in range(REPEATS):
            t_mj2.append(wall(mj2, 1)[0])
            t_mj1.append(wall(mj1, 1)[0])
            t_ad.append(wall(lambda: ad.rollout(model, q0, qd0, T_END, threads=2, **ours), 1)[0])
        sec2, sec1 = float(np.median(t_mj2)), float(np.median(t_mj1))
        best = {**best, "seconds_2_threads": float(np.median(t_ad))}
        out["armdyn"] = best
        qf = mj2()
        out["mujoco"] = {
            "integrator": "RK4",
            "timestep": chosen,
            "final_error": final_error(qf, ref),
            "seconds_2_threads": sec2,
            "seconds_1_thread": sec1,
        }
        armdyn_rate = N_RUNS / best["seconds_2_threads"]
        mujoco_rate = N_RUNS / sec2
        out["throughput"] = {
            "armdyn_runs_per_s": armdyn_rate,
            "mujoco_runs_per_s": mujoco_rate,
            "ratio_armdyn_over_mujoco": armdyn_rate / mujoco_rate,
            "goal_ratio": 2.0,
        }
    path_out = common.write_json(common.RESULTS / "rollout.json", out)
    th = out["threads"]
    print(
        f"threads: 1 -> {th['seconds_1_thread']:.3f} s, 2 -> {th['seconds_2_threads']:.3f} s, "
        f"ratio {th['ratio_2_over_1']:.3f} (target <= 0.65; CPU/wall with 2 threads "
        f"{th['cpu_per_wall_2_threads']:.2f}; the machine's two-process ratio "
        f"{th['machine_two_process_ratio_before_after']}); max difference to serial "
        f"simulate {th['max_difference_to_serial_simulate']:.1e}"
    )
    print(f"armdyn at {TARGET}: {best}")
    print(f"mujoco: {out['mujoco']}")
    if "throughput" in out:
        print(
            f"throughput ratio armdyn/mujoco: {out['throughput']['ratio_armdyn_over_mujoco']:.2f}"
        )
    print(f"wrote {path_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
