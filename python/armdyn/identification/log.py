"""Measured motions: a log of joint positions and torques (or motor currents), read with strict
checks, filtered and differentiated to the ``(t, q, qd, qdd, tau)`` samples an identification
fits.

The log (a CSV file, a pandas DataFrame or a dict of arrays) has the columns

- ``t``: time [s], finite and strictly increasing;
- one position column per model coordinate, named as ``model.coord_names`` [rad or m];
- per coordinate either ``<joint>.tau`` (the joint-side torque or force [N m or N]) or
  ``<joint>.current`` (the motor current [A], converted as below);
- optionally ``<joint>.qd`` and ``<joint>.qdd`` (given derivatives: for every joint or none).

Any other column, a missing one, or a duplicate is an error naming it (a CSV header's names are
stripped of surrounding blanks).

**Current to torque.** ``tau = gear_ratio * torque_constant * current`` per joint, times
``efficiency`` when given (one factor for both directions of power flow). Sign convention: a
positive current drives the joint in its positive direction (the direction of increasing q);
for a motor mounted the other way round give a negative gear ratio. ``torque_constants`` [N m/A]
must be > 0, ``gear_ratios`` non-zero, ``efficiency`` in (0, 1]; each is a dict by joint name (the
joints with a current column; other keys are errors) or a sequence of one value per coordinate.

**Filtering and differentiation** (:func:`differentiate`). With ``cutoff`` [Hz] set, q and tau
(and given qd, qdd) are low-pass filtered by the same zero-phase Butterworth filter
(``scipy.signal.butter`` of ``filter_order``, second-order sections, run forward and backward by
``scipy.signal.sosfiltfilt``: no phase lag, so q, its derivatives and tau stay aligned in time;
the forward-backward pass squares the magnitude, -6 dB at the cutoff). Filtering needs uniform
sampling: every interval within :data:`UNIFORM_TOLERANCE` (1 %) of the median interval (the
first row breaking it is named), and a cutoff strictly below the Nyquist frequency. Then, from
the (filtered) q and t: qd by central differences (``numpy.gradient`` with the time vector,
second-order one-sided differences at the two ends), qdd by the three-point second difference
(on a non-uniform grid its three-point generalisation, first order in the step) and, at the
first two and last two samples, the four-point one-sided second difference. On a uniform grid of
step h the truncation errors are at most ``h**2/6 max|q'''|`` (qd, interior), ``h**2/3
max|q'''|`` (qd, ends), ``h**2/12 max|q''''|`` (qdd, interior) and ``11 h**2/12 max|q''''|``
(qdd, ends), up to higher-order terms. ``cutoff=None``: no filtering.

**Filtering tau, or not.** Filtering tau reduces its noise for display and validation, but
biases a fit wherever the torque is not smooth: a Coulomb friction step at each velocity
reversal is smeared by the filter while the model's ``fc tanh(qd / v)`` of the filtered
velocity still steps, and the filtered noise is correlated from row to row, so least-squares
standard deviations that assume independent rows come out too small. Measured in
``tests/identification/test_log.py`` (a two-link arm with 2 and 1 N m of Coulomb friction,
exact torques, cutoff 4 Hz at 100 Hz): a least-squares fit's residual is 0.33 and 0.17 N m
with tau filtered, 0.0039 and 0.0015 N m with q alone filtered. So by default
(``filter_tau=False``) q alone is filtered (being zero-phase, the filter keeps q and the logged
tau aligned in time); ``filter_tau=True`` filters tau too.

**Edge transients.** A zero-phase filter still distorts the ends (``sosfiltfilt`` pads the
signal by odd reflection, which keeps q and qd continuous but flips the sign of the curvature):
qdd is wrong by up to a quarter of its peak within ``1 / cutoff`` seconds of either end.
``trim`` [s] drops that much of the processed log at each end; ``3 / cutoff`` brings qdd
within 0.1 % of its peak in ``tests/identification/test_log.py`` (a 10 Hz cutoff at 200 Hz).

Logs are for fixed-base models: a floating base is refused (ModelError).
"""

from __future__ import annotations

import io
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from armdyn import _core
from armdyn._checks import regular_file

__all__ = [
    "LOG_MAX_BYTES",
    "UNIFORM_TOLERANCE",
    "MotionLog",
    "differentiate",
    "load_log",
    "log_from_arrays",
]

#: the largest log file :func:`load_log` reads [bytes] (checked with stat before it is opened):
#: armdyn's URDF limit, 64 MiB
LOG_MAX_BYTES = _core.URDF_MAX_BYTES
#: the largest relative deviation of a sampling interval from the median interval that filtering
#: accepts as uniform sampling
UNIFORM_TOLERANCE = 0.01
_MIN_SAMPLES = 4  # the four-point end differences of qdd
_ME = _core.ModelError


# --- the log --------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class MotionLog:
    """Measured samples, ready for a fit: ``t`` (N,) [s] strictly increasing, ``q`` (N, n_coords),
    ``qd``, ``qdd`` and ``tau`` (N, n_dofs) joint-side, ``joint_names`` (the model's
    coord_names), and ``processing``: how qd, qdd and tau were obtained (for reports). The
    arrays are read-only."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    joint_names: list[str]
    processing: str

    def __post_init__(self) -> None:
        names = [str(n) for n in self.joint_names]
        t = _times("MotionLog", self.t)
        object.__setattr__(self, "t", t)
        for name in ("q", "qd", "qdd", "tau"):
            a = _array("MotionLog", name, getattr(self, name), 2)  # a copy: the log owns it
            if a.shape != (len(t), len(names)):
                raise _ME(
                    f"MotionLog: {name} must have shape ({len(t)}, {len(names)}) (samples, "
                    f"joint_names), got {a.shape}"
                )
            object.__setattr__(self, name, a)
        for name in ("t", "q", "qd", "qdd", "tau"):
            getattr(self, name).setflags(write=False)
        object.__setattr__(self, "joint_names", names)

    def __len__(self) -> int:
        return len(self.t)

    def select(self, mask_or_slice: Any) -> MotionLog:
        """The samples picked by a slice, a boolean mask (N,) or increasing row indices; at least
        four samples must remain (ModelError otherwise)."""
        mask = np.asarray(mask_or_slice) if isinstance(mask_or_slice, np.ndarray | list) else None
        if mask is not None and mask.dtype == bool and mask.shape != self.t.shape:
            raise _ME(
                f"MotionLog.select: the mask has shape {mask.shape}, the log {len(self.t)} samples"
            )
        try:
            idx = np.arange(len(self.t))[mask_or_slice]
        except (IndexError, TypeError, ValueError) as e:
            raise _ME(f"MotionLog.select: {e}") from None
        idx = np.atleast_1d(idx)
        if idx.size == 0:
            raise _ME("MotionLog.select: no sample selected")
        if np.any(np.diff(idx) <= 0):
            raise _ME("MotionLog.select: the rows must be increasing (time order, no repeats)")
        return MotionLog(
            self.t[idx],
            self.q[idx],
            self.qd[idx],
            self.qdd[idx],
            self.tau[idx],
            self.joint_names,
            self.processing,
        )

    def split(self, fraction: float = 0.7) -> tuple[MotionLog, MotionLog]:
        """(first, rest) by time: the samples with ``t < t0 + fraction * (t_end - t0)``, and the
        others (e.g. fit and validation data). ``fraction`` in (0, 1); both parts non-empty."""
        f = float(fraction)
        if not 0.0 < f < 1.0:
            raise _ME(f"MotionLog.split: fraction must be in (0, 1), got {fraction!r}")
        cut = self.t[0] + f * (self.t[-1] - self.t[0])
        first = self.t < cut
        if first.all() or not first.any():
            raise _ME(f"MotionLog.split: fraction {f} leaves one part empty")
        return self.select(first), self.select(~first)

    def to_csv(self, path: str | os.PathLike) -> None:
        """Write the log as a CSV :func:`load_log` reads back exactly (t, the positions, then per
        joint .qd, .qdd, .tau; 17 significant digits)."""
        import pandas as pd

        cols: dict[str, np.ndarray] = {"t": self.t}
        for j, name in enumerate(self.joint_names):
            cols[name] = self.q[:, j]
        for kind, a in (("qd", self.qd), ("qdd", self.qdd), ("tau", self.tau)):
            for j, name in enumerate(self.joint_names):
                cols[f"{name}.{kind}"] = a[:, j]
        pd.DataFrame(cols).to_csv(path, index=False, float_format="%.17g")


# --- differentiation ------------------------------------------------------------------------


def _uniform_step(who: str, t: np.ndarray) -> float:
    """The sampling interval of uniformly sampled t, or ModelError naming the first interval off
    the median by more than UNIFORM_TOLERANCE."""
    dt = np.diff(t)
    h = float(np.median(dt))
    off = np.abs(dt - h) > UNIFORM_TOLERANCE * h
    if off.any():
        i = int(np.argmax(off))
        raise _ME(
            f"{who}: filtering needs uniform sampling, but the interval from row {i} "
            f"(t = {float(t[i])!r}) to row {i + 1} (t = {float(t[i + 1])!r}) is "
            f"{float(dt[i]):.6g} s, more than {UNIFORM_TOLERANCE:.0%} off the median interval "
            f"{h:.6g} s"
        )
    return h


def _lowpass(who: str, t: np.ndarray, x: np.ndarray, cutoff: float, order: int) -> np.ndarray:
    from scipy.signal import butter, sosfiltfilt

    h = _uniform_step(who, t)
    nyquist = 0.5 / h
    if not cutoff < nyquist:
        raise _ME(
            f"{who}: cutoff {cutoff!r} Hz is not below the Nyquist frequency {nyquist:.6g} Hz "
            f"(sampling interval {h:.6g} s)"
        )
    sos = butter(order, cutoff, btype="low", fs=1.0 / h, output="sos")
    padlen = 3 * (2 * len(sos) + 1 - min((sos[:, 2] == 0).sum(), (sos[:, 5] == 0).sum()))
    if len(t) <= padlen:
        raise _ME(
            f"{who}: filtering of order {order} needs more than {padlen} samples, the log has "
            f"{len(t)}"
        )
    return sosfiltfilt(sos, x, axis=0)


def _second_derivative(t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Three-point second differences inside, four-point one-sided ones at two samples per end."""
    qdd = np.empty_like(q)
    h1 = (t[1:-1] - t[:-2])[:, None]
    h2 = (t[2:] - t[1:-1])[:, None]
    qdd[1:-1] = 2.0 * (h1 * q[2:] - (h1 + h2) * q[1:-1] + h2 * q[:-2]) / (h1 * h2 * (h1 + h2))
    for rows, at in ((slice(0, 4), (0, 1)), (slice(-4, None), (-2, -1))):
        nodes = t[rows]
        for i in at:
            qdd[i] = _weights(nodes - t[i]) @ q[rows]
    return qdd


def _weights(x: np.ndarray) -> np.ndarray:
    """Weights of the second derivative at 0 from values at the 4 nodes x (exact for cubics)."""
    v = np.vander(x, 4, increasing=True).T  # rows: x**k
    rhs = np.array([0.0, 0.0, 2.0, 0.0])
    return np.linalg.solve(v, rhs)


def _check_order(who: str, order: Any) -> int:
    if isinstance(order, bool) or not isinstance(order, int | np.integer) or not 1 <= order <= 10:
        raise _ME(f"{who}: filter order must be an integer from 1 to 10, got {order!r}")
    return int(order)


def _check_cutoff(who: str, cutoff: Any) -> float | None:
    if cutoff is None:
        return None
    try:
        c = float(cutoff)
    except (TypeError, ValueError):
        raise _ME(f"{who}: cutoff must be a frequency in Hz or None, got {cutoff!r}") from None
    if not (np.isfinite(c) and c > 0.0):
        raise _ME(f"{who}: cutoff must be a positive frequency in Hz, got {cutoff!r}")
    return c


def _times(who: str, t: Any) -> np.ndarray:
    t = _array(who, "t", t, 1)
    if len(t) < _MIN_SAMPLES:
        raise _ME(f"{who}: a log needs at least {_MIN_SAMPLES} samples, got {len(t)}")
    bad = np.flatnonzero(np.diff(t) <= 0.0)
    if bad.size:
        i = int(bad[0])
        raise _ME(
            f"{who}: t must be strictly increasing, but row {i + 1} (t = {float(t[i + 1])!r}) "
            f"does not follow row {i} (t = {float(t[i])!r})"
        )
    return t


def _array(who: str, name: str, a: Any, ndim: int) -> np.ndarray:
    try:
        a = np.array(a, dtype=float)
    except (TypeError, ValueError):
        raise _ME(f"{who}: {name} must be an array of real numbers") from None
    if a.ndim != ndim:
        raise _ME(f"{who}: {name} must be {ndim}-dimensional, got shape {a.shape}")
    bad = ~np.isfinite(a)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"row {idx[0]}" + (f", column {idx[1]}" if len(idx) > 1 else "")
        raise _ME(f"{who}: {name} at {where} is {float(a[idx])!r}, not finite")
    return a


def differentiate(
    t: Any, q: Any, *, cutoff: float | None = None, order: int = 4
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q_f, qd, qdd) from samples q (N,) or (N, n) at times t (N,): q_f is q low-pass filtered
    (zero-phase Butterworth of ``order`` at ``cutoff`` Hz; uniform sampling required) or q itself
    when ``cutoff`` is None; qd and qdd its central differences (the module's docstring gives
    the stencils and their error bounds). ModelError on non-finite or non-increasing t, non-finite
    q, fewer than 4 samples, non-uniform sampling with a cutoff, or a cutoff at or above
    Nyquist."""
    who = "differentiate"
    t = _times(who, t)
    q = np.asarray(q)
    q2 = _array(who, "q", q.reshape(len(q), -1) if q.ndim == 1 else q, 2)
    if len(q2) != len(t):
        raise _ME(f"{who}: q has {len(q2)} rows, t has {len(t)}")
    q_f, qd, qdd = _differentiate(who, t, q2, _check_cutoff(who, cutoff), _check_order(who, order))
    if q.ndim == 1:
        return q_f[:, 0], qd[:, 0], qdd[:, 0]
    return q_f, qd, qdd


def _differentiate(who, t, q, cutoff, order):
    q_f = q if cutoff is None else _lowpass(who, t, q, cutoff, order)
    qd = np.gradient(q_f, t, axis=0, edge_order=2)
    return q_f, qd, _second_derivative(t, q_f)


# --- building a log -------------------------------------------------------------------------


def _fixed_base(who: str, model: Any) -> list[str]:
    if not isinstance(model, _core.Model):
        raise _ME(f"{who}: model must be an armdyn.Model, got {type(model).__name__}")
    if model.n_free:
        raise _ME(
            f"{who}: the model has a floating base; logs and identification take fixed-base "
            "models only"
        )
    return list(model.coord_names)


def log_from_arrays(
    model: Any,
    t: Any,
    q: Any,
    tau: Any,
    qd: Any = None,
    qdd: Any = None,
    *,
    cutoff: float | None = None,
    filter_order: int = 4,
    trim: float = 0.0,
    filter_tau: bool = False,
    source: str = "arrays",
) -> MotionLog:
    """A :class:`MotionLog` from arrays: t (N,), q (N, n_coords), tau (N, n_dofs) joint-side,
    optional qd, qdd (N, n_dofs; given together or alone: a missing one is differentiated). With
    ``cutoff`` q (and qd, qdd when given) are filtered, tau too with ``filter_tau=True`` (module
    docstring: filtering tau biases a fit); ``trim`` [s] drops that much at each end afterwards.
    ModelError naming the culprit on bad input."""
    who = "log_from_arrays" if source == "arrays" else "load_log"
    names = _fixed_base(who, model)
    n = len(names)
    t = _times(who, t)
    cutoff = _check_cutoff(who, cutoff)
    order = _check_order(who, filter_order)
    given = {"q": q, "tau": tau, "qd": qd, "qdd": qdd}
    arrays = {}
    for key, a in given.items():
        if a is None:
            continue
        a = _array(who, key, a, 2)
        if a.shape != (len(t), n):
            raise _ME(f"{who}: {key} must have shape ({len(t)}, {n}), got {a.shape}")
        arrays[key] = a
    steps = []
    if cutoff is not None:
        filtered = [k for k in ("q", "qd", "qdd", "tau") if k in arrays]
        if not filter_tau:
            filtered.remove("tau")
        for k in filtered:
            arrays[k] = _lowpass(who, t, arrays[k], cutoff, order)
        steps.append(
            f"{', '.join(filtered)} low-pass filtered (zero-phase Butterworth of order {order}, "
            f"forward and backward, cutoff {cutoff:g} Hz, sampling {1.0 / np.median(np.diff(t)):g} "
            "Hz)"
        )
    steps += _derivatives(t, arrays)
    t, arrays, trimmed = _trim(who, t, arrays, trim)
    steps += trimmed
    return MotionLog(
        t,
        arrays["q"],
        arrays["qd"],
        arrays["qdd"],
        arrays["tau"],
        names,
        f"{source}: " + "; ".join(steps) if steps else f"{source}: used as given",
    )


def _derivatives(t: np.ndarray, arrays: dict) -> list[str]:
    """Fill in the derivatives the log lacks; the words saying how."""
    has_qd, has_qdd = "qd" in arrays, "qdd" in arrays
    steps = []
    if not has_qd:
        arrays["qd"] = np.gradient(arrays["q"], t, axis=0, edge_order=2)
        steps.append("qd by central differences of q (numpy.gradient, second order at the ends)")
    if not has_qdd and not has_qd:
        arrays["qdd"] = _second_derivative(t, arrays["q"])
        steps.append(
            "qdd by three-point second differences of q (four-point one-sided at the ends)"
        )
    elif not has_qdd:
        arrays["qdd"] = np.gradient(arrays["qd"], t, axis=0, edge_order=2)
        steps.append("qdd by central differences of the given qd (numpy.gradient)")
    if has_qd and has_qdd:
        steps.append("qd, qdd as given")
    return steps


def _trim(who: str, t: np.ndarray, arrays: dict, trim: Any) -> tuple:
    try:
        trim = float(trim)
    except (TypeError, ValueError):
        raise _ME(f"{who}: trim must be a duration in s, got {trim!r}") from None
    if not (np.isfinite(trim) and trim >= 0.0):
        raise _ME(f"{who}: trim must be a duration >= 0 s, got {trim!r}")
    if trim == 0.0:
        return t, arrays, []
    keep = (t >= t[0] + trim) & (t <= t[-1] - trim)
    if keep.sum() < _MIN_SAMPLES:
        raise _ME(
            f"{who}: trim {trim!r} s at each end leaves {int(keep.sum())} samples of "
            f"{len(t)} (a log needs at least {_MIN_SAMPLES})"
        )
    return (
        t[keep],
        {k: a[keep] for k, a in arrays.items()},
        [f"{trim:g} s trimmed at each end (filter edge transients)"],
    )


# --- reading a log --------------------------------------------------------------------------


def load_log(
    source: Any,
    model: Any,
    *,
    cutoff: float | None = None,
    filter_order: int = 4,
    torque_constants: Any = None,
    gear_ratios: Any = None,
    efficiency: Any = None,
    trim: float = 0.0,
    filter_tau: bool = False,
) -> MotionLog:
    """A :class:`MotionLog` from a CSV file (path), a pandas DataFrame or a dict of arrays with
    the columns of the module docstring. Motor currents become joint torques with
    ``torque_constants`` and ``gear_ratios`` (and ``efficiency``); ``cutoff``, ``filter_order``,
    ``trim`` and ``filter_tau`` as :func:`log_from_arrays`. A file is checked before it is read (a
    regular file of at most :data:`LOG_MAX_BYTES`, never a directory, FIFO or device), then must
    be UTF-8 and comma-separated. ModelError naming the culprit (file, column, row, cell) on bad
    input; OSError for a missing or unreadable file."""
    who = "load_log"
    names = _fixed_base(who, model)
    columns, shown, lines = _columns(who, source)
    layout = _layout(who, shown, list(columns), names)
    n_rows = {len(v) for v in columns.values()}
    if len(n_rows) != 1:
        raise _ME(f"{who}: {shown}: the columns have different lengths {sorted(n_rows)}")
    if n_rows == {0}:
        raise _ME(f"{who}: {shown} has a header but no data rows")
    data = {c: _column(who, shown, c, v, lines) for c, v in columns.items()}
    tau, how = _torques(who, names, data, layout, torque_constants, gear_ratios, efficiency)
    q = np.column_stack([data[j] for j in names])
    given = {
        k: np.column_stack([data[f"{j}.{k}"] for j in names]) if layout[k] else None
        for k in ("qd", "qdd")
    }
    return log_from_arrays(
        model,
        data["t"],
        q,
        tau,
        given["qd"],
        given["qdd"],
        cutoff=cutoff,
        filter_order=filter_order,
        trim=trim,
        filter_tau=filter_tau,
        source=f"{shown}: {how}",
    )


def _columns(who: str, source: Any) -> tuple[dict, str, np.ndarray | None]:
    """The log's columns (name -> 1-D values, as read), how to name the source, and for a CSV
    the file's line number of each data row."""
    import pandas as pd

    if isinstance(source, pd.DataFrame):
        dup = source.columns[source.columns.duplicated()]
        if len(dup):
            raise _ME(f"{who}: the DataFrame has the column {str(dup[0])!r} more than once")
        return {str(c): source[c].to_numpy() for c in source.columns}, "DataFrame", None
    if isinstance(source, Mapping):
        out = {}
        for c, v in source.items():
            a = np.asarray(v)
            if a.ndim != 1:
                raise _ME(f"{who}: column {c!r} must be 1-dimensional, got shape {a.shape}")
            out[str(c)] = a
        return out, "dict", None
    if isinstance(source, str | os.PathLike):
        return _read_csv(who, source)
    raise _ME(
        f"{who}: source must be a CSV path, a pandas DataFrame or a dict of arrays, got "
        f"{type(source).__name__}"
    )


def _read_csv(who: str, path: Any) -> tuple[dict, str, np.ndarray]:
    import pandas as pd

    shown = f"log {str(os.fspath(path))!r}"
    raw = regular_file(path, "log", LOG_MAX_BYTES)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise _ME(f"{who}: {shown} is not UTF-8 text (byte {e.start}, line {line})") from None
    if not text.strip():
        raise _ME(f"{who}: {shown} is empty")
    numbered = [(i + 1, line) for i, line in enumerate(text.splitlines()) if line.strip()]
    header = numbered[0][1]
    text = "\n".join(line for _, line in numbered) + "\n"  # blank lines dropped
    names = [h.strip() for h in header.split(",")]
    if len(names) == 1:
        for sep in (";", "\t", "|", " "):
            if sep in header.strip():
                raise _ME(
                    f"{who}: {shown} must be comma-separated; its header {header.strip()[:80]!r} "
                    f"looks separated by {sep!r}"
                )
    seen = set()
    for name in names:
        if name in seen:
            raise _ME(f"{who}: {shown} has the column {name!r} more than once")
        seen.add(name)
    try:
        frame = pd.read_csv(
            io.StringIO(text),
            dtype=str,
            keep_default_na=False,
            skipinitialspace=True,
            skip_blank_lines=True,
        )
    except (pd.errors.ParserError, ValueError) as e:
        raise _ME(f"{who}: {shown} is not a valid CSV table: {str(e).strip()}") from None
    if len(frame.columns) != len(names):
        raise _ME(f"{who}: {shown}: cannot read the header {header.strip()[:80]!r}")
    frame.columns = names
    lines = np.array([n for n, _ in numbered[1:]])
    return {c: frame[c].to_numpy() for c in names}, shown, lines


def _layout(who: str, shown: str, columns: list[str], names: list[str]) -> dict:
    """Which columns the log has per joint: checks t, positions, one torque source per joint,
    qd and qdd for all joints or none, no unknown column."""
    expected = {"t", *names}
    allowed = set(expected)
    for j in names:
        allowed |= {f"{j}.{k}" for k in ("tau", "current", "qd", "qdd")}
    unknown = [c for c in columns if c not in allowed]
    if unknown:
        raise _ME(
            f"{who}: {shown}: unknown column {unknown[0]!r} (the columns are t, the model's "
            f"coordinates {names}, and per coordinate .tau or .current, optional .qd, .qdd)"
        )
    missing = [c for c in ["t", *names] if c not in columns]
    if missing:
        raise _ME(f"{who}: {shown}: missing column {missing[0]!r} (needed: t and {names})")
    have = set(columns)
    source = {}
    for j in names:
        kinds = [k for k in ("tau", "current") if f"{j}.{k}" in have]
        if len(kinds) != 1:
            what = "neither" if not kinds else "both"
            raise _ME(
                f"{who}: {shown}: joint {j!r} needs one of the columns '{j}.tau' or "
                f"'{j}.current', the log has {what}"
            )
        source[j] = kinds[0]
    layout: dict[str, Any] = {"source": source}
    for k in ("qd", "qdd"):
        present = [j for j in names if f"{j}.{k}" in have]
        if present and len(present) != len(names):
            lacking = next(j for j in names if j not in present)
            raise _ME(
                f"{who}: {shown}: column '{lacking}.{k}' is missing (given derivatives need a "
                "column for every joint, or none)"
            )
        layout[k] = bool(present)
    return layout


def _column(who: str, shown: str, name: str, values: np.ndarray, lines: Any) -> np.ndarray:
    """The column as floats; ModelError naming the first cell that is empty, not a number or not
    finite (data row i, 0-based; for a CSV also its line)."""
    import pandas as pd

    if values.dtype.kind in "fiu":
        x = values.astype(float)
        raw = values
    else:
        raw = np.array(["" if v is None or v is pd.NA else str(v) for v in values], dtype=object)
        x = pd.to_numeric(pd.Series(raw).str.strip(), errors="coerce").to_numpy(dtype=float)
    bad = ~np.isfinite(x)
    if bad.any():
        i = int(np.argmax(bad))
        cell = str(raw[i]).strip()
        if cell == "":
            what = "is empty"
        elif np.isnan(x[i]) and cell.lower() not in ("nan", "-nan", "+nan"):
            what = f"is {cell!r}, not a number"
        else:
            what = f"is {cell!r}, not finite"
        line = f" (line {lines[i]})" if lines is not None and i < len(lines) else ""
        raise _ME(f"{who}: {shown}: column {name!r}, row {i}{line} {what}")
    return x


def _per_joint(who: str, what: str, value: Any, joints: list[str], names: list[str]) -> dict:
    """A per-joint parameter given as a dict by joint name or one value per coordinate."""
    if isinstance(value, Mapping):
        unknown = [k for k in value if k not in joints]
        if unknown:
            raise _ME(
                f"{who}: {what} has the key {unknown[0]!r}, not a joint with a current column "
                f"({joints})"
            )
        missing = [j for j in joints if j not in value]
        if missing:
            raise _ME(f"{who}: {what} has no value for joint {missing[0]!r}")
        out = dict(value)
    else:
        try:
            arr = np.array(value, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise _ME(f"{who}: {what} must be a dict by joint or a sequence of numbers") from None
        if arr.size != len(names):
            raise _ME(
                f"{who}: {what} needs {len(names)} values (one per coordinate), got {arr.size}"
            )
        out = {j: arr[names.index(j)] for j in joints}
    result = {}
    for j, v in out.items():
        try:
            result[j] = float(v)
        except (TypeError, ValueError):
            raise _ME(f"{who}: {what}[{j!r}] = {v!r} is not a number") from None
    return result


def _torques(who, names, data, layout, torque_constants, gear_ratios, efficiency):
    """tau (N, n) from the .tau and .current columns, and the words saying how."""
    current = [j for j in names if layout["source"][j] == "current"]
    if not current:
        for arg, value in (
            ("torque_constants", torque_constants),
            ("gear_ratios", gear_ratios),
            ("efficiency", efficiency),
        ):
            if value is not None:
                raise _ME(f"{who}: {arg} given, but the log has no current column")
        return np.column_stack([data[f"{j}.tau"] for j in names]), "torques as logged"
    for arg, value in (("torque_constants", torque_constants), ("gear_ratios", gear_ratios)):
        if value is None:
            raise _ME(
                f"{who}: the log has current columns ({', '.join(current)}): {arg} is required"
            )
    kt = _per_joint(who, "torque_constants", torque_constants, current, names)
    ratio = _per_joint(who, "gear_ratios", gear_ratios, current, names)
    eta = (
        dict.fromkeys(current, 1.0)
        if efficiency is None
        else (
            _per_joint(who, "efficiency", efficiency, current, names)
            if isinstance(efficiency, Mapping) or np.ndim(efficiency) > 0
            else dict.fromkeys(current, efficiency)
        )
    )
    for j in current:
        if not (np.isfinite(kt[j]) and kt[j] > 0.0):
            raise _ME(f"{who}: torque_constants[{j!r}] = {kt[j]!r} must be > 0 [N m/A]")
        if not (np.isfinite(ratio[j]) and ratio[j] != 0.0):
            raise _ME(
                f"{who}: gear_ratios[{j!r}] = {ratio[j]!r} must be finite and non-zero "
                "(negative: a motor turning against the joint)"
            )
        e = eta[j]
        if not isinstance(e, int | float | np.floating) or not (0.0 < float(e) <= 1.0):
            raise _ME(f"{who}: efficiency[{j!r}] = {e!r} must be in (0, 1]")
    cols = [
        data[f"{j}.tau"] if j not in kt else ratio[j] * kt[j] * float(eta[j]) * data[f"{j}.current"]
        for j in names
    ]
    factor = " * efficiency" if efficiency is not None else ""
    how = f"torque = gear_ratio * torque_constant * current{factor} for {', '.join(current)}"
    return np.column_stack(cols), how
