"""Closed-loop benchmark: error at the end time against CPU time, armdyn against MuJoCo, Pinocchio
and Exudyn on the same mechanisms, in one run.

``python -m benchmarks.closed_loop [PROBLEM ...] [--quick]`` (from the repository root) writes
``benchmarks/results/closed_loop.json`` (``closed_loop_quick.json`` with ``--quick``) and prints
the table of docs/benchmarks.md ("Closed loops against the peers").

Problems (each released at rest in its assembled configuration, no drives):

- ``four_bar``: :func:`armdyn.scenes.four_bar` (crank 0.3, coupler 0.6, rocker 0.5, ground
  0.7 m, crank at 60 deg, gravity -y), 1.5 s of free swinging, the loop closed by an inline
  joint (``closure="inline"``: no redundant rows); ``four_bar_revolute``: the same closed by a
  revolute (3 redundant rows: armdyn's minimum-norm dense KKT path, the peers' models alike).
- ``slider_crank``: the slider-crank of :func:`armdyn.scenes.slider_crank` (crank 0.1, rod
  0.35 m) with gravity -y and the crank released at 60 deg, 2 s; the loop closed at the
  rod-slider pin by an inline joint.
- ``squeezer``: Andrews' squeezer (:func:`armdyn.scenes.standard.andrews_squeezer`), 0.03 s.
- ``palletizer``, ``delta``: :func:`armdyn.scenes.palletizer` and
  :func:`armdyn.scenes.delta_robot` (when the installed armdyn has them), 0.5 s and 1 s
  under gravity (the palletizer falls 1.3 m in 0.5 s; later it folds through configurations
  where the runs stop agreeing at 1e-3). The delta's reference is armdyn's own DOP853 at
  1e-13: Pinocchio has no distance constraint (its rods with ball ends would need rod bodies,
  another mechanism), so the peers' smallest errors are the only check of it.

Error: the largest deviation of the bodies' centres of mass (world, [m]) at the end time from
a tight reference. Reference: SciPy DOP853 at rtol = atol = 1e-13 on Pinocchio's constrained
dynamics (``pin.constraintDynamics``, Baumgarte-stabilised) of the same mechanism; for the
squeezer the seven-angle index-1 equations of the Test Set (:mod:`benchmarks.references`). The
JSON records how far armdyn's DOP853 at rtol 1e-12 is from it (``reference_check``): a second,
independent method.

Curves (each point: the median CPU time of warm repeats of the whole run, and its error; the
sweep's times are consecutive, not interleaved):

- armdyn: :func:`armdyn.work_precision` (``simulate``, Cartesian formulation) with DOP853 and
  DOPRI5 over tolerances (atol = rtol), one output interval;
- MuJoCo: RK4 at fixed steps, the loops as ``connect`` (or tendon) equalities as stiff as MuJoCo
  allows (impedance 0.9999, time constant 2 steps: :mod:`benchmarks.peers.closed_loops`);
- Pinocchio: ``pin.constraintDynamics`` (proximal KKT, Baumgarte Kp = 100, Kd = 20) integrated
  by SciPy ``solve_ivp`` DOP853 over tolerances;
- Exudyn: redundant coordinates, GeneralizedAlpha and TrapezoidalIndex2 at fixed steps.

The peer models are built from the armdyn model's data (:mod:`benchmarks.peers.loop_models`;
the squeezer's MuJoCo and Exudyn models are :mod:`benchmarks.peers.closed_loops`'), and checked
to be the same mechanism in tests/peers/test_peer_closed_loop_bench.py (accelerations at a
moving state against armdyn's).

``ratio`` in the 1e-6 table (``rounds_1e-6`` in the JSON): the sweep only picks each curve's
cheapest point reaching 1e-6; those points are then re-timed in ``ROUNDS`` (9; 3 in --quick)
interleaved rounds, each round running every chosen point once in a rotating order (a run
under 30 ms repeated within its sample), on the process CPU clock (``time.process_time``: all
peers run in this process). Per round a library's time is its fastest curve's, and the ratio
peer / armdyn is taken within the round, so a load burst on this shared machine scales both
sides of a ratio alike. The table gives the median time over the rounds and the median of the
per-round ratios with their [min, max]. The median rather than the minimum: the CPU clock
already excludes time spent descheduled, what load remains (cache and memory-bandwidth
contention from the other processes) slows either side of a round, and the median of the
paired ratios is the typical ratio, not the luckiest one. The 1e-3 table is the sweep's
(fastest point each, one run, no spread).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from dataclasses import dataclass, field

import armdyn as ad
import numpy as np
from armdyn.scenes import basic, standard

from benchmarks import common, references
from benchmarks.peers import closed_loops as pcl
from benchmarks.peers import loop_models as lm

TARGETS = (1e-3, 1e-6)
BAUMGARTE = (100.0, 20.0)  # Kp [1/s^2], Kd [1/s]: alpha = 10 1/s, critically damped
REF_RTOL = 1e-13
MIN_SAMPLE_S = 0.03  # a sample repeats runs shorter than this (clock granularity, jitter)
ROUNDS = 9  # interleaved timing rounds of each curve's point to 1e-6 (3 in --quick)
HALF_DECADES = tuple(float(f"{10 ** (-k / 2):.3g}") for k in range(6, 21))  # 1e-3 ... 1e-10


@dataclass
class LoopProblem:
    name: str
    title: str
    t_end: float
    build: object  # () -> armdyn Model
    # half decades from 1e-3: loose enough that every curve's cheapest point reaching 1e-6 is
    # inside the sweep, not its loosest setting
    armdyn_rtols: tuple = HALF_DECADES
    mujoco_steps: tuple = tuple(4e-3 / 2**k for k in range(8))  # 4e-3 ... 3.125e-5
    pin_rtols: tuple = HALF_DECADES
    exudyn_steps: tuple = (250, 500, 1000, 2000, 4000, 8000, 16000)
    quick: dict = field(default_factory=dict)  # curve kind -> settings in --quick
    extra_tau: object = None  # Pinocchio force elements besides gravity
    special: object = None  # () -> {"mujoco": MujocoPeer-like, "exudyn": ExudynPeer-like, ...}


def slider_crank_falling(angle: float = np.pi / 3, closure: str = "inline") -> ad.Model:
    """The slider-crank of :func:`armdyn.scenes.slider_crank` (crank 0.1 m, 1 kg; rod 0.35 m,
    0.5 kg; slider 2 kg on a prismatic joint along x) with gravity -y and the crank released at
    ``angle`` from +x. ``closure="inline"`` (default) closes the loop at the rod-slider pin with
    an inline joint (2 rows: 17 independent rows, none redundant), ``"revolute"`` with a
    revolute (20 rows of rank 17: 3 redundant), the same motion."""
    crank, rod = 0.1, 0.35
    b = ad.ModelBuilder(gravity=(0.0, -9.81, 0.0))
    a = crank * np.array([np.cos(angle), np.sin(angle), 0.0])
    s = np.array([a[0] + np.sqrt(rod**2 - a[1] ** 2), 0.0, 0.0])
    ez = (0, 0, 1)

    def rod_inertia(m, length, axis):
        # a slender cylinder of radius 1 cm along ``axis`` (world x or the rod's direction)
        ia, it = 0.5 * m * 1e-4, m * (3e-4 + length**2) / 12.0
        d = axis / np.linalg.norm(axis)
        return it * np.eye(3) + (ia - it) * np.outer(d, d)

    b.add_body("crank", 1.0, rod_inertia(1.0, crank, a), position=a / 2)
    b.add_body("rod", 0.5, rod_inertia(0.5, rod, s - a), position=(a + s) / 2)
    b.add_body("slider", 2.0, [1e-3, 1e-3, 1e-3], position=s)
    b.add_revolute("crank_pin", "ground", "crank", point=(0, 0, 0), axis=ez)
    b.add_revolute("crank_rod", "crank", "rod", point=a, axis=ez)
    if closure == "inline":
        b.add_inline("rod_slider", "rod", "slider", point=s, axis=ez)
    else:
        b.add_revolute("rod_slider", "rod", "slider", point=s, axis=ez)
    b.add_prismatic("guide", "ground", "slider", point=s, axis=(1, 0, 0))
    return b.finalize()


# -- the squeezer: its peers are benchmarks.peers.closed_loops' -------------------------------


def squeezer_com(angles: np.ndarray) -> np.ndarray:
    """The seven angles (n, 7) -> the bodies' CoM positions (n, 21), z = 0."""
    out = []
    for q in np.atleast_2d(angles):
        com = np.array(standard.squeezer_points(q)["com"])
        out.append(np.column_stack([com, np.zeros(7)]).ravel())
    return np.array(out)


def squeezer_extra_tau():
    """Pinocchio joint torques of the squeezer's motor (0.033 N m on joint O) and spring
    (c0 (L - l0) between the world point C and D on K3)."""
    p = standard.SQUEEZER
    pts = standard.squeezer_points(p["q0"])
    c = np.array([*pts["C"], 0.0])
    d_local = np.array([*(pts["D"] - pts["com"][2]), 0.0])  # K3 starts unrotated

    def tau(peer, q, _v):
        pin, m, d = peer.pin, peer.model, peer.data
        pin.computeJointJacobians(m, d, q)
        pin.updateFramePlacements(m, d)
        fid = peer.frames["K3"]
        x = d.oMf[fid]
        r = x.rotation @ d_local
        point = x.translation + r
        jac = pin.getFrameJacobian(m, d, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        skew = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
        jd = jac[:3] + skew.T @ jac[3:]  # v_D = v + w x r = v - r x w
        length = np.linalg.norm(point - c)
        f = -p["c0"] * (length - p["l0"]) * (point - c) / length
        out = jd.T @ f
        out[m.joints[m.getJointId("O")].idx_v] += p["mom"]
        return out

    return tau


class _SqueezerMujoco:
    """:func:`benchmarks.peers.closed_loops.mujoco_squeezer` observing the CoM positions."""

    def __init__(self):
        self.peer = pcl.mujoco_squeezer()
        self.mujoco, self.model = self.peer.mujoco, self.peer.model

    def set_step(self, h):
        self.peer.set_step(h)

    def run(self, data, t_end, n_out):
        return self.peer.run(data, t_end, n_out)

    def observe(self, qpos):
        return squeezer_com(self.peer.observe(qpos))


class _SqueezerExudyn:
    """:func:`benchmarks.peers.closed_loops.exudyn_squeezer` observing the CoM positions."""

    def __init__(self):
        self.peer = pcl.exudyn_squeezer()

    def runner(self, t_end, n_steps, method):
        solve = self.peer.runner(t_end, 1, n_steps, method)

        def run():
            angles, stats = solve()
            return squeezer_com(angles[-1:]), stats

        return run


def _machine(name):
    from armdyn import scenes

    return getattr(scenes, name)()


PROBLEMS = {
    "four_bar": LoopProblem(
        "four_bar",
        "Four-bar (armdyn.scenes.four_bar, closure='inline'), free swing under gravity, 1.5 s",
        1.5,
        lambda: basic.four_bar(closure="inline"),
        quick={"armdyn": (1e-8,), "mujoco": (1.25e-4,), "pin": (1e-8,), "exudyn": (2000,)},
    ),
    "four_bar_revolute": LoopProblem(
        "four_bar_revolute",
        "The same four-bar closed by a revolute (3 redundant rows), 1.5 s",
        1.5,
        lambda: basic.four_bar(closure="revolute"),
        quick={"armdyn": (1e-8,), "mujoco": (1.25e-4,), "pin": (1e-8,), "exudyn": (2000,)},
    ),
    "slider_crank": LoopProblem(
        "slider_crank",
        "Slider-crank (crank 0.1 m, rod 0.35 m) released at 60 deg under gravity, 2 s",
        2.0,
        slider_crank_falling,
        quick={"armdyn": (1e-8,), "mujoco": (1.25e-4,), "pin": (1e-8,), "exudyn": (2000,)},
    ),
    "squeezer": LoopProblem(
        "squeezer",
        "Andrews' squeezer (Hairer-Wanner VII.7; IFToMM A03), 0.03 s",
        0.03,
        standard.andrews_squeezer,
        mujoco_steps=tuple(4e-4 / 2**k for k in range(9)),  # 4e-4 ... 1.5625e-6
        exudyn_steps=(600, 1200, 2400, 4800, 9600, 19200, 38400),
        quick={"armdyn": (1e-8,), "mujoco": (1.25e-5,), "pin": (1e-8,), "exudyn": (2400,)},
        extra_tau=squeezer_extra_tau(),
        special=lambda: {"mujoco": _SqueezerMujoco(), "exudyn": _SqueezerExudyn()},
    ),
    "palletizer": LoopProblem(
        "palletizer",
        "Palletizer (armdyn.scenes.palletizer), released under gravity, 0.5 s",
        0.5,
        lambda: _machine("palletizer"),
        quick={"armdyn": (1e-8,), "mujoco": (1.25e-4,), "pin": (1e-8,), "exudyn": (1000,)},
    ),
    "delta": LoopProblem(
        "delta",
        "Delta robot (armdyn.scenes.delta_robot), released under gravity, 1 s",
        1.0,
        lambda: _machine("delta_robot"),
        quick={"armdyn": (1e-8,), "mujoco": (1.25e-4,), "pin": (1e-8,), "exudyn": (1000,)},
    ),
}
ALL = ("four_bar", "four_bar_revolute", "slider_crank", "squeezer", "palletizer", "delta")


def _without_drives(model):
    """The problems run free: a machine scene built with drives is refused (its drives would
    prescribe the motion)."""
    if model.n_drives:
        raise ValueError("closed_loop: the benchmark's mechanisms must be built without drives")
    return model


# -- references -------------------------------------------------------------------------------


def pinocchio_reference(problem: LoopProblem, topo: lm.Topology) -> np.ndarray:
    """CoM positions at the end time, (1, 3 nb): DOP853 at rtol 1e-13 on Pinocchio's model."""
    from scipy.integrate import solve_ivp

    peer = lm.PinocchioLoop(topo, BAUMGARTE, prox=(1e-14, 1e-10, 100), extra_tau=problem.extra_tau)
    f, y0 = peer.rhs()
    sol = solve_ivp(f, (0.0, problem.t_end), y0, method="DOP853", rtol=REF_RTOL, atol=REF_RTOL)
    if not sol.success:
        raise RuntimeError(f"closed_loop: the reference run failed: {sol.message}")
    return peer.observe_y(sol.y[:, -1:])


def reference(problem: LoopProblem, topo: lm.Topology) -> tuple[np.ndarray, str]:
    if problem.name == "squeezer":
        angles = references.squeezer_angles(np.array([0.0, problem.t_end]))
        return squeezer_com(angles[-1:]), "seven-angle index-1 equations, DOP853 at rtol 1e-13"
    try:
        return (
            pinocchio_reference(problem, topo),
            "Pinocchio constraintDynamics (Baumgarte-stabilised), SciPy DOP853 at rtol 1e-13",
        )
    except NotImplementedError as exc:
        # no independent exact model (Pinocchio has no distance rods): armdyn's own DOP853 at
        # 1e-13, checked only by the peers' convergence to it (their smallest errors)
        res = ad.simulate(
            topo.model,
            problem.t_end,
            integrator="dop853",
            rtol=REF_RTOL,
            atol=REF_RTOL,
            output_dt=problem.t_end,
            limits="ignore",
        )
        return (
            lm.Topology.observe_u(np.asarray(res.u)[-1]),
            f"armdyn DOP853 at rtol 1e-13 (not independent: {exc})",
        )


def _err(obs, ref) -> float:
    return common.max_error(np.asarray(obs)[-1:], ref)


# -- curves -----------------------------------------------------------------------------------


def armdyn_curve(problem, model, integrator, rtols, ref, repeats) -> list[dict]:
    """:func:`armdyn.work_precision` on the Cartesian formulation, one output interval."""
    t = np.array([0.0, problem.t_end])
    u0 = np.asarray(model.u0, dtype=float)
    ref2 = np.vstack([lm.Topology.observe_u(u0), ref])
    res = ad.work_precision(
        model,
        problem.t_end,
        integrators=[integrator],
        rtols=list(rtols),
        reference=(t, ref2),
        n_out=1,
        observe=lambda r: lm.Topology.observe_u(r.u),
        error_measure="max |CoM - CoM_ref| at the end time [m]",
        repeats=repeats,
        max_steps=10_000_000,
        limits="ignore",
    )
    points = []
    for s, row in zip(rtols, res.table.itertuples(index=False), strict=True):
        if row.status == "failed":
            points.append({"setting": s, "failed": row.message[:200], "error": float("nan")})
        else:
            points.append(
                {
                    "setting": s,
                    "cpu_s": row.cpu_s,
                    "repeats": int(row.repeats),
                    "error": row.error,
                    "steps": int(row.steps),
                    "rhs_evals": int(row.rhs_evals),
                }
            )
    return points


def mujoco_curve(peer, t_end, steps, ref, repeats) -> list[dict]:
    points = []
    for h in steps:
        point = {"setting": float(h), "steps": round(t_end / h)}
        try:
            peer.set_step(h)
            data = peer.mujoco.MjData(peer.model)
            sec, reps, qpos = common.cpu_time(lambda d=data: peer.run(d, t_end, 1), repeats)
            point.update(cpu_s=sec, repeats=reps, error=_err(peer.observe(qpos[-1:]), ref))
        except (RuntimeError, ValueError) as exc:
            point.update(failed=str(exc)[:200], error=float("nan"))
        points.append(point)
    return points


def pinocchio_curve(problem, topo, rtols, ref, repeats) -> list[dict]:
    from scipy.integrate import solve_ivp

    peer = lm.PinocchioLoop(topo, BAUMGARTE, extra_tau=problem.extra_tau)
    f, y0 = peer.rhs()
    points = []
    for rtol in rtols:

        def call(rtol=rtol):
            return solve_ivp(f, (0.0, problem.t_end), y0, method="DOP853", rtol=rtol, atol=rtol)

        sec, reps, sol = common.cpu_time(call, repeats)
        point = {"setting": rtol, "cpu_s": sec, "repeats": reps, "rhs_evals": int(sol.nfev)}
        if sol.success:
            point["error"] = _err(peer.observe_y(sol.y[:, -1:]), ref)
        else:
            point.update(error=float("nan"), failed=str(sol.message)[:200])
        points.append(point)
    return points


def exudyn_curve(peer, t_end, method, steps, ref, repeats) -> list[dict]:
    points = []
    for n in steps:
        point = {"setting": t_end / n, "steps": int(n)}
        try:
            solve = peer.runner(t_end, n, method)
            sec, reps, (obs, stats) = common.cpu_time(solve, repeats)
            point.update(
                cpu_s=sec,
                repeats=reps,
                error=_err(obs, ref),
                newton_iterations=stats["newton_iterations"],
            )
        except RuntimeError as exc:
            point.update(failed=str(exc)[:200], error=float("nan"))
        points.append(point)
    return points


# -- interleaved rounds: the ratio's timing -------------------------------------------------


def _armdyn_runner(problem, model, integrator):
    def make(rtol):
        return lambda: ad.simulate(
            model,
            problem.t_end,
            integrator=integrator,
            rtol=rtol,
            atol=rtol,
            output_dt=problem.t_end,
            coordinates="cartesian",
            max_steps=10_000_000,
            limits="ignore",
        )

    return make


def _mujoco_runner(peer, t_end):
    def make(h):
        def run():
            peer.set_step(h)  # the curve's step (one MuJoCo curve: set on every call, cheap)
            return peer.run(peer.mujoco.MjData(peer.model), t_end, 1)

        return run

    return make


def _pinocchio_runner(problem, topo):
    from scipy.integrate import solve_ivp

    f, y0 = lm.PinocchioLoop(topo, BAUMGARTE, extra_tau=problem.extra_tau).rhs()
    return lambda rtol: (
        lambda: solve_ivp(f, (0.0, problem.t_end), y0, method="DOP853", rtol=rtol, atol=rtol)
    )


def _exudyn_runner(peer, t_end, method):
    def make(h):
        solve = peer.runner(t_end, round(t_end / h), method)
        keep = getattr(peer, "_keep", None)  # the system container owning this runner's mbs

        def run():
            return solve(), keep

        return run

    return make


def _chosen(points, target):
    """The curve's point that reached ``target`` at the least CPU time in the sweep, or None."""
    ok = [q for q in points if q.get("error", np.nan) <= target and "cpu_s" in q]
    return min(ok, key=lambda q: q["cpu_s"]) if ok else None


def interleaved_rounds(curves, makers, target, rounds) -> dict:
    """Re-time, in ``rounds`` interleaved rounds, each curve's cheapest point to ``target``:
    every round runs each chosen point once (process CPU clock; the order rotates from round to
    round, so none is always first), so a load burst that slows one round slows armdyn and the
    peers alike. Per library and round, the time is its fastest curve's; the per-round ratio
    peer / armdyn is then paired within the round. Returns per library its chosen points, the
    per-round times and their median, and per peer the ratios' median, min and max."""
    chosen = {}
    for key, pts in curves.items():
        q = _chosen(pts, target)
        if q is not None and key in makers:
            chosen[key] = (q["setting"], makers[key](q["setting"]))
    keys = list(chosen)
    calls = {}
    for key in keys:  # warm-up; a run under MIN_SAMPLE_S is repeated within each sample
        t0 = time.process_time()
        chosen[key][1]()
        calls[key] = max(1, min(50, int(MIN_SAMPLE_S / max(time.process_time() - t0, 1e-6))))
    per_curve = {k: [] for k in keys}
    for r in range(rounds):
        for k in keys[r % len(keys) :] + keys[: r % len(keys)] if keys else []:
            t0 = time.process_time()
            for _ in range(calls[k]):
                chosen[k][1]()
            per_curve[k].append((time.process_time() - t0) / calls[k])
    libs = {}
    for k in keys:
        libs.setdefault(k.split()[0], []).append(k)
    out = {"target": target, "rounds": rounds, "clock": "time.process_time", "libraries": {}}
    for lib, ks in libs.items():
        times = np.min([per_curve[k] for k in ks], axis=0)
        out["libraries"][lib] = {
            "points": {k: chosen[k][0] for k in ks},
            "calls_per_sample": {k: calls[k] for k in ks},
            "round_cpu_s": [float(t) for t in times],
            "median_cpu_s": float(np.median(times)),
        }
    a = out["libraries"].get("armdyn")
    out["ratios"] = {}
    for lib, rec in out["libraries"].items():
        if lib == "armdyn" or a is None:
            continue
        rr = np.array(rec["round_cpu_s"]) / np.array(a["round_cpu_s"])
        out["ratios"][lib] = {
            "median": float(np.median(rr)),
            "min": float(rr.min()),
            "max": float(rr.max()),
            "per_round": [float(x) for x in rr],
        }
    return out


def _settings(problem, kind, quick):
    full = {
        "armdyn": problem.armdyn_rtols,
        "mujoco": problem.mujoco_steps,
        "pin": problem.pin_rtols,
        "exudyn": problem.exudyn_steps,
    }[kind]
    return problem.quick.get(kind, full[:1]) if quick else full


def run_problem(name: str, quick: bool = False, echo: bool = True) -> dict:
    p = PROBLEMS[name]
    model = _without_drives(p.build())
    topo = lm.Topology(model)
    ref, ref_source = reference(p, topo)
    repeats = 3 if quick else 5
    special = p.special() if p.special else {}
    curves = {}
    makers = {}

    def add(key, fn):
        curves[key] = fn()
        if echo:
            _echo(key, curves[key])

    for integ in ("dop853", "dopri5"):
        rt = _settings(p, "armdyn", quick)
        add(f"armdyn {integ}", lambda i=integ, r=rt: armdyn_curve(p, model, i, r, ref, repeats))
        makers[f"armdyn {integ}"] = _armdyn_runner(p, model, integ)
    with contextlib.suppress(ImportError):
        import mujoco  # noqa: F401

        mj = special.get("mujoco") or lm.MujocoLoop(topo)
        steps = _settings(p, "mujoco", quick)
        add("MuJoCo rk4", lambda: mujoco_curve(mj, p.t_end, steps, ref, repeats))
        makers["MuJoCo rk4"] = _mujoco_runner(mj, p.t_end)
    not_run = {}
    with contextlib.suppress(ImportError):
        import pinocchio  # noqa: F401

        rt = _settings(p, "pin", quick)
        try:
            add(
                "Pinocchio constraintDynamics + SciPy DOP853",
                lambda: pinocchio_curve(p, topo, rt, ref, repeats),
            )
            makers["Pinocchio constraintDynamics + SciPy DOP853"] = _pinocchio_runner(p, topo)
        except NotImplementedError as exc:
            not_run["Pinocchio"] = str(exc)
    with contextlib.suppress(ImportError):
        import exudyn  # noqa: F401

        ex = special.get("exudyn") or lm.ExudynLoop(topo)
        for method in pcl.EXUDYN_METHODS:
            n = _settings(p, "exudyn", quick)
            add(f"Exudyn {method}", lambda m=method, n=n: exudyn_curve(ex, p.t_end, m, n, ref, 1))
            makers[f"Exudyn {method}"] = _exudyn_runner(ex, p.t_end, method)
    check = {}
    if not quick:
        tight = armdyn_curve(p, model, "dop853", (1e-12,), ref, 1)[0]
        check["armdyn_dop853_1e-12_vs_reference_m"] = tight["error"]
    return {
        "problem": name,
        "title": p.title,
        "t_end": p.t_end,
        "bodies": len(topo.bodies),
        "joints": len(topo.joints),
        "error": "max |CoM - CoM_ref| over the bodies at the end time [m]",
        "reference": ref_source,
        "reference_check": check,
        "curves": curves,
        "not_run": not_run,
        "fastest_to": {f"{t:g}": fastest(curves, t) for t in TARGETS},
        "rounds_1e-6": interleaved_rounds(curves, makers, 1e-6, 3 if quick else ROUNDS),
    }


def cpu_to(points, target):
    ok = [q["cpu_s"] for q in points if q.get("error", np.nan) <= target]
    return min(ok) if ok else None


def fastest(curves: dict, target: float) -> dict:
    """Per library (armdyn, MuJoCo, Pinocchio, Exudyn): the fastest curve's CPU time to reach
    ``target`` (None: no point reached it) and that curve."""
    out = {}
    for key, pts in curves.items():
        lib = key.split()[0]
        t = cpu_to(pts, target)
        if t is not None and (out.get(lib) is None or t < out[lib]["cpu_s"]):
            out[lib] = {"cpu_s": t, "curve": key}
        out.setdefault(lib, None)
    return out


def _echo(key, pts):
    for q in pts:
        if "failed" in q:
            print(f"  {key:46s} {q['setting']:9.2e}  failed: {q['failed'][:80]}")
        else:
            print(
                f"  {key:46s} {q['setting']:9.2e}  error {q['error']:9.2e}  "
                f"cpu {q['cpu_s'] * 1e3:9.2f} ms"
            )


PEERS = ("MuJoCo", "Pinocchio", "Exudyn")


def table(results: dict, target: float = 1e-6) -> str:
    """Markdown: per problem, the median CPU time of each library to reach ``target`` over the
    interleaved rounds (``rounds_1e-6``; for other targets the sweep's fastest points) and the
    peer/armdyn ratio: the median of the per-round ratios and their [min, max]."""
    spread = " [min, max] over rounds" if target == 1e-6 else ""
    lines = [
        f"| problem | armdyn to {target:g} [ms] | "
        + " | ".join(f"{p} [ms] (ratio{spread})" for p in PEERS)
        + " |",
        "|---|---|" + "---|" * len(PEERS),
    ]
    for r in results.values():
        rounds = r.get("rounds_1e-6") if target == 1e-6 else None
        if rounds is None:
            best = r["fastest_to"][f"{target:g}"]
            times = {k: (None if v is None else v["cpu_s"]) for k, v in best.items()}
            ratios = {}
        else:
            times = {k: v["median_cpu_s"] for k, v in rounds["libraries"].items()}
            ran = {k.split()[0] for k in r["curves"]}
            times.update({k: None for k in ran if k not in times})
            ratios = rounds["ratios"]
        a = times.get("armdyn")
        cells = [r["problem"], "not reached" if a is None else f"{a * 1e3:.3g}"]
        for peer in PEERS:
            b = times.get(peer, "absent")
            if b == "absent":
                cells.append("not run")
            elif b is None:
                cells.append("not reached")
            elif peer in ratios:
                q = ratios[peer]
                cells.append(f"{b * 1e3:.3g} ({q['median']:.1f}x [{q['min']:.1f}, {q['max']:.1f}])")
            else:
                cells.append(f"{b * 1e3:.3g}" + ("" if a is None else f" ({b / a:.1f}x)"))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def available(names) -> list[str]:
    """The problems whose models build here (the machines need armdyn.scenes.palletizer and
    delta_robot)."""
    out = []
    for n in names:
        try:
            PROBLEMS[n].build()
        except (AttributeError, ImportError):
            continue
        out.append(n)
    return out


def run(problems=None, quick=False, echo=True, out=None) -> dict:
    names = available(list(ALL) if not problems or problems == ["all"] else list(problems))
    results = {}
    for name in names:
        if echo:
            print(f"{name}: {PROBLEMS[name].title}")
        results[name] = run_problem(name, quick=quick, echo=echo)
    command = "python -m benchmarks.closed_loop" + (" --quick" if quick else "")
    if problems and problems != ["all"]:
        command += " " + " ".join(problems)
    doc = {
        "command": command,
        "machine": common.machine(),
        "problems": results,
        "table_1e-6": table(results),
        "table_1e-3": table(results, 1e-3),
    }
    if out is None:
        out = common.RESULTS / ("closed_loop_quick.json" if quick else "closed_loop.json")
    if out:
        common.write_json(out, doc)
    if echo:
        print(doc["table_1e-6"])
    return doc


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.closed_loop")
    parser.add_argument("problems", nargs="*", default=["all"], help=f"{', '.join(ALL)} or all")
    parser.add_argument("--quick", action="store_true", help="one point per curve")
    parser.add_argument("--out", default=None, help="JSON path (default: benchmarks/results/)")
    args = parser.parse_args(argv)
    run(args.problems, quick=args.quick, out=args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
