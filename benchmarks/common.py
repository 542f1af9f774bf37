"""Helpers shared by every benchmark script and peer model: timing, errors, the example-robot-data
URDFs, machine information and the results folder.

Nothing here imports another module of ``benchmarks``, so every peer and script can import it.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import platform
import site
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"

ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
}
UR5_Q0 = (0.3, -1.0, 1.2, -0.5, 0.8, 0.1)  # the UR5 problem's start, Pinocchio joint order


def robots_dir() -> Path | None:
    """The ``robots`` folder of the installed example-robot-data (the cmeel wheel ships the data
    under ``cmeel.prefix/share/example-robot-data``, without a Python module), or None when the
    package is not installed."""
    sub = Path("cmeel.prefix") / "share" / "example-robot-data" / "robots"
    try:
        dist = importlib.metadata.distribution("example-robot-data")
        candidates = [Path(dist.locate_file(sub))]
    except importlib.metadata.PackageNotFoundError:
        candidates = []
    candidates += [Path(b) / sub for b in [*site.getsitepackages(), site.getusersitepackages()]]
    return next((p for p in candidates if p.is_dir()), None)


def robot_urdf(name: str) -> Path | None:
    """Path of an example-robot-data URDF, or None when the package is not installed."""
    base = robots_dir()
    p = None if base is None else base / ROBOTS[name]
    return p if p is not None and p.is_file() else None


def cpu_time(fn, repeats: int):
    """``(seconds, runs, result)``: the median CPU time of ``repeats`` warm calls of ``fn`` (after
    one warm-up call) and the last result. A first call longer than 2 s is itself the
    measurement: warm-up effects are below the noise there, and repeating it would only cost
    time."""
    t0 = time.process_time()
    out = fn()
    first = time.process_time() - t0
    if first > 2.0:
        return first, 1, out
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return float(np.median(times)), len(times), out


def median_time(fn, number: int, repeat: int = 7) -> float:
    """Median over ``repeat`` runs of the wall time per call of ``number`` calls of ``fn`` (after
    one warm-up call)."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t0) / number)
    return float(np.median(times))


def interleaved_times(fns: dict, number: int, repeat: int = 15) -> dict:
    """Seconds per call of each function of ``fns`` (name -> callable), measured in interleaved
    rounds: every round times ``number`` calls of each function in turn, so that a change in the
    machine's load falls on all of them alike. Returns, per name, the median over the rounds;
    and ``rounds`` (per name, the list of per-round times) for ratios taken round by round."""
    for fn in fns.values():
        fn()
    rounds = {name: [] for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            for _ in range(number):
                fn()
            rounds[name].append((time.perf_counter() - t0) / number)
    out = {name: float(np.median(t)) for name, t in rounds.items()}
    out["rounds"] = rounds
    return out


def paired_ratio(times: dict, a: str, b: str) -> float:
    """Median over the rounds of interleaved_times of time(a) / time(b)."""
    ra, rb = np.asarray(times["rounds"][a]), np.asarray(times["rounds"][b])
    return float(np.median(ra / rb))


def wrap(a):
    """Angles wrapped to [-pi, pi)."""
    return np.remainder(np.asarray(a) + np.pi, 2 * np.pi) - np.pi


def max_error(obs: np.ndarray, ref: np.ndarray, angular: bool = False) -> float:
    """Largest absolute deviation of ``obs`` from ``ref`` (wrapped for angles); NaN when the
    shapes differ or ``obs`` is not finite."""
    obs, ref = np.asarray(obs), np.asarray(ref)
    if obs.shape != ref.shape or not np.all(np.isfinite(obs)):
        return float("nan")
    d = obs - ref
    if angular:
        d = wrap(d)
    return float(np.abs(d).max())


def error(problem, obs: np.ndarray, ref: np.ndarray) -> float:
    """:func:`max_error` with the problem's ``angular`` flag."""
    return max_error(obs, ref, problem.angular)


def output_times(problem) -> np.ndarray:
    """The problem's output grid: ``n_out`` intervals over [0, ``t_end``]."""
    return np.linspace(0.0, problem.t_end, problem.n_out + 1)


def sweep_scipy(
    problem, method: str, rtols, ref, repeats: int = 5, rhs=None, observe=None
) -> list[dict]:
    """SciPy ``solve_ivp`` points (setting = rtol = atol) on ``rhs`` = (f, y0), by default the
    problem's ``scipy_rhs()``, observed by ``observe`` (default ``scipy_observe``). A run that
    stops early (a failed step, or an exactly singular matrix inside f) is a failed point that
    says why, the last output time reached and the latest time f was evaluated at (a rejected
    step's stages can lie beyond where the run got stuck)."""
    from scipy.integrate import solve_ivp

    f, y0 = rhs if rhs is not None else problem.scipy_rhs()
    observe = observe or problem.scipy_observe
    t_out = output_times(problem)
    reached = [0.0]

    def f_tracked(t, y):
        reached[0] = max(reached[0], t)
        return f(t, y)

    points = []
    for rtol in rtols:

        def call(rtol=rtol):
            reached[0] = 0.0
            return solve_ivp(
                f_tracked,
                (0.0, problem.t_end),
                y0,
                method=method,
                rtol=rtol,
                atol=rtol,
                t_eval=t_out,
            )

        point = {"setting": rtol}
        try:
            sec, reps, sol = cpu_time(call, repeats)
        except np.linalg.LinAlgError as exc:
            point.update(error=float("nan"), failed=f"at t = {reached[0]:.4g} s: {exc}"[:200])
            points.append(point)
            continue
        point.update(cpu_s=sec, repeats=reps, rhs_evals=int(sol.nfev))
        if sol.success:
            point["error"] = error(problem, observe(sol.y), ref)
        else:
            point.update(
                error=float("nan"),
                failed=f"stopped after the output at t = {sol.t[-1]:.4g} s (latest evaluation "
                f"at t = {reached[0]:.4g} s): {sol.message}"[:200],
            )
        points.append(point)
    return points


def machine() -> dict:
    """The CPU model, core count, Python version and system the results were measured on."""
    cpu = platform.processor()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "system": platform.platform(),
    }


def write_json(path, obj) -> Path:
    """Write ``obj`` as indented JSON (NumPy scalars as floats), creating the folder."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(obj, indent=1, default=float), encoding="utf-8")
    return path
