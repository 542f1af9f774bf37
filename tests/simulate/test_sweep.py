"""armdyn.sweep on a 2-worker LocalCluster (worker processes, one cluster for the module): the
Dataset equals fn called serially at every grid point, failing points are recorded in `status`
(NaN outputs) and retried when asked, array outputs get their dimensions and coordinates, the
per-point seeds are the SeedSequence spawn of the root seed, and bad input raises naming it."""

import importlib.metadata
import itertools
import json
import os
import sys
from pathlib import Path

import armdyn as ad
import cloudpickle
import numpy as np
import pytest

distributed = pytest.importorskip("distributed")
xr = pytest.importorskip("xarray")

# the workers cannot import this test module: its functions travel by value
cloudpickle.register_pickle_by_value(sys.modules[__name__])


def _ur5() -> str:
    sub = Path("cmeel.prefix", "share", "example-robot-data", "robots", "ur_description")
    dist = importlib.metadata.distribution("example-robot-data")
    path = Path(dist.locate_file(sub)) / "urdf" / "ur5_robot.urdf"
    assert path.is_file(), path
    return str(path)


UR5 = _ur5()
Q = np.array([0.3, -1.0, 1.2, -0.5, 0.8, 0.1])


def ur5_point(payload, speed):
    """UR5 with a payload welded to the flange's body, inverse dynamics at one state; the
    model is built inside (models need not travel to the workers)."""
    b = ad.urdf_builder(UR5)
    wrist = ad.load_urdf(UR5).frame("tool0")["body"]
    b.add_body("payload", payload, [payload * 0.01 / 6] * 3, position=(0.4, 0.1, 0.6))
    b.add_fixed("mount", wrist, "payload")
    model = b.finalize()
    qd = speed * np.linspace(1.0, -0.5, 6)
    qdd = np.array([1.0, -2.0, 0.5, 3.0, -1.0, 2.0])
    tau = ad.inverse_dynamics(model, Q, qd, qdd)
    return {"tau": tau, "peak": float(np.abs(tau).max()), "nb": model.nb}


@pytest.fixture(scope="module")
def client():
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


def test_results_equal_serial_calls(client):
    grid = {"payload": [0.5, 1.0, 3.0, 5.0], "speed": [0.0, 0.7, 1.5]}
    ds = ad.sweep(ur5_point, client, dims={"tau": ("joint",)}, **grid)
    assert isinstance(ds, xr.Dataset)
    assert dict(ds.sizes) == {"payload": 4, "speed": 3, "joint": 6}
    assert ds["tau"].dims == ("payload", "speed", "joint")
    assert ds["peak"].dims == ("payload", "speed")
    np.testing.assert_array_equal(ds["payload"].values, grid["payload"])
    np.testing.assert_array_equal(ds["speed"].values, grid["speed"])
    assert (ds["status"].values == "ok").all()
    for p, s in itertools.product(grid["payload"], grid["speed"]):
        ref = ur5_point(p, s)
        got = ds.sel(payload=p, speed=s)
        np.testing.assert_array_equal(got["tau"].values, ref["tau"])
        assert got["peak"].item() == ref["peak"]
        assert got["nb"].item() == ref["nb"]
    assert ds["nb"].dtype.kind == "i"  # integers stay integers when no point fails
    attrs = ds.attrs
    assert attrs["armdyn_version"] == ad.__version__
    assert json.loads(attrs["grid"]) == grid
    assert attrs["seed"] == "none" and attrs["failed"] == 0 and attrs["fn"] == "ur5_point"


def _static(payload):
    """Gravity torques of the UR5 with a payload at rest (a module-level fn, no dict)."""
    b = ad.urdf_builder(UR5)
    wrist = ad.load_urdf(UR5).frame("tool0")["body"]
    b.add_body("payload", payload, [1e-3] * 3, position=(0.4, 0.1, 0.6))
    b.add_fixed("mount", wrist, "payload")
    b.add_frame("payload_com", "payload", position=(0.4, 0.1, 0.6))
    model = b.finalize()
    zero = np.zeros(6)
    return ad.inverse_dynamics(model, Q, zero, zero)


def test_array_output_is_linear_in_the_payload_as_j_transpose_m_g(client):
    """A bare array output (variable `result`, dims result_dim0): the payload's share of the
    static torques is J_v(payload)^T m g, J_v from ad.frame_jacobian."""
    masses = [0.0, 1.0, 2.5]
    ds = ad.sweep(_static, client, payload=masses)
    assert ds["result"].dims == ("payload", "result_dim0")
    b = ad.urdf_builder(UR5)
    b.add_body("payload", 1.0, [1e-3] * 3, position=(0.4, 0.1, 0.6))
    b.add_fixed("mount", ad.load_urdf(UR5).frame("tool0")["body"], "payload")
    b.add_frame("payload_com", "payload", position=(0.4, 0.1, 0.6))
    jv = ad.frame_jacobian(b.finalize(), Q, "payload_com")[:3]
    base = ds["result"].sel(payload=0.0).values
    for m in masses[1:]:
        extra = ds["result"].sel(payload=m).values - base
        np.testing.assert_allclose(extra, jv.T @ [0.0, 0.0, m * 9.81], rtol=1e-9, atol=1e-9)


def flaky_point(x, mode):
    if mode == "raise" and x == 2:
        raise ValueError(f"no solution at x={x}")
    if mode == "shape" and x == 3:
        return {"a": float(x), "v": np.zeros(4)}
    return {"a": float(x), "v": np.full(2, x), "i": int(x)}


def test_failing_points_are_recorded_not_raised(client):
    ds = ad.sweep(flaky_point, client, x=[1, 2, 3, 4], mode=["raise", "fine"])
    status = ds["status"]
    assert status.sel(x=2, mode="raise").item() == "ValueError: no solution at x=2"
    assert (status.values == "ok").sum() == 7 and ds.attrs["failed"] == 1
    assert np.isnan(ds["a"].sel(x=2, mode="raise").item())
    assert np.isnan(ds["v"].sel(x=2, mode="raise").values).all()
    # integers become float with NaN where a point failed
    assert ds["i"].dtype == np.float64 and np.isnan(ds["i"].sel(x=2, mode="raise").item())
    np.testing.assert_array_equal(ds["a"].sel(mode="fine").values, [1.0, 2.0, 3.0, 4.0])
    np.testing.assert_array_equal(ds["v"].sel(x=4, mode="raise").values, [4.0, 4.0])


def test_an_unsupported_output_is_a_failed_point(client):
    ds = ad.sweep(lambda x: None if x == 1 else {"a": x}, client, x=[1, 2])
    assert ds["status"].sel(x=1).item() == (
        "TypeError: output 'result' is NoneType of dtype object: fn must return a number, "
        "a numeric numpy array, or a dict of those"
    )
    assert ds["status"].sel(x=2).item() == "ok" and ds["a"].sel(x=2).item() == 2.0


def test_a_point_with_another_output_shape_is_failed(client):
    ds = ad.sweep(flaky_point, client, x=[1, 2, 3], mode=["shape"])
    bad = ds["status"].sel(x=3, mode="shape").item()
    assert bad.startswith("output structure") and "(4,)" in bad and "(2,)" in bad
    assert np.isnan(ds["a"].sel(x=3).item()) and ds["a"].sel(x=1).item() == 1.0


def once_then_ok(x, marker_dir):
    """Fails on the first call at each point (a marker file made atomically), then succeeds."""
    path = os.path.join(marker_dir, f"x{x}")
    try:
        os.close(os.open(path, os.O_CREAT | os.O_EXCL))
    except FileExistsError:
        return 10.0 * x
    raise RuntimeError(f"transient failure at x={x}")


def test_retries(client, tmp_path):
    no_retry = tmp_path / "none"
    no_retry.mkdir()
    ds = ad.sweep(once_then_ok, client, x=[1, 2, 3], marker_dir=[str(no_retry)])
    assert list(ds["status"].values.ravel()) == [
        f"RuntimeError: transient failure at x={x}" for x in (1, 2, 3)
    ]
    retry = tmp_path / "one"
    retry.mkdir()
    ds = ad.sweep(once_then_ok, client, retries=1, x=[1, 2, 3], marker_dir=[str(retry)])
    assert (ds["status"].values == "ok").all() and ds.attrs["retries"] == 1
    np.testing.assert_array_equal(ds["result"].values.ravel(), [10.0, 20.0, 30.0])


def noisy(scale, seed):
    rng = np.random.default_rng(seed)
    return {"draw": scale * rng.standard_normal(3)}


def test_seeds_are_spawned_in_grid_order(client):
    ds = ad.sweep(noisy, client, seed=1234, scale=[1.0, 2.0], dims={"draw": ("k",)})
    children = np.random.SeedSequence(1234).spawn(2)
    for i, s in enumerate([1.0, 2.0]):
        ref = noisy(s, children[i])["draw"]
        np.testing.assert_array_equal(ds["draw"].sel(scale=s).values, ref)
    assert ds.attrs["seed"] == 1234
    # a SeedSequence as the root: the same children, its entropy recorded
    same = ad.sweep(noisy, client, seed=np.random.SeedSequence([5, 6]), scale=[1.0])
    ref = noisy(1.0, np.random.SeedSequence([5, 6]).spawn(1)[0])["draw"]
    np.testing.assert_array_equal(same["draw"].values[0], ref)
    assert same.attrs["seed"] == [5, 6]
    # without a seed: fresh entropy, recorded, and passing it back repeats the sweep
    first = ad.sweep(noisy, client, scale=[1.0, 2.0])
    assert 0 <= first.attrs["seed"] < 2**63  # fits an int64 attribute
    again = ad.sweep(noisy, client, seed=first.attrs["seed"], scale=[1.0, 2.0])
    np.testing.assert_array_equal(first["draw"].values, again["draw"].values)
    assert not np.array_equal(first["draw"].values, ds["draw"].values)


def test_output_dims_coords_and_dataarray_outputs(client):
    import xarray

    def per_joint(gain):
        names = ["a", "b", "c"]
        return {
            "peak": gain * np.array([1.0, 2.0, 3.0]),
            "rms": gain * np.array([0.5, 1.0, 1.5]),
            "map": xarray.DataArray(gain * np.ones((3, 2)), dims=("joint", "side")),
            "names": len(names),
        }

    ds = ad.sweep(
        per_joint,
        client,
        gain=[1.0, 2.0],
        dims={"peak": ("joint",), "rms": ("joint",)},
        coords={"joint": ["a", "b", "c"], "side": ["in", "out"]},
    )
    assert ds["peak"].dims == ("gain", "joint") and ds["rms"].dims == ("gain", "joint")
    assert ds["map"].dims == ("gain", "joint", "side")
    assert list(ds["joint"].values) == ["a", "b", "c"]
    assert ds["peak"].sel(gain=2.0, joint="c").item() == 6.0
    assert ds["map"].sel(gain=2.0, side="out", joint="b").item() == 2.0


def test_mixed_type_axis_passes_the_values_unchanged(client):
    ds = ad.sweep(lambda x: {"is_int": isinstance(x, int), "n": len(str(x))}, client, x=[10, "ab"])
    assert ds["x"].dtype == object and list(ds["x"].values) == [10, "ab"]
    np.testing.assert_array_equal(ds["is_int"].values, [True, False])


def test_progress_bar(client, capsys):
    ad.sweep(flaky_point, client, progress=True, x=[1, 2], mode=["fine"])
    err = capsys.readouterr().err
    assert "sweep" in err and "2/2" in err


def test_own_local_cluster_when_no_client():
    """client=None starts a LocalCluster (processes), runs, and closes it."""
    ds = ad.sweep(flaky_point, x=[1, 2, 3], mode=["fine"])
    np.testing.assert_array_equal(ds["a"].values.ravel(), [1.0, 2.0, 3.0])
    assert (ds["status"].values == "ok").all()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({}, "at least one grid axis"),
        ({"x": [[1, 2], [3, 4]]}, "'x' must be a 1-D sequence"),
        ({"x": "abc"}, "'x' must be a 1-D sequence"),
        ({"x": 3.0}, "'x' must be a 1-D sequence"),
        ({"x": []}, "'x' is empty"),
        ({"x": [[1], [2, 3]]}, "'x' must be a 1-D sequence"),
        ({"x": [1.0, 2.0, 1.0]}, "'x' has repeated values"),
        ({"x": [1], "retries": -1}, "retries must be an integer >= 0"),
        ({"status": [1, 2]}, "grid axis 'status' clashes"),
    ],
)
def test_bad_grids_raise_before_any_work(kwargs, match):
    # a ModelError naming the argument, still a ValueError for code written before
    with pytest.raises(ad.ModelError, match=match) as err:
        ad.sweep(flaky_point, **kwargs)
    assert isinstance(err.value, ValueError)


def test_bad_fn_and_seed_raise():
    # ModelErrors naming the argument that are also TypeErrors (as documented before)
    for call, match in [
        (lambda: ad.sweep(3, x=[1]), "fn must be callable"),
        (lambda: ad.sweep(flaky_point, seed=1, x=[1], mode=["fine"]), "takes no 'seed' argument"),
        (lambda: ad.sweep(noisy, seed=[1, 2], scale=[1.0]), "a grid axis cannot be named 'seed'"),
    ]:
        with pytest.raises(ad.ModelError, match=match) as err:
            call()
        assert isinstance(err.value, TypeError)


def test_a_cluster_instead_of_a_client_raises(client):
    with pytest.raises(
        ad.ModelError, match=r"client must be a distributed.Client or None, got Loc"
    ):
        ad.sweep(flaky_point, client.cluster, x=[1], mode=["fine"])


def test_output_clashing_with_a_grid_name_raises(client):
    with pytest.raises(ad.ModelError, match="output 'a' has the name of a grid axis"):
        ad.sweep(lambda a: {"a": a}, client, a=[1])


def test_clear_import_error_without_dask(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(ImportError, match=r'pip install "armdyn\[distributed\]"'):
        ad.sweep(flaky_point, x=[1], mode=["fine"])


def crash_at_two(x):
    if x == 2:
        os._exit(1)  # as a segfault in compiled code would: the worker process dies
    return 1.5 * x


def test_a_point_that_kills_its_worker_is_recorded():
    """After the scheduler's allowed failures (none here: one worker death) the point is
    recorded as KilledWorker; a point queued behind it on the dying worker (killed with it) is
    run again alone and succeeds."""
    import dask

    with (
        dask.config.set({"distributed.scheduler.allowed-failures": 0}),
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        ds = ad.sweep(crash_at_two, c, x=[1, 2, 3, 4])
    assert ds["status"].sel(x=2).item().startswith("KilledWorker")
    np.testing.assert_array_equal(ds["result"].values, [1.5, np.nan, 4.5, 6.0])
