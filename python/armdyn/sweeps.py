"""Parameter sweeps on Dask: :func:`sweep` runs a function over the Cartesian product of a grid
on a ``dask.distributed`` cluster and returns an ``xarray.Dataset``.

Optional dependency (``pip install "armdyn[distributed]"``): ``dask[distributed]`` and
``xarray`` (``tqdm`` for ``progress=True``). They are imported when :func:`sweep` is called,
never by ``import armdyn``.

The module is ``armdyn.sweeps`` (plural) so that the package attribute ``armdyn.sweep`` stays
the function: importing a submodule ``armdyn.sweep`` would rebind that attribute to the module.
"""

from __future__ import annotations

import importlib
import inspect
import itertools
import json
import logging
import os
import secrets
from collections import Counter
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from armdyn import _core
from armdyn._checks import ArgumentTypeError

if TYPE_CHECKING:
    import xarray as xr

#: keyword names of :func:`sweep` itself: they cannot be grid names
RESERVED = ("fn", "client", "retries", "progress", "seed", "dims", "coords")
#: the variable name of a non-dict output
RESULT = "result"

_MISSING = (
    'armdyn.sweep needs dask.distributed and xarray: pip install "armdyn[distributed]" '
    '(or pip install "dask[distributed]" xarray)'
)


def _import_optional():
    try:
        import distributed
        import xarray
    except ImportError as exc:  # pragma: no cover - exercised in a subprocess by the tests
        raise ImportError(f"{_MISSING} ({exc})") from exc
    return distributed, xarray


def _cores() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _as_array(name: str, value) -> tuple[np.ndarray, tuple | None]:
    """One output variable as a numeric numpy array (and the dims of a DataArray-like value)."""
    dims = getattr(value, "dims", None)
    arr = np.asarray(value)
    if arr.dtype.kind not in "biufc":
        raise TypeError(
            f"output {name!r} is {type(value).__name__} of dtype {arr.dtype}: fn must return a "
            "number, a numeric numpy array, or a dict of those"
        )
    if dims is not None:
        dims = tuple(str(d) for d in dims)
        if len(dims) != arr.ndim:
            dims = None
    return arr, dims


def _normalise(out) -> dict[str, tuple[np.ndarray, tuple | None]]:
    if isinstance(out, Mapping):
        if not out:
            raise TypeError("fn returned an empty dict")
        bad = [k for k in out if not isinstance(k, str)]
        if bad:
            raise TypeError(f"fn returned a dict with non-string keys {bad!r}")
        return {k: _as_array(k, v) for k, v in out.items()}
    return {RESULT: _as_array(RESULT, out)}


def _call(fn: Callable, point: dict, seed) -> dict:
    """The task run on a worker for one grid point: fn(**point[, seed]) normalised to arrays."""
    kwargs = dict(point)
    if seed is not None:
        kwargs["seed"] = seed
    return _normalise(fn(**kwargs))


def _takes_seed(fn: Callable) -> bool:
    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return False
    p = params.get("seed")
    return p is not None and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)


def _check_grid(grid: dict) -> dict[str, tuple[np.ndarray, list]]:
    """Each axis as (coordinate array, the values passed to fn)."""
    if not grid:
        raise _core.ModelError(
            "sweep needs at least one grid axis, e.g. sweep(fn, payload=[0.0, 1.0])"
        )
    axes = {}
    for name, values in grid.items():
        if name == "status":
            raise _core.ModelError("grid axis 'status' clashes with the Dataset's status variable")
        try:
            ndim = np.ndim(values)
        except ValueError:  # ragged nesting
            ndim = -1
        if isinstance(values, str | bytes) or ndim != 1:
            raise _core.ModelError(
                f"grid axis {name!r} must be a 1-D sequence of values, got {values!r:.80}"
            )
        values = list(values)
        arr = np.asarray(values)
        if arr.dtype.kind in "US" and not all(isinstance(v, str | bytes) for v in values):
            arr = np.asarray(values, dtype=object)  # mixed types: no conversion to strings
        if arr.size == 0:
            raise _core.ModelError(f"grid axis {name!r} is empty")
        try:
            distinct = len(set(arr.tolist())) == arr.size
        except TypeError:  # unhashable values
            distinct = True
        if not distinct:
            raise _core.ModelError(f"grid axis {name!r} has repeated values: {arr.tolist()!r:.200}")
        axes[name] = (arr, values)
    return axes


def _signature(out: dict) -> tuple:
    return tuple((k, a.shape) for k, (a, _) in out.items())


def _entropy(root: np.random.SeedSequence):
    """The root's entropy as an attribute: an int, or a list of ints."""
    e = root.entropy
    return int(e) if isinstance(e, int | np.integer) else [int(x) for x in e]


def _message(exc: BaseException) -> str:
    text = str(exc)
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def sweep(
    fn: Callable[..., Any],
    client: Any = None,
    *,
    retries: int = 0,
    progress: bool = False,
    seed: int | np.random.SeedSequence | None = None,
    dims: Mapping[str, tuple[str, ...]] | None = None,
    coords: Mapping[str, Any] | None = None,
    **grid: Any,
) -> xr.Dataset:
    """Run ``fn(**point)`` at every point of the Cartesian product of ``grid`` on Dask.

    Args:
        fn: the function of one grid point; its keyword arguments are the grid names. It
            returns a number, a numeric numpy array, or a dict ``{name: number or array}`` (a
            value with a ``dims`` attribute, e.g. an ``xarray.DataArray``, names its own
            dimensions). It must be picklable (cloudpickle: lambdas and closures are) and build
            what it needs itself, e.g. its model from a URDF path.
        client: a ``distributed.Client``, used as it is (a LocalCluster, dask-jobqueue's SLURM or
            PBS cluster, Kubernetes, ...); None starts a ``LocalCluster`` on this machine (worker
            processes, one per core, one thread each) and closes it afterwards.
        retries: Dask retries of a point whose fn raised (or whose worker died) before it is
            recorded as failed.
        progress: show a progress bar (tqdm) while points finish.
        seed: with an ``int`` (or a ``numpy.random.SeedSequence``), every point gets its own
            ``numpy.random.SeedSequence`` spawned from it in grid order (C order of the
            product), passed as ``fn(..., seed=ss)`` (``np.random.default_rng(ss)``); fn must
            then take a ``seed`` argument. With None and an fn that takes ``seed``, a fresh
            63-bit seed is drawn; either way the root entropy is ``attrs["seed"]`` and passing it
            back as ``seed=`` repeats the sweep.
        dims: ``{variable: (dim, ...)}`` names of the array dimensions of fn's outputs (default
            ``<variable>_dim0``, ``<variable>_dim1``, ... ; variables may share a dimension).
        coords: ``{dim: values}`` coordinates of output dimensions.
        **grid: ``name=values``, each a 1-D sequence of distinct values. The names ``fn``,
            ``client``, ``retries``, ``progress``, ``seed``, ``dims`` and ``coords`` are this
            function's own and cannot be grid names.

    Returns:
        ``xarray.Dataset`` with the grid names as its first dimensions (coordinates = the grid
        values), each output variable (dims: the grid's, then its own), and ``status``: "ok"
        or the point's error (``"ValueError: ..."``). A failed point's outputs are NaN;
        integer and boolean outputs become float64 when a point failed. Points whose outputs
        differ in names or shapes from the most common structure are failed with a status
        saying so. ``attrs``: ``armdyn_version``, ``grid`` (JSON of the grid), ``seed``
        (root entropy, or "none"), ``fn``, ``retries``, ``failed`` (number of failed points).

    Raises:
        ImportError: dask.distributed or xarray is not installed.
        armdyn.ModelError (also a TypeError): fn is not callable, a seed that is not an int
            or SeedSequence or that fn cannot take, or a client that is not a
            ``distributed.Client``.
        armdyn.ModelError (a ValueError): an empty or non-1-D grid axis, repeated grid
            values, a bad ``retries``, ``dims`` or ``coords`` entry, or an output name that
            clashes with a grid name or ``status``.
    """
    _check_arguments(fn, retries, seed)
    checked = _check_grid(grid)
    axes = {k: arr for k, (arr, _) in checked.items()}
    dims = dict(dims or {})
    coords = dict(coords or {})
    takes_seed = _check_seed_use(fn, seed)
    distributed, xr = _import_optional()
    names, shape, points = _points(checked)
    root, seeds = _seeds(seed, takes_seed, len(points))
    _check_client(client, distributed)
    bar = _progress_bar(progress)
    results, errors = _run_points(fn, client, distributed, points, seeds, retries, bar)
    _fail_odd_structures(results, errors, points)
    data_vars = _data_vars(results, errors, names, shape, axes, dims)
    ok = any(r is not None for r in results)
    all_coords = _coords(axes, coords, data_vars, ok)
    attrs = _attrs(axes, root, fn, retries, errors)
    try:
        return xr.Dataset(data_vars, coords=all_coords, attrs=attrs)
    except ValueError as exc:  # e.g. a coordinate of the wrong length
        raise ValueError(f"sweep: cannot assemble the Dataset: {exc}") from exc


# --- the stages of sweep, in order ------------------------------------------------------------


def _check_arguments(fn, retries, seed) -> None:
    """fn callable, retries an integer >= 0, seed an int, a SeedSequence or None."""
    if not callable(fn):
        raise ArgumentTypeError(f"sweep: fn must be callable, got {type(fn).__name__}")
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise _core.ModelError(f"sweep: retries must be an integer >= 0, got {retries!r}")
    if seed is not None and not isinstance(seed, int | np.integer | np.random.SeedSequence):
        raise ArgumentTypeError(
            f"sweep: seed must be an int, a numpy SeedSequence or None, got {seed!r:.80} "
            "(a grid axis cannot be named 'seed')"
        )


def _check_seed_use(fn, seed) -> bool:
    """Whether fn takes a ``seed`` argument; a seed given to an fn without one is an error."""
    takes_seed = _takes_seed(fn)
    if seed is not None and not takes_seed:
        raise ArgumentTypeError(
            f"sweep: seed={seed!r} given but fn {getattr(fn, '__name__', fn)!r} takes no "
            "'seed' argument"
        )
    return takes_seed


def _points(checked: dict) -> tuple[list[str], tuple[int, ...], list[dict]]:
    """``(names, shape, points)``: the grid's axis names and shape, and one ``{name: value}``
    per point in C order of the product, the values plain Python (numpy scalars' .item())."""
    names = list(checked)
    shape = tuple(arr.size for arr, _ in checked.values())
    values = [
        [v.item() if isinstance(v, np.generic) else v for v in vs] for _, vs in checked.values()
    ]
    points = [dict(zip(names, combo, strict=True)) for combo in itertools.product(*values)]
    return names, shape, points


def _seeds(seed, takes_seed: bool, n: int):
    """``(root, seeds)``: the root SeedSequence (None when fn takes no seed) and one spawned
    SeedSequence per point (None each when fn takes no seed)."""
    if not takes_seed:
        return None, [None] * n
    if seed is None:  # fresh entropy, 63 bits: an int64 attribute (netCDF) repeats it
        seed = secrets.randbits(63)
    root = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    return root, root.spawn(n)


def _check_client(client, distributed) -> None:
    if client is not None and not isinstance(client, distributed.Client):
        raise ArgumentTypeError(
            f"sweep: client must be a distributed.Client or None, got {type(client).__name__}"
            " (for a cluster object: distributed.Client(cluster))"
        )


def _progress_bar(progress: bool):
    """tqdm's progress bar class when asked for (an ImportError without tqdm), else None."""
    if not progress:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError as exc:
        raise ImportError(f"sweep(progress=True) needs tqdm: {_MISSING}") from exc
    return tqdm


def _run_points(fn, client, distributed, points, seeds, retries, bar):
    """``(results, errors)`` per point: fn's normalised outputs (None for a failed point) and
    the failure's message (None for a point that ran). Without a client, on a LocalCluster
    started and closed here; on a given client, whatever is still running when this is
    interrupted is cancelled."""
    own = client is None
    cluster = None
    if own:
        cluster = distributed.LocalCluster(
            n_workers=_cores(),
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            # a failing point is recorded in `status`: no worker traceback on the console
            silence_logs=logging.CRITICAL,
        )
        client = distributed.Client(cluster)
    futures: list = []
    try:
        return _submit_and_collect(fn, client, distributed, points, seeds, retries, bar, futures)
    except BaseException:  # Ctrl-C or a lost client: nothing left running on a given cluster
        if not own and futures:
            client.cancel([f for f in futures if not f.done()])
        raise
    finally:
        if own:
            client.close()
            cluster.close()


def _submit_and_collect(fn, client, distributed, points, seeds, retries, bar, futures):
    """Submit one task per point (appended to ``futures``) and collect them as they finish;
    when workers died under several points, each of those runs once more alone, so that only
    the culprits stay failed (a point queued on a worker another point crashed dies with it)."""
    n = len(points)
    results: list = [None] * n
    errors: list[str | None] = [None] * n
    futures.extend(
        [
            client.submit(_call, fn, p, s, retries=retries, pure=False)
            for p, s in zip(points, seeds, strict=True)
        ]
    )
    index = {f.key: i for i, f in enumerate(futures)}
    progress = bar(total=n, desc="sweep", unit="point") if bar is not None else None
    killed: list[int] = []
    try:
        for fut in distributed.as_completed(futures):
            _collect(fut, index[fut.key], results, errors, killed, distributed)
            if progress is not None:
                progress.update()
        if len(killed) > 1:
            for i in list(killed):
                fut = client.submit(_call, fn, points[i], seeds[i], retries=retries, pure=False)
                futures.append(fut)
                distributed.wait(fut)
                _collect(fut, i, results, errors, killed, distributed)
    finally:
        if progress is not None:
            progress.close()
    return results, errors


def _collect(fut, i: int, results: list, errors: list, killed: list, distributed) -> None:
    """Point ``i``'s outcome from its finished future (a KilledWorker adds it to ``killed``)."""
    if fut.status == "finished":
        results[i], errors[i] = fut.result(), None
    else:
        exc = fut.exception()
        errors[i] = _message(exc) if exc is not None else f"task {fut.status}"
        if isinstance(exc, distributed.KilledWorker):
            killed.append(i)
    fut.release()


def _fail_odd_structures(results: list, errors: list, points: list[dict]) -> None:
    """The structure shared by the successful points is the most common one (first in grid
    order on a tie); points whose outputs differ from it are failed (in place)."""
    sigs = Counter(_signature(r) for r in results if r is not None)
    if not sigs:
        return
    best = max(sigs.values())
    ref_sig = next(_signature(r) for r in results if r is not None and sigs[_signature(r)] == best)
    ref_point = next(i for i, r in enumerate(results) if r is not None and _signature(r) == ref_sig)
    for i, r in enumerate(results):
        if r is not None and _signature(r) != ref_sig:
            errors[i] = (
                f"output structure {dict(_signature(r))} differs from "
                f"{dict(ref_sig)} of point {points[ref_point]}"
            )
            results[i] = None


def _data_vars(results, errors, names, shape, axes, dims) -> dict:
    """The Dataset's variables: each output over the grid (NaN, or 0, at failed points) and
    ``status``."""
    ok = [r for r in results if r is not None]
    data_vars: dict = {}
    if ok:
        for var, (arr0, own_dims) in ok[0].items():
            vdims = _output_dims(var, arr0, own_dims, axes, dims)
            data_vars[var] = ((*names, *vdims), _gridded(var, arr0, results, ok, shape))
    unknown = [v for v in dims if v not in data_vars]
    if unknown and ok:
        raise _core.ModelError(f"sweep: dims given for {unknown}, which fn does not return")
    status = np.array(["ok" if e is None else e for e in errors], dtype=object).reshape(shape)
    data_vars["status"] = (tuple(names), status)
    return data_vars


def _output_dims(var: str, arr0: np.ndarray, own_dims, axes, dims) -> tuple:
    """The names of an output's own dimensions: ``dims[var]``, else the ones it carries, else
    ``<var>_dim0``, ...; checked against its shape and the grid's names."""
    if var in axes or var == "status":
        raise _core.ModelError(f"sweep: output {var!r} has the name of a grid axis or of 'status'")
    vdims = tuple(dims.get(var, own_dims or tuple(f"{var}_dim{k}" for k in range(arr0.ndim))))
    if len(vdims) != arr0.ndim:
        raise _core.ModelError(
            f"sweep: dims[{var!r}] = {vdims!r} names {len(vdims)} dimensions but "
            f"{var!r} has shape {arr0.shape}"
        )
    clash = [d for d in vdims if d in axes]
    if clash:
        raise _core.ModelError(f"sweep: output dims {clash} of {var!r} repeat grid names")
    return vdims


def _gridded(var: str, arr0: np.ndarray, results, ok, shape) -> np.ndarray:
    """One output over the grid, in the common dtype of the points' values (float64 for an
    integer output when some point failed: its entries are NaN)."""
    n = len(results)
    dtype = np.result_type(*{r[var][0].dtype for r in ok})
    if len(ok) < n and dtype.kind in "biu":
        dtype = np.dtype(np.float64)
    full = np.full(shape + arr0.shape, np.nan if dtype.kind in "fc" else 0, dtype=dtype)
    flat = full.reshape((n, *arr0.shape))
    for i, r in enumerate(results):
        if r is not None:
            flat[i] = r[var][0]
    return full


def _coords(axes, coords, data_vars, ok: bool) -> dict:
    """The grid's coordinates and the given ones of output dimensions (checked)."""
    all_coords = {k: (k, v) for k, v in axes.items()}
    used = {d for v in data_vars.values() for d in v[0]}
    for d, values in coords.items():
        if d in axes:
            raise _core.ModelError(
                f"sweep: coords[{d!r}]: {d!r} is a grid axis (its values are the grid's)"
            )
        if ok and d not in used:
            raise _core.ModelError(f"sweep: coords[{d!r}]: no output has a dimension {d!r}")
        all_coords[d] = (d, np.asarray(values))
    return all_coords


def _attrs(axes, root, fn, retries, errors) -> dict:
    """The Dataset's attributes: the armdyn version, the grid, the seed, fn, retries and the
    number of failed points."""
    # the package's version without importing the package from its own submodule (no cycle)
    __version__ = importlib.import_module("armdyn").__version__
    return {
        "armdyn_version": __version__,
        "grid": json.dumps({k: v.tolist() for k, v in axes.items()}, default=str),
        "seed": "none" if root is None else _entropy(root),
        "fn": getattr(fn, "__qualname__", type(fn).__name__),
        "retries": retries,
        "failed": int(sum(e is not None for e in errors)),
    }
