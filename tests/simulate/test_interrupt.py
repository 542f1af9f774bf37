"""Interrupt, callbacks, progress and the output memory bound of simulate (issue 23).

Ctrl-C is checked by the compiled loops' signal poll: SIGINT is sent to a child process running
a long simulation (or inverse-dynamics loop, or URDF load), which catches the KeyboardInterrupt
and reports its partial result, checked against an uninterrupted run of the same length (the
same steps: equal to round-off). That the work stopped *inside* the compiled call, by its poll,
and not after it (Python raises a pending KeyboardInterrupt once a call returns) is seen without
a clock: the child's SIGINT handler runs in the poll, and a profile hook tells whether a call
into ``armdyn._core`` is in progress (CHILD_PROLOGUE). No test here asserts a time: how soon the
work stops after the signal is measured by ``python -m benchmarks.interrupt_latency``
(docs/benchmarks.md); the only clock is a hang guard of minutes.
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import armdyn as ad
import numpy as np
import pytest
from conftest import simple_pendulum

# the child's SIGINT handler: a KeyboardInterrupt when it runs inside a call into armdyn's compiled
# module (the loop's poll ran it: the work stops there), else (the signal landed in Python
# between two calls) "again" on stdout, and the parent sends another signal. Installed whatever
# the parent's disposition (a shell's background job starts its children with SIGINT ignored).
CHILD_PROLOGUE = textwrap.dedent(
    """
    import json, signal, sys
    import numpy as np
    import armdyn as ad

    INSIDE = 0  # calls into armdyn._core in progress (their c_call/c_return profile events)
    STOPPED_INSIDE = []


    def _track(frame, event, arg):
        global INSIDE
        if getattr(arg, "__module__", None) == "armdyn._core":
            if event == "c_call":
                INSIDE += 1
            elif event in ("c_return", "c_exception"):
                INSIDE -= 1


    def _on_sigint(signum, frame):
        if INSIDE > 0:
            STOPPED_INSIDE.append(True)
            raise KeyboardInterrupt
        print("again", flush=True)


    sys.setprofile(_track)
    signal.signal(signal.SIGINT, _on_sigint)
    """
)

# a hang guard, not a latency bound: the child is killed (and the test fails) past it
HANG_GUARD_S = 300.0

CHILD = CHILD_PROLOGUE + textwrap.dedent(
    """
    method = sys.argv[1]
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("bob", 1.0, np.eye(3) * 1e-3, position=(-0.5, 0.0, -0.8))
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    opts = dict(max_steps=10**10)
    if method == "rk4":
        opts.update(integrator="rk4", dt=1e-5, output_dt=0.01)
    elif method == "kinematic":
        b.add_drive("hinge", lambda t: (np.sin(t), np.cos(t), -np.sin(t)))
        opts.update(integrator="kinematic", output_dt=0.01)
    elif method == "trbdf2":
        opts.update(integrator="trbdf2", rtol=1e-9, atol=1e-11, output_dt=0.01)
    else:
        opts.update(integrator=method, rtol=1e-13, atol=1e-13, output_dt=0.01)
    model = b.finalize()
    print("ready", flush=True)
    try:
        ad.simulate(model, 1e4, **opts)
        print(json.dumps({"completed": True}), flush=True)
        sys.exit(0)
    except KeyboardInterrupt as err:
        r = err.result
    # the partial result against an uninterrupted run to its last output time
    ref = ad.simulate(model, float(r.t[-1]), **opts)
    n = len(ref.t)
    print(json.dumps({
        "inside": bool(STOPPED_INSIDE),
        "rows": len(r.t),
        "t_last": float(r.t[-1]),
        "same_rows": n == len(r.t),
        "t_diff": float(np.max(np.abs(ref.t - r.t[:n]))),
        "q_diff": float(np.max(np.abs(ref.q[:-1] - r.q[:n - 1]))),
        "qd_diff": float(np.max(np.abs(ref.qd[:-1] - r.qd[:n - 1]))),
        "last_diff": float(np.max(np.abs(ref.q[-1] - r.q[n - 1]))),
        "q_scale": float(np.max(np.abs(ref.q))),
    }), flush=True)
    """
)


def _interrupted_child(code, *args, delay):
    """Run ``code`` in a child Python, send it SIGINT ``delay`` s after it prints "ready" (again
    each time it prints "again": the signal landed between two compiled calls), and return its
    JSON report (the last line). The child is killed past HANG_GUARD_S."""
    proc = subprocess.Popen(
        [sys.executable, "-c", code, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    guard = threading.Timer(HANG_GUARD_S, proc.kill)
    guard.start()
    try:
        assert proc.stdout.readline().strip() == "ready", proc.stderr.read()
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        report = None
        for line in proc.stdout:
            if line.strip() == "again":
                time.sleep(delay)
                proc.send_signal(signal.SIGINT)
            elif line.startswith("{"):
                report = json.loads(line)
        err = proc.stderr.read()
        proc.wait()
    finally:
        guard.cancel()
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, f"exit {proc.returncode} (killed past {HANG_GUARD_S} s?): {err}"
    assert report is not None, err
    return report


@pytest.mark.parametrize("method", ["rk4", "dopri5", "dop853", "trbdf2", "kinematic"])
def test_sigint_stops_the_run_inside_its_loop_with_the_partial_result(method):
    report = _interrupted_child(CHILD, method, delay=1.0)
    assert "completed" not in report, f"the run ended before the signal: {report}"
    print(f"{method}: {report['rows']} rows kept")
    # stopped by the stepping loop's poll, inside the call, at a time short of t_end = 1e4
    assert report["inside"]
    assert report["rows"] > 1 and 0 < report["t_last"] < 1e4
    # the partial outputs are those of a run to the same time (the same steps), but for the
    # last output of an error-controlled run, whose final step the shorter run shortens to land
    # on its end (the fixed-step and kinematic runs agree there too)
    assert report["same_rows"] and report["t_diff"] == 0.0
    assert report["q_scale"] > 0.1  # the pendulum swings
    assert report["q_diff"] <= 1e-12 and report["qd_diff"] <= 1e-12, report
    if method in ("rk4", "kinematic"):
        assert report["last_diff"] <= 1e-12, report


ID_CHILD = CHILD_PROLOGUE + textwrap.dedent(
    """
    which = sys.argv[1]
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("a", 1.0, np.eye(3) * 1e-2, position=(0.5, 0.0, 0.0))
    b.add_body("b", 1.0, np.eye(3) * 1e-2, position=(1.5, 0.0, 0.0))
    b.add_revolute("j1", "ground", "a", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_revolute("j2", "a", "b", (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    if which == "driven":
        b.add_drive("j1", lambda t: (np.sin(t), np.cos(t), -np.sin(t)))
        b.add_drive("j2", lambda t: (0.5 * t, 0.5, 0.0))
    model = b.finalize()
    rng = np.random.default_rng(1)
    n = {"batch": 4_000_000, "reactions": 300_000}.get(which, 3_000_000)
    if which in ("batch", "reactions"):
        q, qd, qdd = (rng.standard_normal((n, 2)) for _ in range(3))
    else:
        ts = np.linspace(0.0, 1e4, n)
    print("ready", flush=True)
    calls = 0
    try:
        while True:  # until interrupted: a fast machine cannot finish before the signal
            if which == "batch":
                out = ad.inverse_dynamics(model, q, qd, qdd)
            elif which == "reactions":
                out = ad.joint_reactions(model, q, qd, qdd)
            else:
                out = ad.driven_inverse_dynamics(model, ts)
            calls += 1
    except KeyboardInterrupt as err:
        partial = getattr(err, "result", None)
    report = {"inside": bool(STOPPED_INSIDE), "calls": calls}
    if which == "batch":
        k = len(partial)
        ref = ad.inverse_dynamics(model, q[:k], qd[:k], qdd[:k])
        report.update(rows=k, n=n, diff=float(np.max(np.abs(ref - partial))) if k else 0.0)
    if which == "reactions":  # the rows done, as (forces, torques)
        k = len(partial[0])
        ref = ad.joint_reactions(model, q[:k], qd[:k], qdd[:k])
        diff = max(float(np.max(np.abs(r - p), initial=0.0)) for r, p in zip(ref, partial))
        report.update(rows=k, n=n, diff=diff, same=len(partial[1]) == k)
    print(json.dumps(report), flush=True)
    """
)


@pytest.mark.parametrize("which", ["batch", "driven", "reactions"])
def test_sigint_stops_inverse_dynamics_loops(which):
    # one call takes about 1 s on an idle machine (the batch 0.93 s)
    report = _interrupted_child(ID_CHILD, which, delay=0.25)
    assert report["inside"]  # stopped by the loop's poll, inside the call
    if which in ("batch", "reactions"):  # the rows done, as a batch of those rows computes them
        assert 0 <= report["rows"] < report["n"] and report["diff"] == 0.0
    if which == "reactions":
        assert report["same"]


# --- callbacks --------------------------------------------------------------------------------


def torque_pendulum(callback):
    """The pendulum with a joint torque from a Python callable t -> (tau, 0, 0)."""
    p = simple_pendulum(L=1.0, m=1.0, theta0=0.5)
    p.builder.add_joint_torque("hinge", callback)
    return p.builder.finalize()


def raising_at(t_raise, exc):
    def torque(t):
        if t >= t_raise:
            raise exc
        return (0.1 * t, 0.1, 0.0)

    return torque


@pytest.mark.parametrize("exc_type", [KeyboardInterrupt, SystemExit, GeneratorExit])
def test_base_exceptions_from_a_callback_propagate_with_the_partial_result(exc_type):
    model = torque_pendulum(raising_at(0.5, exc_type("stop here")))
    with pytest.raises(exc_type, match="stop here") as info:
        ad.simulate(model, 2.0, output_dt=0.01)
    r = info.value.result
    assert isinstance(r, ad.SimulationResult)
    assert 0.4 <= r.t[-1] < 0.5
    # the outputs so far are those of the same run without the exception
    ref = ad.simulate(torque_pendulum(raising_at(1e9, ValueError())), 2.0, output_dt=0.01)
    n = len(r.t)
    np.testing.assert_array_equal(r.t, ref.t[:n])
    np.testing.assert_allclose(r.q, ref.q[:n], rtol=0, atol=1e-12)


def test_an_ordinary_exception_from_a_callback_is_a_solver_error_with_its_cause():
    cause = ValueError("bad torque table")
    model = torque_pendulum(raising_at(0.5, cause))
    with pytest.raises(ad.SolverError, match=r"profile callback .* raised at t=") as info:
        ad.simulate(model, 2.0, output_dt=0.01)
    assert info.value.__cause__ is cause
    assert "bad torque table" in str(info.value)
    assert 0.4 <= info.value.result.t[-1] < 0.5


def test_reentrant_simulate_from_a_callback_is_refused():
    inner = simple_pendulum().model
    calls = []

    def torque(t):
        calls.append(t)
        ad.simulate(inner, 0.1)
        return (0.0, 0.0, 0.0)

    model = torque_pendulum(torque)
    with pytest.raises(ad.SolverError, match="profile callback") as info:
        ad.simulate(model, 1.0)
    assert isinstance(info.value.__cause__, ad.ModelError)
    assert "re-entrant runs are refused" in str(info.value.__cause__)
    assert calls  # the callback ran, and simulate refused inside it
    # the guard is released: the same thread simulates again
    r = ad.simulate(inner, 0.1)
    assert r.t[-1] == 0.1


def test_reentrant_simulate_from_a_progress_callable_is_refused():
    inner = simple_pendulum().model

    def progress(t, t_end):
        ad.simulate(inner, 0.1)

    # a run of seconds: progress is called during it (after 0.1 s), where simulate is refused
    p = simple_pendulum()
    with pytest.raises(ad.ModelError, match="re-entrant") as info:
        ad.simulate(p.model, 1e4, rtol=1e-12, atol=1e-12, output_dt=1.0, progress=progress)
    assert len(info.value.result.t) > 1


# --- progress ---------------------------------------------------------------------------------


def test_progress_callable_sees_the_simulated_time():
    p = simple_pendulum()
    seen = []
    r = ad.simulate(
        p.model,
        400.0,
        rtol=1e-12,
        atol=1e-12,
        output_dt=0.1,
        progress=lambda t, t_end: seen.append((t, t_end)),
    )
    assert r.t[-1] == 400.0
    assert seen[-1] == (400.0, 400.0)
    ts = np.array([t for t, _ in seen])
    assert all(te == 400.0 for _, te in seen)
    assert np.all(np.diff(ts) > 0) and ts[0] >= 0
    if r.stats["seconds"] > 0.25:  # updates every 0.1 s during a run that lasts (~0.35 s here)
        assert len(seen) >= 3


def test_progress_true_shows_and_closes_a_tqdm_bar(capsys):
    p = simple_pendulum()
    ad.simulate(p.model, 2.0, output_dt=0.01, progress=True)
    err = capsys.readouterr().err
    assert "simulate" in err and "100%" in err and "t=2/2 s" in err


def test_progress_tqdm_instance_is_updated_and_left_open():
    from tqdm import tqdm

    p = simple_pendulum()
    with open(os.devnull, "w") as sink:
        bar = tqdm(file=sink)
        ad.simulate(p.model, 3.0, output_dt=0.01, progress=bar)
        assert bar.total == 3.0 and bar.n == 3.0
        assert not bar.disable
        bar.close()


def test_progress_exception_propagates_as_itself_with_the_result():
    class Stop(Exception):
        pass

    def progress(t, t_end):
        if t < t_end:
            raise Stop(f"stopped at {t}")

    p = simple_pendulum()
    with pytest.raises(Stop) as info:
        ad.simulate(p.model, 1e4, rtol=1e-12, atol=1e-12, output_dt=1.0, progress=progress)
    r = info.value.result
    assert 0 < r.t[-1] < 1e4


def test_progress_of_the_wrong_type_is_refused():
    p = simple_pendulum()
    with pytest.raises(ad.ModelError, match="progress must be"):
        ad.simulate(p.model, 1.0, progress="yes")


def test_import_armdyn_does_not_import_tqdm():
    code = "import sys, armdyn; assert 'tqdm' not in sys.modules, 'tqdm imported'"
    subprocess.run([sys.executable, "-c", code], check=True)


# --- memory bound -----------------------------------------------------------------------------


def test_outputs_beyond_the_bound_are_refused_before_the_run():
    calls = []
    model = torque_pendulum(lambda t: calls.append(t) or (0.0, 0.0, 0.0))
    with pytest.raises(ad.ModelError, match=r"output_dt=1e-07 .* GiB"):
        ad.simulate(model, 1.0, output_dt=1e-7, progress=lambda t, te: calls.append(t))
    assert calls == []  # refused before the run: no step evaluated its torque, no progress


def test_output_row_bytes_is_the_size_of_a_result_row():
    # a model whose every joint has a limit: every output table's row is counted
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("a", 1.0, np.eye(3) * 1e-2, position=(0.5, 0.0, 0.0))
    b.add_body("b", 1.0, np.eye(3) * 1e-2, position=(1.5, 0.0, 0.0))
    b.add_revolute("j1", "ground", "a", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_revolute("j2", "a", "b", (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.set_joint_limits("j1", -3.0, 3.0)
    b.set_joint_limits("j2", -3.0, 3.0)
    model = b.finalize()
    r = ad.simulate(model, 0.1, output_dt=0.01)
    arrays = [
        r.t,
        r.u,
        r.v,
        r.q,
        r.qd,
        r.qdd,
        r.drive_forces,
        r.joint_torques,
        r.reaction_forces,
        r.reaction_torques,
        r.position_residual,
        r.velocity_residual,
        r.kinetic_energy,
        r.potential_energy,
        r.gear_forces["force"],
        r.limit_forces["force"],
    ]
    assert r.limit_forces["force"].shape[1] == 2
    assert sum(a.nbytes for a in arrays) == len(r.t) * ad._core._output_row_bytes(model)


def test_the_memory_bound_is_adjustable(monkeypatch):
    p = simple_pendulum()
    row = ad._core._output_row_bytes(p.model)
    need = (1.0 / 1e-3 + 2) * row
    r = ad.simulate(p.model, 1.0, output_dt=1e-3, max_output_bytes=int(need) + 1)
    assert len(r.t) == 1001
    with pytest.raises(ad.ModelError, match=r"output_dt=0\.001"):
        ad.simulate(p.model, 1.0, output_dt=1e-3, max_output_bytes=int(need) - 1)
    with pytest.raises(ad.ModelError, match="max_output_bytes must be a positive number"):
        ad.simulate(p.model, 1.0, output_dt=1e-3, max_output_bytes=-1)
    monkeypatch.setattr(ad.simulation, "MAX_OUTPUT_BYTES", int(need) - 1)
    with pytest.raises(ad.ModelError, match="MAX_OUTPUT_BYTES"):
        ad.simulate(p.model, 1.0, output_dt=1e-3)


def test_runs_on_worker_threads_equal_the_main_thread_run():
    # off the main thread the poll takes the GIL only for a progress callable
    from concurrent.futures import ThreadPoolExecutor

    p = simple_pendulum(theta0=0.5)
    ref = ad.simulate(p.model, 5.0, output_dt=0.01)
    seen = []
    with ThreadPoolExecutor(2) as pool:
        plain = pool.submit(ad.simulate, p.model, 5.0, output_dt=0.01)
        shown = pool.submit(
            ad.simulate, p.model, 5.0, output_dt=0.01, progress=lambda t, te: seen.append(t)
        )
        for r in (plain.result(), shown.result()):
            np.testing.assert_array_equal(r.t, ref.t)
            np.testing.assert_array_equal(r.q, ref.q)
    assert seen[-1] == 5.0


URDF_CHILD = CHILD_PROLOGUE + textwrap.dedent(
    """
    inertial = (
        '<inertial><origin xyz="0 0 0.05"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
        'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
    )
    parts = ['<robot name="chain">', f'<link name="l0">{inertial}</link>']
    for i in range(1, 12001):  # a 12000-link chain: about 4 s to load here
        parts.append(f'<link name="l{i}">{inertial}</link>')
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
            f'<child link="l{i}"/><origin xyz="0 0 0.1"/><axis xyz="0 {i % 2} {1 - i % 2}"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
        )
    parts.append("</robot>")
    xml = "\\n".join(parts)
    print("ready", flush=True)
    loads = 0
    try:
        while True:  # until interrupted: a fast machine cannot finish before the signal
            ad.load_urdf(xml)
            loads += 1
    except KeyboardInterrupt:
        pass
    # the library is intact after the interrupted load
    small = ad.load_urdf(xml.split('<link name="l3">')[0] + "</robot>")
    print(json.dumps({"inside": bool(STOPPED_INSIDE), "loads": loads, "nb": small.nb}), flush=True)
    """
)


def test_sigint_stops_loading_a_large_urdf():
    """The parsing and model analysis of a large URDF check for signals as they go: the
    KeyboardInterrupt is raised inside the load, and a load after it works."""
    report = _interrupted_child(URDF_CHILD, delay=0.5)
    assert report["inside"]
    assert report["nb"] == 2  # l1 and l2 (l0 is the fixed base: ground)
