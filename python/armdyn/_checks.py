"""The facade's argument checks: one small validator per kind of option (number, integer,
choice, flag, name, array, file), each raising :class:`armdyn.ModelError` that names the
function, the argument and what it allows. The public Python functions check their options
through these before anything reaches the C++ core, so that a bad option never shows
pybind11's signature dump or "Unable to cast"."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from numbers import Integral, Real

import numpy as np

from armdyn import _core

#: largest integer option (step counts, threads, bytes): a C++ int64
INT_MAX = 2**63 - 1


class ArgumentTypeError(_core.ModelError, TypeError):
    """A bad argument of the wrong type: a ``ModelError`` naming it that is also a ``TypeError``
    (where a function documented ``TypeError`` before its options were checked as ModelErrors,
    ``except TypeError`` keeps working)."""


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _fail(who: str, name: str, allowed: str, value) -> _core.ModelError:
    return _core.ModelError(f"{who}: {name} must be {allowed}, got {_shown(value)}")


def number(
    who: str,
    name: str,
    value,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    none: bool = False,
) -> float | None:
    """A real finite number (int, float or a numpy real scalar; not bool, str or complex) within
    [lo, hi] (``lo_open``: > lo), as float; None passes when ``none``."""
    if value is None and none:
        return None
    bounds = []
    if lo is not None:
        bounds.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        bounds.append(f"<= {hi:g}")
    if lo == 0.0 and lo_open and hi is None:
        allowed = "a positive number (finite)"
    elif lo is not None and hi is not None:
        allowed = f"a number in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
    else:
        allowed = "a finite number" + (" " + " and ".join(bounds) if bounds else "")
    if none:
        allowed += " (or None)"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Real, np.floating)):
        raise _fail(who, name, allowed, value)
    x = float(value)
    if not np.isfinite(x):
        raise _fail(who, name, allowed, value)
    if lo is not None and (x <= lo if lo_open else x < lo):
        raise _fail(who, name, allowed, value)
    if hi is not None and x > hi:
        raise _fail(who, name, allowed, value)
    return x


def integer(
    who: str, name: str, value, *, lo: int = 0, hi: int = INT_MAX, none: bool = False
) -> int | None:
    """An integer (int or numpy integer; not bool, not a float such as 1.5) in [lo, hi]."""
    if value is None and none:
        return None
    if hi == INT_MAX and lo in (0, 1):
        allowed = "a positive integer" if lo == 1 else "a non-negative integer"
    else:
        allowed = f"an integer in [{lo}, {hi}]"
    allowed += " (or None)" if none else ""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Integral, np.integer)):
        raise _fail(who, name, allowed, value)
    k = int(value)
    if not lo <= k <= hi:
        raise _fail(who, name, allowed, value)
    return k


def choice(who: str, name: str, value, allowed: Iterable[str], *, none: bool = False):
    """One of the strings ``allowed`` (None passes when ``none``)."""
    allowed = tuple(allowed)
    if value is None and none:
        return None
    if not isinstance(value, str) or value not in allowed:
        if len(allowed) == 2 and not none:
            listed = f"{allowed[0]!r} or {allowed[1]!r}"
        else:
            listed = "one of " + ", ".join(repr(a) for a in allowed) + (" or None" if none else "")
        raise _fail(who, name, listed, value)
    return value


def flag(who: str, name: str, value) -> bool:
    """True or False (a numpy bool too)."""
    if not isinstance(value, (bool, np.bool_)):
        raise _fail(who, name, "True or False", value)
    return bool(value)


def text(who: str, name: str, value) -> str:
    """A str that UTF-8 can encode (no lone surrogate)."""
    if not isinstance(value, str):
        raise _fail(who, name, "a str", value)
    try:
        value.encode("utf-8")
    except UnicodeEncodeError as err:
        raise _core.ModelError(
            f"{who}: {name} must be valid Unicode text: it holds a lone surrogate "
            f"{value[err.start]!r} at index {err.start}"
        ) from None
    return value


def array(who: str, name: str, value, *, ndim: int | None = None, finite: bool = False):
    """``value`` as a float64 numpy array: real numbers only (complex, object, str and bool
    arrays are refused), of ``ndim`` dimensions when given, all finite when ``finite`` (the
    first non-finite entry is named)."""
    try:
        a = np.asarray(value)
    except (ValueError, TypeError) as err:  # ragged nested lists
        raise _core.ModelError(f"{who}: {name} must be an array of numbers ({err})") from None
    if a.dtype.kind not in "iuf":
        kind = {"c": "complex", "b": "bool", "O": "objects", "U": "strings", "S": "bytes"}
        raise _core.ModelError(
            f"{who}: {name} must hold real numbers, got an array of "
            f"{kind.get(a.dtype.kind, str(a.dtype))}"
        )
    a = a.astype(float, copy=False)
    if ndim is not None and a.ndim != ndim:
        raise _core.ModelError(f"{who}: {name} must be {ndim}-dimensional, got shape {a.shape}")
    if finite:
        finite_entries(who, name, a)
    return a


def finite_entries(who: str, name: str, a: np.ndarray, what: str = "is not finite") -> None:
    """ModelError naming the first non-finite entry of ``a`` (its index: row, column)."""
    bad = ~np.isfinite(a)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = ", ".join(str(i) for i in idx)
        raise _core.ModelError(f"{who}: {name}[{where}] = {a[idx]!r} {what}")


def regular_file(path, what: str, max_bytes: int) -> bytes:
    """The bytes of the file at ``path``, which must be a regular file of at most ``max_bytes``
    bytes: checked with stat before it is opened, so that a FIFO or a device (``/dev/zero``)
    never blocks or streams, then opened without blocking and read up to the bound (the rules
    the URDF loader applies to its files). OSError for a missing or unreadable file, ModelError
    for anything else; both name the file as ``what 'path'``."""
    path = os.fspath(path)
    shown = f"{what} {str(path)!r}"
    st = os.stat(path)  # FileNotFoundError / PermissionError name the path themselves
    if not stat.S_ISREG(st.st_mode):
        raise _core.ModelError(f"{shown} is {_file_kind(st.st_mode)}, not a regular file")
    if st.st_size > max_bytes:
        raise _core.ModelError(_too_large(shown, st.st_size, max_bytes))
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # replaced since the stat
            raise _core.ModelError(f"{shown} is not a regular file")
        data = f.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise _core.ModelError(_too_large(shown, len(data), max_bytes))
    return data


def _file_kind(mode: int) -> str:
    for test, kind in (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return kind
    return "not a regular file"


def _too_large(shown: str, size: int, max_bytes: int) -> str:
    return (
        f"{shown} is {size} bytes, more than the limit of {max_bytes} bytes ({max_bytes >> 20} MiB)"
    )
