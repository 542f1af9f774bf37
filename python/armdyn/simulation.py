"""Whole runs: :func:`simulate` and :func:`rollout`, the Python face of the C++ stepping loops.

``load_urdf`` lives in :mod:`armdyn.urdf` (re-exported here, its old path)."""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core, _run_options
from armdyn._run_options import INTEGRATORS  # noqa: F401  (armdyn.simulation.INTEGRATORS)
from armdyn.urdf import load_urdf  # noqa: F401  (the old path armdyn.simulation.load_urdf)

if TYPE_CHECKING:
    import pandas as pd

#: what the progress argument of simulate and rollout takes
_Progress = bool | Callable[[float, float], object]


@dataclass
class SimulationResult:
    """Outputs of :func:`simulate`, one row per output time.

    Attributes:
        t: (n,) output times [s].
        u: (n, nq) positions: per body CoM (3) and Euler parameters (4, scalar first).
        v: (n, nv) velocities: per body CoM velocity (3, world) and angular velocity (3, body).
        q: (n, n_joint_coords) joint-space coordinates (angles unwrapped along the run; a
            floating base's position and scalar-first quaternion first,
            ``model.joint_coord_names``): every joint's, the couplings' followers included.
        qd, qdd: (n, n_joint_dofs) rates and accelerations (from the constrained accelerations
            at each output state; a floating base's linear and angular velocity in its own frame
            first, ``model.joint_dof_names``).
        drive_forces: (n, n_drives) actuator torque/force of each drive, applied to the child
            about/along the joint axis (the RNEA/URDF effort convention).
        joint_torques: (n, n_joint_dofs) the applied generalised force on every joint dof
            (columns ``model.joint_dof_names``, like ``qd``), joint side [N m or N]: drive
            efforts (prescribed motion) + ``add_joint_torque`` inputs + ``add_motor``
            controller torques after their ``torque_limit``; springs, dampers and friction are
            not included. Zero on floating bases' dofs and on actuator rotors (followers).
        reaction_forces, reaction_torques: (n, n_joints, 3) joint reaction on the child body at
            the joint point, in the child's joint frame (z = joint axis).
        position_residual: (n,) max |f| of the constraints [m or rad].
        velocity_residual: (n,) max |ζ v − rhs|.
        kinetic_energy, potential_energy: (n,) [J]; potential includes gravity and springs.
        stats: step, rejection, KKT-solve and factorisation counts, and run time [s].
        gear_forces: ``names`` (gear pairs, then ideal gears) and ``force`` (n, n_gears): the
            mesh force along the line of action [N] (positive when the mesh displacement
            s = r_a q_a + r_b q_b is positive); the torque on gear b is −r_b × force.
        events: located events (gear contact): ``t`` (times), ``gear`` (names), ``onset``
            (True at contact onset, False at separation); ``limits``: the joint stops' events,
            ``t``, ``joint``, ``side`` ("lower"/"upper") and ``kind`` ("rest": the joint hit
            its stop and stays on it, "bounce": it hit it and left at once, rebounding or
            pulled off, "release": it left the stop it rested on); one event per stop whose
            contact changed.
        limit_forces: ``names`` (the joints held by stops when limits are enforced) and
            ``force`` (n, n_limited): the stop's torque [N m] or force [N] on the joint's
            coordinate, positive along it (a lower stop pushes up), 0 off the stops.
        actuators: for a model with actuators (``model.actuators``), the motor-side values of
            each (:func:`armdyn.actuators.motor_side_of_result`); empty otherwise.
        model: the :class:`armdyn.Model` the run was made with (set by :func:`simulate` and
            :func:`rollout`; None for a result built by hand): :meth:`plot` and
            :meth:`limit_violations` read names and limits from it.
        error: None for a complete run; else why it stopped (the ``SolverError`` message of a
            run cut short, whose tables end at the last good output, or the ``ModelError`` of a
            run that could not start, whose tables have no rows). :func:`simulate` raises
            instead; :func:`rollout` records it per run. ``status`` is ``"ok"`` or this message.
    """

    t: npt.NDArray[np.float64]
    u: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    qd: npt.NDArray[np.float64]
    qdd: npt.NDArray[np.float64]
    drive_forces: npt.NDArray[np.float64]
    joint_torques: npt.NDArray[np.float64]
    reaction_forces: npt.NDArray[np.float64]
    reaction_torques: npt.NDArray[np.float64]
    position_residual: npt.NDArray[np.float64]
    velocity_residual: npt.NDArray[np.float64]
    kinetic_energy: npt.NDArray[np.float64]
    potential_energy: npt.NDArray[np.float64]
    stats: dict[str, Any] = field(default_factory=dict)
    events: dict[str, Any] = field(default_factory=dict)
    gear_forces: dict[str, Any] = field(default_factory=dict)
    limit_forces: dict[str, Any] = field(default_factory=dict)
    actuators: dict[str, Any] = field(default_factory=dict)
    error: str | None = None
    model: _core.Model | None = field(default=None, repr=False, compare=False)

    @property
    def status(self) -> str:
        """``"ok"`` for a complete run, else the error that stopped it (:attr:`error`)."""
        return "ok" if self.error is None else self.error

    def limit_violations(self, model: _core.Model | None = None) -> pd.DataFrame:
        """Spans where this run exceeds the model's velocity and effort limits, as a DataFrame
        (joint, kind, t_start, t_end, worst, limit, samples); see
        :func:`armdyn.sizing.limit_violations`. ``model``: default the one the run was made
        with (:attr:`model`); a model passed is checked against the result's columns."""
        model = model if model is not None else self.model
        if model is None:
            raise _core.ModelError(
                "SimulationResult.limit_violations: this result holds no model; pass the model "
                "the run was made with"
            )
        from armdyn.sizing import limit_violations

        return limit_violations(model, self)

    @property
    def total_energy(self) -> npt.NDArray[np.float64]:
        """(n,) kinetic + potential energy [J] at each output time (constant for a
        conservative model: a check of the run's accuracy)."""
        return self.kinetic_energy + self.potential_energy

    def plot(
        self,
        kind: str | list[str] | tuple[str, ...] = "q",
        joints: list[str | int] | tuple[str | int, ...] | str | int | None = None,
        *,
        model: _core.Model | None = None,
        ax: Any = None,
        path: str | os.PathLike[str] | None = None,
        title: str | None = None,
        **line_kw: Any,
    ) -> Any:
        """Plot the run against time [s], one panel per kind, joint names in the legends and
        units on the axes (:mod:`armdyn.plotting`; matplotlib is imported here, not by
        ``import armdyn``).

        Args:
            kind: one of, or a list of, ``"q"`` (joint coordinates [rad or m]), ``"qd"``
                (rates), ``"qdd"`` (accelerations), ``"torque"`` (``joint_torques``),
                ``"drive"`` (``drive_forces``), ``"limit"`` (``limit_forces``: joint-stop
                torques/forces), ``"gear"`` (``gear_forces``), ``"reaction"`` (joint reaction
                forces [N] and torques [N m], x/y/z in the child's joint frame; also
                ``"reaction_force"`` / ``"reaction_torque"`` alone), ``"energy"`` (kinetic,
                potential, total [J]), ``"residual"`` (position and velocity constraint
                residuals, log scale; also ``"position_residual"`` / ``"velocity_residual"``).
            joints: the joints to draw (default all): names (a joint, or a column of
                ``model.joint_coord_names`` / ``joint_dof_names``; gear names for ``"gear"``)
                or column indices of each panel's array. Ignored by ``"energy"`` and the
                residuals.
            model: the model the run was made with, for joint names and per-column units;
                default :attr:`model` (set by :func:`simulate` and :func:`rollout`). Without
                either, columns are ``q[0]``, ... and units read "rad or m".
            ax: a matplotlib Axes to draw a single panel into (or a sequence, one per panel);
                default: a new :class:`matplotlib.figure.Figure` (no pyplot state).
            path: save the figure there (dpi 110) when given.
            title: the figure's title (the first axes' with ``ax``).
            **line_kw: passed to ``Axes.plot`` (``lw``, ``alpha``, ...).

        Returns:
            The Figure, or, with ``ax``, the Axes drawn into (a list for a sequence).

        Raises:
            ValueError: an unknown kind, a result without rows, ``ax`` not matching the panels.
            ModelError: an unknown joint (naming it and listing the model's joints), a name
                without ``model``, a result not from ``model``, or a kind the run did not
                record (``"limit"`` without enforced stops, ``"drive"`` without drives,
                ``"gear"`` without gears), saying what records it.
        """
        from armdyn.plotting import plot_result

        model = model if model is not None else self.model
        return plot_result(
            self, kind, joints, model=model, ax=ax, path=path, title=title, **line_kw
        )


def simulate(
    model: _core.Model,
    t_end: float,
    integrator: str | None = None,
    rtol: float = 1e-6,
    atol: float = 1e-8,
    dt: float | None = None,
    output_dt: float | None = None,
    q0: npt.ArrayLike | None = None,
    qd0: npt.ArrayLike | None = None,
    projection: str = "mass",
    max_steps: int = 10_000_000,
    max_step: float | None = None,
    u0: npt.ArrayLike | None = None,
    v0: npt.ArrayLike | None = None,
    merge_welded: bool = True,
    coordinates: str = "auto",
    limits: str = "enforce",
    restitution: float = 0.0,
    progress: _Progress = False,
    max_output_bytes: int | None = None,
) -> SimulationResult:
    """Integrate the model from t = 0 to ``t_end``; the stepping loop runs in C++ without the GIL.

    Args:
        model: a finalized :class:`armdyn.Model`.
        t_end: end time [s] (> 0).
        q0, qd0: initial joint-space coordinates (``model.n_coords``,) and rates
            (``model.n_dofs``,) for tree models; default: the model's assembled state at rest.
            Angles are multi-turn: the run starts from q0's turns (3.5 rad stays 3.5, not
            -2.78). A floating base leads both: ``q = (x, y, z, e0, e1, e2, e3, joints…)``,
            its frame's position and scalar-first unit quaternion, and ``qd = (v, ω, rates…)``,
            its linear and angular velocity in its own frame (Pinocchio's free-flyer convention
            with the quaternion scalar first).
            A coupled model takes its independent coordinates (``model.coord_names``): the
            followers are set by their couplings.
        u0, v0: initial Cartesian state (nq,), (nv,) instead of q0/qd0 (projected onto the
            constraints first); default: the model's assembled state.
        {run options}
        progress: ``False`` (default): nothing shown. ``True``: a tqdm progress bar of the
            simulated time (t of ``t_end`` seconds), closed when the run ends. A ``tqdm``
            instance: that bar, its ``total`` set to ``t_end`` and ``n`` to t (left open, for
            notebooks and nested bars). A callable ``progress(t, t_end)``: called with the
            simulated time (e.g. to update a widget), and once more with ``t = t_end`` when the
            run completes. Updated at most every 0.1 s of wall time, from the run's poll (the
            GIL taken briefly); an exception it raises stops the run and propagates as itself,
            with ``.result``.
        max_output_bytes: bound on the memory of the run's outputs (default
            ``armdyn.simulation.MAX_OUTPUT_BYTES``, 2 GiB), checked before the run starts
            against its rows times the bytes of one row (every output, sized from the model).
            With ``output_dt``: ``t_end / output_dt + 2`` rows; a run beyond the bound is
            refused with a ModelError naming ``output_dt``. Without it (one row per accepted
            step): an RK4 run's ``t_end / dt + 2`` rows likewise (naming ``dt``); an adaptive
            run's rows are at most ``max_steps + 2``, and ``max_steps`` is lowered to fit the
            bound (a run that reaches it stops with a SolverError saying so, ``.result``
            holding the outputs so far).

    Returns:
        SimulationResult.

    Raises:
        ModelError: invalid options (naming the argument and what it allows: a wrong type,
            a value out of range, NaN, complex arrays) or initial state; a ``dt`` too small to
            advance time; outputs beyond ``max_output_bytes``;
            ``simulate`` called from inside a running simulation (a profile or progress
            callable): re-entrant runs are refused.
        SolverError: the run failed (non-finite force, projection not converging, step-size
            underflow, an exception raised by a profile callable: then chained as
            ``__cause__``); ``err.result`` holds the outputs up to the last good one.
        KeyboardInterrupt: Ctrl-C (SIGINT) during the run. The stepping loop checks for
            signals every 5 ms of wall time, so the run stops within milliseconds;
            ``err.result`` holds the outputs up to the last good one. ``SystemExit``,
            ``KeyboardInterrupt`` and ``GeneratorExit`` raised by a profile or progress
            callable propagate as themselves in the same way (``.result`` set).
    """
    # first, before any other name is bound: the arguments, of which the run options
    options = _run_options.core_options("simulate", locals())
    t_end = _checks.number("simulate", "t_end", t_end, lo=0.0, lo_open=True)
    _checks_model("simulate", model)
    q0, qd0, u0, v0 = (
        _checks.array("simulate", name, x, ndim=1) if x is not None else None
        for name, x in (("q0", q0), ("qd0", qd0), ("u0", u0), ("v0", v0))
    )
    if q0 is not None or qd0 is not None:
        if u0 is not None or v0 is not None:
            raise _core.ModelError("simulate: give either q0/qd0 or u0/v0, not both")
        if q0 is None:
            raise _core.ModelError("simulate: qd0 given without q0")
        # on a fresh workspace: the start does not depend on earlier calls (a loop or geared
        # model's dependent coordinates are solved by continuation from the Data's last state)
        u0, v0 = _core.state_from_joints(model, q0, qd0, data=_core.Data(model))
        q_start = q0
    else:
        q_start = None
    if model.nb == 0:
        return _zero_dof_result(model, t_end, output_dt)
    requested = options["max_steps"]
    options = _bound_run("simulate", model, t_end, options, max_output_bytes)
    report, close = _progress_reporter(progress, t_end, unit="s", bar_format=_BAR_FORMAT)
    try:
        raw = _core._simulate(
            model, t_end, u0=u0, v0=v0, q_start=q_start, progress=report, **options
        )
        interrupt = raw.pop("interrupt")
        cause = raw.pop("cause")
        raw["error"] = _explain_capped(raw["error"], options, requested)
        result = _result_of(model, raw)
        if interrupt is not None:
            # Ctrl-C, or SystemExit / KeyboardInterrupt / GeneratorExit from a callable
            interrupt.result = result
            raise interrupt
        if result.error:
            exc = _core.SolverError(result.error)
            exc.result = result
            if cause is not None:
                raise exc from cause
            raise exc
        if report is not None:
            _final_report(report, t_end, t_end, result)
        return result
    finally:
        if close is not None:
            close()


#: Default bound on the outputs of an ``output_dt`` run [bytes] (``simulate(max_output_bytes=)``
#: overrides it per run; assign this attribute to change it for the session).
MAX_OUTPUT_BYTES = 2 * 1024**3


def _bound_run(who, model, t_end, options, max_output_bytes, n_runs=1) -> dict:
    """The run options with the outputs' memory bounded before the run starts, and ``dt``
    checked to advance time; ModelError naming ``dt`` / ``output_dt`` / ``max_output_bytes``.

    Rows per run: ``t_end / output_dt + 2`` with ``output_dt``; without it one per step, so
    at most ``max_steps + 2`` (RK4: ``t_end / dt + 2``). ``n_runs`` runs (rollout) share the
    bound. A run without ``output_dt`` whose ``max_steps`` would allow more rows than the bound
    has its ``max_steps`` lowered to fit (it then stops, keeping its outputs so far, with a
    SolverError saying so); one that cannot fit at all is refused."""
    bound = MAX_OUTPUT_BYTES if max_output_bytes is None else max_output_bytes
    bound = _checks.number(who, "max_output_bytes", bound, lo=0.0, lo_open=True)
    row = float(_core._output_row_bytes(model)) * n_runs
    dt, output_dt = options["dt"], options["output_dt"]
    if dt > 0 and not (t_end + dt > t_end and dt >= _MIN_DT_RATIO * t_end):
        raise _core.ModelError(
            f"{who}: dt={dt:g} does not advance time over t_end={t_end:g} s in floating point "
            f"(dt must be at least {_MIN_DT_RATIO:g} t_end = {_MIN_DT_RATIO * t_end:g} s)"
        )
    if output_dt > 0:
        rows = t_end / output_dt + 2
        if rows * row > bound:
            raise _core.ModelError(
                f"{who}: output_dt={output_dt:g} over t_end={t_end:g} s gives {rows:.3g} output "
                f"rows{_of_runs(n_runs)}, {rows * row / 1024**3:.3g} GiB of outputs, above the "
                f"bound of {bound / 1024**3:.3g} GiB; raise output_dt (at least "
                f"{t_end * row / bound:.3g} s), or raise max_output_bytes= / "
                "armdyn.simulation.MAX_OUTPUT_BYTES"
            )
        return options
    if options["integrator"] == "rk4" and dt > 0:
        steps = np.ceil(t_end / dt)
        if (steps + 2) * row > bound:
            raise _core.ModelError(
                f"{who}: dt={dt:g} over t_end={t_end:g} s without output_dt gives {steps:.3g} "
                f"output rows (one per step){_of_runs(n_runs)}, "
                f"{(steps + 2) * row / 1024**3:.3g} GiB of outputs, above the bound of "
                f"{bound / 1024**3:.3g} GiB; pass output_dt, raise dt, or raise "
                "max_output_bytes= / armdyn.simulation.MAX_OUTPUT_BYTES"
            )
    fit = int(bound // row) - 2
    if fit < 1:
        raise _core.ModelError(
            f"{who}: max_output_bytes={bound:g} does not hold even one step's outputs "
            f"({row:g} bytes{_of_runs(n_runs)})"
        )
    if options["max_steps"] > fit:
        return dict(options, max_steps=fit)
    return options


#: the smallest dt relative to t_end (each step then moves t by at least 64 units of its last
#: place, so that the step count stays close to t_end / dt)
_MIN_DT_RATIO = 64 * np.finfo(float).eps


def _of_runs(n_runs: int) -> str:
    return "" if n_runs == 1 else f" for each of {n_runs} runs"


def _explain_capped(error: str | None, options: dict, requested: int) -> str | None:
    """The error of a run stopped by a max_steps that _bound_run lowered, saying so."""
    capped = options["max_steps"]
    if error and capped < requested and f"more than {capped} steps" in error:
        return (
            f"{error}: max_steps was lowered from {requested} to {capped} so that the outputs "
            "of this run without output_dt (one row per step) fit in max_output_bytes; pass "
            "output_dt, or raise max_output_bytes"
        )
    return error


def _final_report(report, done, total, result) -> None:
    """The progress callable's last call, at the end of a complete run: an exception it raises
    propagates as itself with ``.result`` (the run's, complete), as during the run."""
    try:
        report(done, total)
    except BaseException as exc:
        exc.result = result
        raise


def _checks_model(who: str, model) -> None:
    """A finalized armdyn.Model, or a ModelError naming the argument."""
    if not isinstance(model, _core.Model):
        raise _core.ModelError(
            f"{who}: model must be a finalized armdyn.Model (ModelBuilder.finalize(), "
            f"load_urdf), got {type(model).__name__}"
        )


def _progress_reporter(progress, total, who="simulate", args="(t, t_end)", **bar_options):
    """(report(x, total) or None, close() or None) for a ``progress`` argument: True (a tqdm bar
    of ``total``, closed by close()), a tqdm instance (its total set), a callable (called as
    is), or False/None. tqdm is imported only here (``import armdyn`` stays light)."""
    if progress is None or progress is False:
        return None, None
    if progress is True:
        from tqdm.auto import tqdm

        bar = tqdm(total=total, desc=who, **bar_options)
        return _tqdm_reporter(bar), bar.close
    if hasattr(progress, "update") and hasattr(progress, "refresh") and hasattr(progress, "n"):
        progress.total = total
        return _tqdm_reporter(progress), None
    if callable(progress):
        return progress, None
    raise _core.ModelError(
        f"{who}: progress must be True, False, a tqdm instance or a callable {args}, "
        f"got {type(progress).__name__}"
    )


_BAR_FORMAT = "{desc}: {percentage:3.0f}%|{bar}| t={n:.4g}/{total:.4g} s [{elapsed}<{remaining}]"


def _tqdm_reporter(bar):
    def report(x, total):
        bar.n = x
        bar.refresh()

    return report


def _rows(name: str, x, n_cols: int, n_rows: int | None) -> np.ndarray:
    """x as a float (n_runs, n_cols) array, or ModelError naming it and its shape."""
    a = _checks.array("rollout", name, x)
    if a.ndim != 2 or a.shape[1] != n_cols or (n_rows is not None and a.shape[0] != n_rows):
        rows = "n_runs" if n_rows is None else str(n_rows)
        raise _core.ModelError(
            f"rollout: {name} must have shape ({rows}, {n_cols}) (one row per run), got {a.shape}"
        )
    return np.ascontiguousarray(a)


def rollout(
    model: _core.Model,
    q0: npt.ArrayLike | None = None,
    qd0: npt.ArrayLike | None = None,
    t_end: float | None = None,
    threads: int | None = None,
    *,
    u0: npt.ArrayLike | None = None,
    v0: npt.ArrayLike | None = None,
    progress: _Progress = False,
    max_output_bytes: int | None = None,
    **simulate_options: Any,
) -> list[SimulationResult]:
    """Many runs of :func:`simulate` on C++ threads: one per row of the initial states.

    The batch runs with the GIL released, one ``Data`` (work space) per thread, the runs handed
    out from a shared queue so that slow runs balance. Every result is the one a serial
    ``simulate(model, t_end, q0=q0[k], qd0=qd0[k], **simulate_options)`` returns, bit for bit.

    Args:
        model: a finalized :class:`armdyn.Model` (shared by the threads, read only).
        q0: (n_runs, ``model.n_coords``) initial joint-space coordinates, one row per run (as
            :func:`simulate`'s ``q0``).
        qd0: (n_runs, ``model.n_dofs``) initial rates; default zero.
        t_end: end time [s] of every run.
        threads: number of threads (default ``os.cpu_count()``; at most n_runs).
        u0, v0: (n_runs, nq) and (n_runs, nv) initial Cartesian states instead of q0/qd0 (v0
            default: the model's assembled ``v0``).
        progress: ``False`` (default); ``True``: a tqdm bar of the runs finished; a tqdm
            instance (its ``total`` set to n_runs); or a callable ``progress(done, n_runs)``.
            Updated every 0.1 s from the waiting thread; an exception it raises stops the batch
            as Ctrl-C does (raised as itself, ``.result`` the list).
        max_output_bytes: bound on the memory of the outputs of all the runs together
            (default ``armdyn.simulation.MAX_OUTPUT_BYTES``), as :func:`simulate`'s for one run
            (each run's rows times n_runs).
        **simulate_options: the options of :func:`simulate`, the same for every run:
            {run option names}.

    Returns:
        A list of :class:`SimulationResult` in input order. A run that fails does not stop the
        others: its result has ``error`` set (``status`` is the message, ``"ok"`` otherwise) --
        a run that could not start (an initial state with NaN, an assembly failure) has tables
        without rows; a run stopped by a ``SolverError`` has the outputs up to the last good
        one, as ``SolverError.result`` of :func:`simulate` would.

    Raises:
        ModelError: bad shapes (naming the argument), bad options, or when every run failed to
            start with the same error (the options or the model are at fault, not the runs:
            e.g. rk4 without dt, q0 rows for a model without joint coordinates).
        KeyboardInterrupt: Ctrl-C during the batch: no new run starts, the runs in progress
            stop within milliseconds with their outputs so far (``error`` "run cancelled"), and
            ``err.result`` holds the list (runs not started have ``error`` "interrupted before
            the run started").
    """
    options = _rollout_options(simulate_options)
    t_end = _checks.number("rollout", "t_end", t_end, lo=0.0, lo_open=True)
    threads = _checks.integer("rollout", "threads", threads, lo=1, none=True)
    if threads is None:
        threads = os.cpu_count() or 1
    _checks_model("rollout", model)
    us, vs, q, errors = _initial_rows(model, q0, qd0, u0, v0)
    n = us.shape[0]
    if n == 0:
        return []
    if model.nb == 0:  # nothing to integrate: the zero-DOF result of each run
        return [simulate(model, t_end, output_dt=options["output_dt"] or None) for _ in range(n)]
    results = _run_batch(
        model, t_end, (us, vs, q, errors), min(threads, n), progress, options, max_output_bytes
    )
    _refuse_if_none_started(results)
    return results


simulate.__doc__ = _run_options.document(simulate.__doc__)
rollout.__doc__ = _run_options.document(rollout.__doc__)


def _rollout_options(simulate_options: dict) -> dict:
    """rollout's ``**simulate_options``: only run options (a TypeError naming the others), the
    rest at their defaults, checked and as ``_core._rollout`` takes them."""
    unknown = sorted(set(simulate_options) - set(_run_options.NAMES))
    if unknown:
        raise TypeError(
            f"rollout: unknown option(s) {', '.join(unknown)} (per-run initial states are q0/qd0"
            f" or u0/v0 rows; the options are simulate's: {', '.join(_run_options.NAMES)})"
        )
    return _run_options.core_options("rollout", {**_run_options.DEFAULTS, **simulate_options})


def _initial_rows(model, q0, qd0, u0, v0):
    """(u0 rows, v0 rows, q0 rows or None, errors): the initial Cartesian state of each run,
    from q0/qd0 rows (a run whose joint state does not assemble gets the model's state and its
    error, so that it fails alone) or u0/v0 rows; ModelError for shapes or a mix of both."""
    if q0 is not None or qd0 is not None:
        if u0 is not None or v0 is not None:
            raise _core.ModelError("rollout: give either q0/qd0 or u0/v0 rows, not both")
        if q0 is None:
            raise _core.ModelError("rollout: qd0 given without q0")
        q = _rows("q0", q0, model.n_coords, None)
        n = q.shape[0]
        qd = np.zeros((n, model.n_dofs)) if qd0 is None else _rows("qd0", qd0, model.n_dofs, n)
        us, vs, errors = np.empty((n, model.nq)), np.empty((n, model.nv)), [""] * n
        for k in range(n):
            try:
                us[k], vs[k] = _core.state_from_joints(model, q[k], qd[k], data=_core.Data(model))
            except (_core.ModelError, _core.SolverError) as err:  # this run cannot start alone
                us[k], vs[k], errors[k] = model.u0, model.v0, str(err)
        return us, vs, q, errors
    if u0 is not None:
        us = _rows("u0", u0, model.nq, None)
        n = us.shape[0]
        vs = np.tile(model.v0, (n, 1)) if v0 is None else _rows("v0", v0, model.nv, n)
        return us, vs, None, [""] * n
    raise _core.ModelError("rollout: give the initial states, q0 (and qd0) or u0 (and v0)")


def _run_batch(model, t_end, starts, threads, progress, options, max_output_bytes):
    """The runs on C++ threads, with the outputs' memory bounded and progress reported; the
    results in input order. Ctrl-C (or an exception of the progress callable) is raised with
    ``.result`` the list."""
    us, vs, q, errors = starts
    n = us.shape[0]
    requested = options["max_steps"]
    options = _bound_run("rollout", model, t_end, options, max_output_bytes, n_runs=n)
    report, close = _progress_reporter(progress, n, "rollout", "(done, n_runs)", unit="run")
    try:
        raws, interrupt = _core._rollout(
            model,
            t_end,
            u0=us,
            v0=vs,
            q_start=q,
            errors=errors,
            threads=threads,
            progress=report,
            **options,
        )
        for raw in raws:
            raw["error"] = _explain_capped(raw["error"], options, requested)
        results = [_result_of(model, raw) for raw in raws]
        if report is not None and interrupt is None:
            _final_report(report, n, n, results)
    finally:
        if close is not None:
            close()
    if interrupt is not None:
        interrupt.result = results
        raise interrupt
    return results


def _refuse_if_none_started(results: list[SimulationResult]) -> None:
    """The same error on every run and none started: the options or the model are at fault
    (rk4 without dt, a model without joint coordinates), not the runs: one ModelError."""
    messages = {r.error for r in results}
    if len(messages) == 1 and None not in messages and all(len(r.t) == 0 for r in results):
        raise _core.ModelError(f"rollout: every run failed to start: {messages.pop()}")


def _result_of(model: _core.Model, raw: dict) -> SimulationResult:
    """A SimulationResult of a C++ result dict (its ``error``: None for a complete run)."""
    error = raw.pop("error")
    result = SimulationResult(**raw)
    result.error = error or None
    result.model = model
    if model.actuators and len(result.t):
        _attach_motor_side(model, result)
    return result


def _attach_motor_side(model: _core.Model, result: SimulationResult) -> None:
    """result.actuators: the motor-side values of the model's actuators (armdyn.actuators)."""
    from armdyn.actuators import motor_side_of_result

    result.actuators = motor_side_of_result(model, result)


def _zero_dof_result(model: _core.Model, t_end: float, output_dt: float | None):
    """The run of a model with no bodies (a zero-DOF structure): nothing moves, nothing is
    integrated; the time grid of an ``output_dt`` run (k·output_dt, then ``t_end``) or
    ``[0, t_end]``, and state arrays with no columns."""
    if not (np.isfinite(t_end) and t_end > 0):
        raise _core.ModelError(f"simulate: t_end must be positive and finite, got {t_end}")
    if output_dt:
        k = np.arange(int(np.ceil(t_end / output_dt)) + 1)
        t = k * output_dt
        t = np.append(t[t < t_end - 1e-9 * output_dt], t_end)
    else:
        t = np.array([0.0, float(t_end)])
    n = len(t)
    empty = np.zeros((n, 0))
    return SimulationResult(
        t=t,
        u=empty,
        v=empty.copy(),
        q=empty.copy(),
        qd=empty.copy(),
        qdd=empty.copy(),
        drive_forces=empty.copy(),
        joint_torques=empty.copy(),
        reaction_forces=np.zeros((n, len(model.joint_names), 3)),
        reaction_torques=np.zeros((n, len(model.joint_names), 3)),
        position_residual=np.zeros(n),
        velocity_residual=np.zeros(n),
        kinetic_energy=np.zeros(n),
        potential_energy=np.zeros(n),
        stats={
            "steps": 0,
            "seconds": 0.0,
            "integrator": "none",
            "integrator_reason": "the model has no bodies (no degrees of freedom)",
            "formulation": "none: the model has no bodies",
            "solver_bodies": 0,
            "solver_rows": 0,
        },
        events={
            "t": np.zeros(0),
            "gear": [],
            "onset": [],
            "limits": {"t": np.zeros(0), "joint": [], "side": [], "kind": []},
        },
        gear_forces={"names": [], "force": np.zeros((n, 0))},
        limit_forces={"names": [], "force": np.zeros((n, 0))},
        model=model,
    )
