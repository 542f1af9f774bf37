"""Argument checks shared by the vectorised gearbox, bearing, emergency-stop, drive, bus and
brake values (:mod:`armdyn.sizing.gearbox`, :mod:`armdyn.sizing.drive`): a joint load's
samples, per-candidate parameter arrays and catalog columns. Every failure is a ModelError that
names the function, the argument (or the load's field, or the column) and the first bad
candidate."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np

from armdyn import _core


def fail(who: str, text: str) -> _core.ModelError:
    return _core.ModelError(f"{who}: {text}")


def _float_array(who: str, name: str, value) -> np.ndarray:
    if isinstance(value, (str, bytes)):
        raise fail(who, f"{name} must be numbers, got {value!r}")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise fail(who, f"{name} must be numbers, got {type(value).__name__}") from None
    return arr


def cycle_times(who: str, load) -> np.ndarray:
    """The load's sample times (:func:`times`)."""
    if not hasattr(load, "t"):
        raise fail(who, "load has no field 't'")
    return times(who, "load.t", load.t)


def times(who: str, name: str, value) -> np.ndarray:
    """Sample times: 1-D, at least two, finite, non-decreasing, spanning > 0."""
    t = _float_array(who, name, value)
    if t.ndim != 1 or t.size < 2:
        raise fail(who, f"{name} must hold at least two samples (an empty cycle?), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise fail(who, f"{name} has a non-finite sample at index {_first(~np.isfinite(t))}")
    if np.any(np.diff(t) < 0.0):
        raise fail(who, f"{name} decreases at index {_first(np.diff(t) < 0.0) + 1}")
    if not t[-1] > t[0]:
        raise fail(who, f"{name} spans no time (the cycle has zero duration)")
    return t


def series(who: str, load, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """The load's field ``name`` as a finite float array of ``shape``."""
    if not hasattr(load, name):
        raise fail(who, f"load has no field {name!r}")
    arr = _float_array(who, f"load.{name}", getattr(load, name))
    if arr.shape != shape:
        raise fail(who, f"load.{name} must have shape {shape}, got {arr.shape}")
    bad = ~np.isfinite(arr)
    if np.any(bad):
        idx = np.argwhere(bad)[0]
        raise fail(who, f"load.{name} has a non-finite value at index {tuple(int(i) for i in idx)}")
    return arr


def unit_axis(who: str, load) -> np.ndarray:
    """The load's joint axis (3,), normalised; a zero axis is an error."""
    axis = series(who, load, "axis", (3,))
    norm = float(np.linalg.norm(axis))
    if not norm > 0.0:
        raise fail(who, "load.axis must be a non-zero vector")
    return axis / norm


def _first(mask: np.ndarray) -> int:
    return int(np.flatnonzero(mask)[0])


def candidates(
    who: str,
    name: str,
    value,
    k: int | None,
    *,
    nan: bool,
    lo: float | None = 0.0,
    lo_open: bool = False,
    nonzero: bool = False,
) -> np.ndarray:
    """``value`` as a (k,) float array (a scalar broadcasts; k None = take the length given).

    ``nan``: NaN allowed (not given). Every other entry must be finite and within the bounds:
    ``lo`` (None = unbounded), ``lo_open`` (> lo), ``nonzero`` (≠ 0)."""
    arr = _float_array(who, name, value)
    if arr.ndim == 0:
        arr = np.full(1 if k is None else k, float(arr))
    if arr.ndim != 1 or (k is not None and arr.shape[0] != k):
        want = "(k,)" if k is None else f"({k},)"
        raise fail(who, f"{name} must have shape {want}, got {arr.shape}")
    isnan = np.isnan(arr)
    if not nan and np.any(isnan):
        raise fail(who, f"{name}[{_first(isnan)}] must be given (a number), got nan")
    given = ~isnan
    if np.any(given & ~np.isfinite(arr)):
        raise fail(who, f"{name}[{_first(given & ~np.isfinite(arr))}] must be finite, got inf")
    if lo is not None:
        low = (arr <= lo) if lo_open else (arr < lo)
        low &= given
        if np.any(low):
            i = _first(low)
            rel = ">" if lo_open else ">="
            raise fail(who, f"{name}[{i}] must be {rel} {lo:g}, got {arr[i]!r}")
    if nonzero and np.any(given & (arr == 0.0)):
        raise fail(who, f"{name}[{_first(given & (arr == 0.0))}] must be non-zero, got 0.0")
    return arr


def columns(
    who: str, table, spec: Mapping[str, dict], k: int | None, label: str
) -> dict[str, np.ndarray]:
    """Per-candidate catalog columns from ``table``: a mapping or pandas DataFrame of column ->
    (k,) values, or one part (a catalog dataclass such as ``Gearbox``: k = 1). ``spec`` maps
    each column name to :func:`candidates`' keywords plus an optional ``default`` used when the
    column is absent (absent without a default = NaN, not given). k None: the length of the
    columns read (other columns are ignored)."""
    if table is None:
        table = {}
    if dataclasses.is_dataclass(table) and not isinstance(table, type):  # one catalog part
        table = {f.name: getattr(table, f.name) for f in dataclasses.fields(table)}
    if not isinstance(table, Mapping) and not hasattr(table, "columns"):
        raise fail(who, f"{label} must be a mapping of column -> (k,) values")
    keys = set(table.keys()) if isinstance(table, Mapping) else set(table.columns)
    if k is None:
        known = keys & set(spec) or keys  # k from the columns read (else from any column)
        lengths = {len(np.atleast_1d(np.asarray(table[c], dtype=object))) for c in known}
        if len(lengths) != 1:
            raise fail(
                who,
                f"{label} must hold (k,) columns of one length k >= 1 (got lengths "
                f"{sorted(lengths)})",
            )
        k = lengths.pop()
    out: dict[str, np.ndarray] = {}
    for name, kw in spec.items():
        kw = dict(kw)
        default = kw.pop("default", np.nan)
        if name in keys:
            raw = table[name]
            raw = getattr(raw, "to_numpy", lambda raw=raw: raw)()
        else:
            raw = default
        out[name] = candidates(who, f"{label}[{name!r}]", raw, k, **kw)
    return out


def options_of(options):
    from armdyn.sizing.options import sizing_options

    return sizing_options(options)
