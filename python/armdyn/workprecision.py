"""Error against run time (work–precision) for the user's own model and initial state.

:func:`work_precision` sweeps the tolerance (DOPRI5, DOP853, TR-BDF2) or the fixed step (RK4) of
:func:`armdyn.simulate` on one output grid, measures each run's error against a reference
computed by a different method at a tight tolerance, and returns the table (a pandas DataFrame)
and a log-log plot of error against CPU seconds. ``python -m benchmarks.workprecision`` runs the
same function on the project's standard problems and the papers' arms.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core
from armdyn.simulation import simulate

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: integrators :func:`work_precision` sweeps, and their default settings
TOLERANCE_INTEGRATORS = ("dopri5", "dop853", "trbdf2")
INTEGRATORS = (*TOLERANCE_INTEGRATORS, "rk4", "kinematic")
DEFAULT_INTEGRATORS = ("dopri5", "dop853", "trbdf2", "rk4")
DEFAULT_RTOLS = {
    "dopri5": tuple(10.0**-k for k in range(3, 11)),  # 1e-3 ... 1e-10
    "dop853": tuple(10.0**-k for k in range(3, 11)),
    # second order: below 1e-8 its step count grows past what a sweep should spend
    "trbdf2": tuple(10.0**-k for k in range(3, 9)),  # 1e-3 ... 1e-8
}
#: RK4 steps: the output spacing divided by 1, 2, 4, ..., 32
RK4_DIVISORS = (1, 2, 4, 8, 16, 32)
#: the default reference: DOP853 at this tolerance (and one decade looser for its own error)
REFERENCE_RTOL = 1e-13

COLUMNS = (
    "integrator",
    "coordinates",
    "rtol",
    "atol",
    "dt",
    "error",
    "cpu_s",
    "steps",
    "rejected",
    "rhs_evals",
    "kkt_solves",
    "factorizations",
    "singular_evaluations",
    "integration_s",
    "max_position_residual",
    "repeats",
    "status",
    "message",
    "reference",
    "error_measure",
)
_COUNTERS = (
    "steps",
    "rejected",
    "rhs_evals",
    "kkt_solves",
    "factorizations",
    "singular_evaluations",
)


#: the most repeats of a work_precision point (each one a full run)
MAX_REPEATS = 1000


def _bad(msg: str) -> _core.ModelError:
    return _core.ModelError(f"work_precision: {msg}")


@dataclass
class WorkPrecisionResult:
    """Outputs of :func:`work_precision`.

    Attributes:
        table: pandas DataFrame, one row per run (columns in :data:`COLUMNS`): ``integrator``,
            ``coordinates`` (the formulation integrated), ``rtol`` and ``atol`` (NaN for RK4 and
            the kinematic path), ``dt`` (RK4's step, else NaN), ``error`` (the error measure
            below; NaN for a failed run), ``cpu_s`` (CPU seconds of the ``simulate`` call: the
            median of the warm repeats when ``repeats > 1``; for a failed run the time to the
            failure), the counters ``steps``, ``rejected``, ``rhs_evals``, ``kkt_solves``,
            ``factorizations``, ``singular_evaluations`` (nullable integers, from
            ``result.stats``), ``integration_s`` (``stats["seconds"]``: the CPU time of the
            integration alone, of the last repeat), ``max_position_residual`` (largest
            constraint residual over the outputs), ``repeats``, ``status`` (``"ok"``,
            ``"failed"``: the run raised :class:`armdyn.SolverError`, ``message`` says why, or
            ``"non-finite"``: outputs that are not finite), ``reference`` (the reference the
            row was measured against) and ``error_measure``.
        t: the output grid (n_out + 1,) [s].
        error_measure: what ``error`` measures, with its unit.
        reference: how each reference was obtained: ``{label: {"method", "formulation",
            "rtol", "estimated_error", ...}}``; ``estimated_error`` is the reference's own error
            estimate (the largest difference over the grid between it and the same method one
            decade looser; NaN for a reference given by the user): errors near it are not
            resolved.
        reference_values: ``{label: (n_out + 1, k)}`` the reference on the grid.
    """

    table: pd.DataFrame
    t: npt.NDArray[np.float64]
    error_measure: str
    reference: dict[str, dict[str, Any]] = field(default_factory=dict)
    reference_values: dict[str, npt.NDArray[np.float64]] = field(default_factory=dict)

    def floor(self) -> float:
        """The largest estimated error of the references used (NaN when unknown)."""
        errs = [r.get("estimated_error", math.nan) for r in self.reference.values()]
        errs = [e for e in errs if e is not None and np.isfinite(e)]
        return max(errs) if errs else math.nan

    def plot(
        self,
        path: str | os.PathLike[str] | None = None,
        title: str | None = None,
        ax: Axes | None = None,
    ) -> Figure | Axes:
        """Log-log plot of error against CPU seconds, one line per integrator (and
        formulation) in the order of the sweep, with the references' estimated error as a
        dotted line (:func:`armdyn.plotting.work_precision_figure`). Saved to ``path``
        when given. Returns the :class:`matplotlib.figure.Figure`, or with ``ax`` (a
        matplotlib Axes to draw into) that Axes.

        Raises:
            ImportError: matplotlib is missing (``pip install armdyn[plot]``).
        """
        from armdyn.plotting import work_precision_figure

        return work_precision_figure(self, path=path, title=title, ax=ax)


def _cpu_time(fn, repeats: int):
    """``(seconds, runs, result)`` of ``fn``. ``repeats == 1``: one call. Otherwise one warm-up
    call, then the median CPU time of ``repeats`` calls; a warm-up call longer than 2 s is itself
    the measurement (warm-up effects are below the noise there)."""
    t0 = time.process_time()
    out = fn()
    first = time.process_time() - t0
    if repeats <= 1 or first > 2.0:
        return first, 1, out
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return float(np.median(times)), len(times), out


def _angular_mask(model) -> np.ndarray:
    """True for the joint coordinates that are angles (revolute, the angle of a cylindrical
    joint; spherical, universal and the rest have no joint coordinates)."""
    per_type = {"revolute": (True,), "prismatic": (False,), "cylindrical": (True, False)}
    mask = []
    for jt in model.joint_types:
        mask.extend(per_type.get(str(jt).split(".")[-1].lower(), ()))
    if len(mask) != model.n_joint_coords:  # a joint type this map does not know: wrap nothing
        return np.zeros(model.n_joint_coords, dtype=bool)
    return np.array(mask, dtype=bool)


def _max_error(obs, ref, angular) -> float:
    """Largest absolute deviation (angles wrapped to [-pi, pi)); NaN for non-finite outputs or
    mismatched shapes."""
    obs, ref = np.asarray(obs, dtype=float), np.asarray(ref, dtype=float)
    if obs.shape != ref.shape or not np.all(np.isfinite(obs)):
        return math.nan
    d = obs - ref
    if np.any(angular):
        wrapped = np.remainder(d + np.pi, 2 * np.pi) - np.pi
        d = np.where(angular, wrapped, d) if np.ndim(angular) else wrapped
    return float(np.abs(d).max()) if d.size else 0.0


def _check_vector(name: str, x, n: int):
    if x is None:
        return None
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise _bad(f"{name} must be numbers, got {x!r}") from exc
    if a.shape != (n,):
        raise _bad(f"{name} needs {n} joint coordinates (model.n_coords), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        bad = [int(i) for i in np.flatnonzero(~np.isfinite(a))]
        raise _bad(f"{name} has non-finite entries at {bad}")
    return a


def _check_settings(name: str, values) -> tuple:
    try:
        vals = tuple(float(v) for v in values)
    except (TypeError, ValueError) as exc:
        raise _bad(f"{name} must be a sequence of positive numbers, got {values!r}") from exc
    if not vals:
        raise _bad(f"{name} is empty")
    for v in vals:
        if not (np.isfinite(v) and v > 0):
            raise _bad(f"{name} must be positive and finite, got {v}")
    return vals


def _reference_on_grid(reference, t: np.ndarray, model, observe_default: bool):
    """The user's reference as an array on the grid ``t``."""
    if callable(reference):
        vals = np.asarray(reference(t), dtype=float)
    else:
        if isinstance(reference, tuple) and len(reference) == 2:
            t_ref, vals = reference
        elif hasattr(reference, "t") and hasattr(reference, "q"):
            t_ref, vals = reference.t, reference.q
        else:
            raise _bad(
                "reference must be a callable t -> values, a tuple (t, values) or a result with "
                f"t and q (e.g. a SimulationResult); got {type(reference).__name__}"
            )
        t_ref = np.asarray(t_ref, dtype=float)
        vals = np.asarray(vals, dtype=float)
        if t_ref.shape != t.shape or not np.allclose(t_ref, t, rtol=0, atol=1e-12 * t[-1]):
            raise _bad(
                f"reference times do not match the output grid ({len(t)} points from 0 to "
                f"{t[-1]:g} s, n_out={len(t) - 1}); pass a callable to evaluate it on the grid"
            )
    if vals.ndim == 1:
        vals = vals[:, None]
    if vals.shape[0] != len(t):
        raise _bad(f"reference has {vals.shape[0]} rows for {len(t)} output times")
    if observe_default and vals.shape[1] != model.n_joint_coords:
        raise _bad(
            f"reference has {vals.shape[1]} columns; the error compares the "
            f"{model.n_joint_coords} joint coordinates (model.joint_coord_names)"
        )
    if not np.all(np.isfinite(vals)):
        raise _bad("reference has non-finite values")
    return vals


def work_precision(
    model: _core.Model,
    t_end: float,
    q0: npt.ArrayLike | None = None,
    qd0: npt.ArrayLike | None = None,
    integrators: Sequence[str] | None = None,
    rtols: Sequence[float] | None = None,
    reference: Any = None,
    *,
    dts: Sequence[float] | None = None,
    n_out: int = 100,
    coordinates: str = "cartesian",
    atol_factor: float = 1.0,
    u0: npt.ArrayLike | None = None,
    v0: npt.ArrayLike | None = None,
    observe: Callable[..., Any] | None = None,
    angular: npt.ArrayLike | None = None,
    error_measure: str | None = None,
    repeats: int = 1,
    max_steps: int = 1_000_000,
    limits: str = "enforce",
) -> WorkPrecisionResult:
    """Error against CPU time of :func:`armdyn.simulate`'s integrators on the user's model.

    Every run integrates from the same initial state to ``t_end`` and writes its outputs on the
    grid of ``n_out`` equal intervals (``output_dt = t_end / n_out``). Each run's error is the
    largest absolute deviation over that grid of its joint coordinates ``result.q`` from a
    reference (rad for angles, wrapped to [-π, π), m for displacements).

    Args:
        model: a finalized :class:`armdyn.Model`.
        t_end: end time [s] (> 0).
        q0, qd0: initial joint coordinates and rates (``model.n_coords``,) as
            :func:`armdyn.simulate` takes them; ``None``: the model's assembled state at rest
            (or ``u0``/``v0``).
        integrators: any of ``"dopri5"``, ``"dop853"``, ``"trbdf2"``, ``"rk4"``,
            ``"kinematic"`` (a fully driven model: one run, nothing integrated). Default:
            DOPRI5, DOP853, TR-BDF2 and RK4.
        rtols: the relative tolerances of the error-controlled integrators, the same for each
            (a sequence) or per integrator (a dict). Default: 1e-3 … 1e-10 by decades
            (TR-BDF2, second order: 1e-3 … 1e-8). The absolute tolerance is tied to it:
            ``atol = atol_factor * rtol`` on every state component (m, rad, m/s, rad/s).
        reference: ``None`` (default): computed by a different method at rtol 1e-13, see
            below. Or the user's own: a callable ``t -> (len(t), k)`` values, a tuple
            ``(t, values)`` on the output grid, or a result with ``t`` and ``q`` on the grid
            (e.g. a :class:`SimulationResult` run with ``output_dt = t_end / n_out``); the
            values are the joint coordinates (``k = model.n_joint_coords``), or what ``observe``
            returns.
        dts: RK4's fixed steps; default: the output spacing ``t_end / n_out`` divided by 1, 2,
            4, 8, 16, 32.
        n_out: number of output intervals (≥ 1).
        coordinates: the formulation the sweep integrates, ``"cartesian"`` (default) or
            ``"joint"`` (trees without drives, ideal gears allowed: where
            ``model.joint_path_reason`` is empty).
        atol_factor: ``atol = atol_factor * rtol`` (default 1).
        u0, v0: a Cartesian initial state instead of q0/qd0.
        observe: ``(result) -> (n_out + 1, k)`` the quantity compared, instead of ``result.q``
            (then ``reference`` is required and ``error_measure`` should say what it is).
        angular: which columns of the compared quantity are angles (wrapped): a bool or a
            (k,) mask; default: the model's angular joint coordinates (none with ``observe``).
        error_measure: the error's description (default: the joint-coordinate error).
        repeats: CPU time of each point: 1 (default) one run; more: one warm-up run, then the
            median of ``repeats`` runs (at most ``MAX_REPEATS``, 1000).
        max_steps: step limit of each run: a run that needs more is a failed row.
        limits: :func:`armdyn.simulate`'s ``limits`` for every run (``"ignore"`` to compare with
            a reference that knows no joint stops).

    The default reference is DOP853 at rtol = atol = 1e-13 on the other formulation: the joint
    coordinates when the sweep is Cartesian and the model is a tree without drives
    (``model.joint_path_reason == ""``), the Cartesian one when the sweep runs in joint
    coordinates. For other models (closed loops, drives, spherical joints) it is the Cartesian
    formulation at rtol 1e-13 with DOP853 for every curve but DOP853's own, which is measured
    against DOPRI5 at rtol 1e-12 (each row's ``reference`` column names which). A fully
    driven model's reference is the kinematic path (each output solved from the constraints).
    Each default reference's own error is estimated against the same method one decade looser
    (``result.reference[label]["estimated_error"]``): errors near it are not resolved.

    Runs that fail (step-size underflow, more than ``max_steps`` steps, non-finite values) are
    rows with ``status`` ``"failed"`` and the reason in ``message``, not exceptions.

    Returns:
        WorkPrecisionResult: ``.table`` (pandas DataFrame) and ``.plot(path=None)``.

    Raises:
        ModelError: bad input (``t_end`` ≤ 0 or not finite, an unknown integrator, ``q0`` or
            ``qd0`` of the wrong size or not finite, non-positive tolerances or steps, a
            ``coordinates`` the model cannot take, a reference of the wrong shape).
        SolverError: the default reference run failed (pass ``reference=``).
    """
    plan = _check_arguments(
        model,
        t_end,
        integrators,
        n_out=n_out,
        coordinates=coordinates,
        atol_factor=atol_factor,
        repeats=repeats,
        max_steps=max_steps,
        limits=limits,
    )
    plan.start = _check_start(model, q0, qd0, u0, v0, observe, reference)
    settings = _settings(plan, rtols, dts)
    seen = _observation(model, plan.n_out, observe, angular, error_measure)
    refs, ref_values, row_reference = _references(plan, reference, seen.mask, observe is None)
    rows = [
        _measure(plan, integ, s, row_reference[integ], ref_values[row_reference[integ]], seen)
        for integ in plan.integrators
        for s in settings[integ]
    ]
    return WorkPrecisionResult(
        table=_table(rows),
        t=plan.t,
        error_measure=seen.measure,
        reference=refs,
        reference_values=ref_values,
    )


# --- the stages of work_precision, in order ---------------------------------------------------


@dataclass
class _Plan:
    """The checked arguments every run of the sweep shares, and the output grid."""

    model: _core.Model
    t_end: float
    n_out: int
    coordinates: str
    atol_factor: float
    repeats: int
    max_steps: int
    limits: str
    integrators: list[str]
    t: np.ndarray
    start: dict[str, Any] = field(default_factory=dict)

    def run(self, integ: str, coords: str, rtol=None, dt=None, max_steps=None):
        """:func:`armdyn.simulate` from the start state on the output grid: ``integ`` in
        formulation ``coords`` at ``rtol`` (``atol = atol_factor * rtol``) or, for RK4, step
        ``dt``; ``max_steps`` default the sweep's."""
        opts = dict(
            self.start,
            output_dt=self.t_end / self.n_out,
            coordinates=coords,
            max_steps=int(self.max_steps if max_steps is None else max_steps),
            limits=self.limits,
        )
        if integ == "rk4":
            opts["dt"] = dt
        elif integ != "kinematic":
            opts.update(rtol=rtol, atol=self.atol_factor * rtol)
        return simulate(self.model, self.t_end, integrator=integ, **opts)


def _check_arguments(
    model, t_end, integrators, *, n_out, coordinates, atol_factor, repeats, max_steps, limits
) -> _Plan:
    """The model, the numbers and choices, and the integrators, checked (a ModelError naming
    the argument)."""
    if not isinstance(model, _core.Model):
        raise _bad(f"model must be an armdyn.Model, got {type(model).__name__}")
    who = "work_precision"
    t_end = _checks.number(who, "t_end", t_end, lo=0.0, lo_open=True)
    n_out = _checks.integer(who, "n_out", n_out, lo=1)
    atol_factor = _checks.number(who, "atol_factor", atol_factor, lo=0.0, lo_open=True)
    repeats = _checks.integer(who, "repeats", repeats, lo=1, hi=MAX_REPEATS)
    # the tight reference runs take 10 max_steps: keep that an int64
    max_steps = _checks.integer(who, "max_steps", max_steps, lo=1, hi=_checks.INT_MAX // 10)
    coordinates = _checks.choice(who, "coordinates", coordinates, ("cartesian", "joint"))
    limits = _checks.choice(who, "limits", limits, ("enforce", "ignore"))
    if coordinates == "joint" and model.joint_path_reason:
        raise _bad(f"coordinates='joint' does not apply to this model: {model.joint_path_reason}")
    return _Plan(
        model=model,
        t_end=t_end,
        n_out=n_out,
        coordinates=coordinates,
        atol_factor=atol_factor,
        repeats=repeats,
        max_steps=max_steps,
        limits=limits,
        integrators=_check_integrators(model, integrators),
        t=np.linspace(0.0, t_end, n_out + 1),
    )


def _check_integrators(model, integrators) -> list[str]:
    if isinstance(integrators, str):
        integrators = [integrators]
    integrators = list(DEFAULT_INTEGRATORS if integrators is None else integrators)
    if not integrators:
        raise _bad("integrators is empty")
    for integ in integrators:
        if integ not in INTEGRATORS:
            raise _bad(f"unknown integrator {integ!r}; choose from {list(INTEGRATORS)}")
    if len(set(integrators)) != len(integrators):
        raise _bad(f"integrators has duplicates: {integrators}")
    if "kinematic" in integrators and model.mobility_driven != 0:
        raise _bad("integrator 'kinematic' needs a fully driven model (mobility_driven == 0)")
    return integrators


def _check_start(model, q0, qd0, u0, v0, observe, reference) -> dict[str, Any]:
    """The start state as simulate's keywords (empty: the model's assembled state at rest),
    and what is compared checked to exist."""
    q0 = _check_vector("q0", q0, model.n_coords)
    qd0 = _check_vector("qd0", qd0, model.n_coords)
    if qd0 is not None and q0 is None:
        raise _bad("qd0 given without q0")
    if (q0 is not None) and (u0 is not None or v0 is not None):
        raise _bad("give either q0/qd0 or u0/v0, not both")
    if observe is None and model.n_joint_coords == 0:
        raise _bad(
            "the model has no joint coordinates to compare (spherical, universal or free joints "
            "only); pass observe= and reference="
        )
    if observe is not None and reference is None:
        raise _bad("observe needs reference= (the default reference compares joint coordinates)")
    if q0 is not None:
        return {"q0": q0, "qd0": qd0}
    if u0 is not None or v0 is not None:
        return {"u0": u0, "v0": v0}
    return {}


def _settings(plan: _Plan, rtols, dts) -> dict[str, tuple]:
    """Per integrator, the settings swept: RK4's steps, the others' tolerances (the kinematic
    path: one NaN)."""
    settings: dict[str, tuple] = {}
    for integ in plan.integrators:
        if integ == "rk4":
            spacing = plan.t_end / plan.n_out
            settings[integ] = (
                _check_settings("dts", dts)
                if dts is not None
                else tuple(spacing / k for k in RK4_DIVISORS)
            )
        elif integ == "kinematic":
            settings[integ] = (math.nan,)
        else:
            settings[integ] = _check_settings(f"rtols of {integ}", _rtols_of(integ, rtols))
    return settings


def _rtols_of(integ: str, rtols):
    if rtols is None:
        return DEFAULT_RTOLS[integ]
    if isinstance(rtols, dict):
        unknown = sorted(set(rtols) - set(TOLERANCE_INTEGRATORS))
        if unknown:
            raise _bad(
                f"rtols names {unknown}, which take no tolerance; choose from "
                f"{list(TOLERANCE_INTEGRATORS)} (RK4's steps: dts=)"
            )
        return rtols.get(integ, DEFAULT_RTOLS[integ])
    return rtols


@dataclass
class _Observation:
    """What each run's error compares: ``observe(result)``, its angular columns (wrapped) and
    the description of the error."""

    observe: Callable[[Any], Any]
    mask: Any
    measure: str


def _observation(model, n_out: int, observe, angular, error_measure) -> _Observation:
    if observe is None:
        mask = _angular_mask(model) if angular is None else angular
        observe_fn = lambda res: res.q  # noqa: E731
        measure = error_measure or (
            f"max |q - q_ref| of the {model.n_joint_coords} joint coordinates over {n_out + 1} "
            "outputs [rad for angles (wrapped), m for displacements]"
        )
    else:
        mask = bool(angular) if angular is None or np.ndim(angular) == 0 else angular
        observe_fn = observe
        measure = error_measure or f"max |observed - reference| over {n_out + 1} outputs"
    if np.ndim(mask) == 1:
        mask = np.asarray(mask, dtype=bool)
    return _Observation(observe_fn, mask, measure)


def _references(plan: _Plan, reference, mask, observe_default: bool):
    """``(refs, ref_values, row_reference)``: how each reference was obtained, its values on
    the grid, and which one each integrator's rows are measured against (the user's; else the
    kinematic path of a fully driven model; else DOP853 at REFERENCE_RTOL on the other
    formulation; else, without a joint formulation, the Cartesian one with another
    integrator)."""
    model, integrators = plan.model, plan.integrators
    if reference is not None:
        vals = _reference_on_grid(reference, plan.t, model, observe_default)
        refs = {
            "user": {
                "method": "given by the user",
                "formulation": None,
                "rtol": None,
                "estimated_error": math.nan,
                "why": "reference= given",
            }
        }
        return refs, {"user": vals}, dict.fromkeys(integrators, "user")
    refs: dict[str, dict] = {}
    ref_values: dict[str, np.ndarray] = {}

    def default(label, integ, coords, rtol, why):
        refs[label], ref_values[label] = _default_reference(
            plan, label, integ, coords, rtol, why, mask
        )

    if model.mobility_driven == 0 and model.n_drives > 0:
        label = "kinematic (cartesian)"
        default(
            label, "kinematic", "cartesian", 0.0, "fully driven: every output is solved exactly"
        )
        return refs, ref_values, dict.fromkeys(integrators, label)
    if not model.joint_path_reason:
        other = "joint" if plan.coordinates == "cartesian" else "cartesian"
        label = f"dop853 rtol {REFERENCE_RTOL:g} ({other})"
        why = f"the other formulation than the sweep's ({plan.coordinates})"
        default(label, "dop853", other, REFERENCE_RTOL, why)
        return refs, ref_values, dict.fromkeys(integrators, label)
    why = (
        f"the joint formulation does not apply to this model ({model.joint_path_reason}): the "
        "Cartesian one with a different integrator"
    )
    label = f"dop853 rtol {REFERENCE_RTOL:g} (cartesian)"
    if any(i != "dop853" for i in integrators):
        default(label, "dop853", "cartesian", REFERENCE_RTOL, why)
    row_reference = dict.fromkeys(integrators, label)
    if "dop853" in integrators:
        label2 = "dopri5 rtol 1e-12 (cartesian)"
        default(label2, "dopri5", "cartesian", 1e-12, why)
        row_reference["dop853"] = label2
    return refs, ref_values, row_reference


def _default_reference(plan: _Plan, label: str, integ, coords, rtol, why, mask):
    """``(info, values)`` of a reference run at ``rtol`` (10 times the sweep's step limit),
    its own error estimated against the same method one decade looser (the kinematic path: its
    largest position residual)."""
    try:
        tight = plan.run(integ, coords, rtol=rtol, max_steps=10 * plan.max_steps)
        loose = (
            plan.run(integ, coords, rtol=10 * rtol, max_steps=10 * plan.max_steps)
            if integ != "kinematic"
            else None
        )
    except _core.SolverError as exc:
        raise _core.SolverError(
            f"work_precision: the reference run ({label}) failed: {exc}; pass reference="
        ) from exc
    vals = np.asarray(tight.q, dtype=float)
    if loose is not None:
        est = _max_error(loose.q, vals, mask)
    else:
        est = float(np.max(tight.position_residual))
    info = {
        "method": integ,
        "formulation": coords,
        "rtol": rtol if integ != "kinematic" else None,
        "atol": plan.atol_factor * rtol if integ != "kinematic" else None,
        "estimated_error": est,
        "estimated_error_how": (
            f"max over the grid of |{integ} at rtol {rtol:g} - {integ} at rtol {10 * rtol:g}|"
            if integ != "kinematic"
            else "largest position residual of the constraints over the outputs"
        ),
        "why": why,
    }
    return info, vals


def _measure(plan: _Plan, integ: str, s: float, ref_label: str, ref, seen: _Observation) -> dict:
    """One row of the table: the run of ``integ`` at setting ``s`` (its tolerance or RK4's
    step), its CPU time, error against ``ref`` and counters; a run that fails is a row with
    its reason."""
    row = dict.fromkeys(COLUMNS, math.nan)
    tolerance = integ in TOLERANCE_INTEGRATORS
    row.update(
        integrator=integ,
        coordinates=plan.coordinates,
        rtol=s if tolerance else math.nan,
        atol=plan.atol_factor * s if tolerance else math.nan,
        dt=s if integ == "rk4" else math.nan,
        status="ok",
        message="",
        reference=ref_label,
        error_measure=seen.measure,
        repeats=plan.repeats,
    )
    for k in _COUNTERS:
        row[k] = None
    res = None
    t0 = time.process_time()
    try:
        sec, reps, res = _cpu_time(
            lambda: plan.run(integ, plan.coordinates, rtol=s, dt=s), plan.repeats
        )
        row.update(cpu_s=sec, repeats=reps)
        row["error"] = _max_error(seen.observe(res), ref, seen.mask)
        if not np.isfinite(row["error"]):
            row.update(status="non-finite", message="outputs are not finite")
    except _core.SolverError as exc:
        row.update(
            cpu_s=time.process_time() - t0,
            repeats=1,
            status="failed",
            message=str(exc).split(";")[0][:300],
            error=math.nan,
        )
        res = getattr(exc, "result", None)
    if res is not None:
        _add_stats(row, res)
    return row


def _add_stats(row: dict, res) -> None:
    """The run's counters, integration time and largest position residual into ``row``."""
    for k in _COUNTERS:
        if k in res.stats:
            row[k] = int(res.stats[k])
    if "seconds" in res.stats:
        row["integration_s"] = float(res.stats["seconds"])
    if len(res.position_residual):
        row["max_position_residual"] = float(np.max(res.position_residual))


def _table(rows: list[dict]) -> pd.DataFrame:
    """The rows as a DataFrame with :data:`COLUMNS` and their dtypes (nullable integer
    counters)."""
    import pandas as pd

    table = pd.DataFrame(rows, columns=list(COLUMNS))
    for k in _COUNTERS:
        table[k] = table[k].astype("Int64")
    table["repeats"] = table["repeats"].astype("int64")
    for k in ("rtol", "atol", "dt", "error", "cpu_s", "integration_s", "max_position_residual"):
        table[k] = table[k].astype("float64")
    return table
