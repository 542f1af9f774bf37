"""Fuzzing of a Model's pickled state bytes (the bytes a Dask worker or a cache receives).

Each mutated state is loaded in a child interpreter under a memory limit (RLIMIT_AS) and a
timeout, as ``pickle.loads`` loads it (``Model.__setstate__``). A mutant must either raise
``armdyn.ModelError`` or load as a model that then works: forward dynamics (joint-space
models), a short simulation and a pickle round trip that gives back the same bytes. A signal
(segmentation fault, abort), a timeout, or any other exception type is a failure.

The mutations do not parse the format (they work on any version of it): they find the 64-bit
integers that look like counts or indices (small values) and the 8-byte doubles of plausible
magnitude by scanning the bytes, and mutate those (+-1, extreme values, NaN, inf, 1e308), flip
and set bytes, truncate, extend, insert, delete, duplicate and swap segments, and change the
header's format version. Many mutants run in one child; a child that dies has its culprit
named by running the suspect alone.

As a script it measures a build (the issue's before/after counts)::

    PYTHONPATH=$PWD/python python tests/model/model_bytes_fuzz.py --per-model 2000
"""

from __future__ import annotations

import argparse
import collections
import functools
import os
import pickle
import random
import resource
import signal
import struct
import subprocess
import sys
import zlib
from pathlib import Path

MEMORY_LIMIT = 3 << 30  # address space of a child [bytes]: numpy and armdyn need ~1 GiB
BATCH = 150  # mutants per child
BATCH_TIMEOUT = 120.0  # [s] a whole batch (a loaded machine); a lone mutant gets SINGLE_TIMEOUT
SINGLE_TIMEOUT = 30.0
ROOT = Path(__file__).resolve().parents[2]

# ---------------------------------------------------------------------------------------------
# models: every element of the format


def _inertia(m, a, b, c):
    import numpy as np

    return np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / 12.0


def builder_model():
    """Closed loops (a slider-crank closed by an inline joint and a four-bar closed by a distance
    joint), a gear pair with backlash, an ideal gear, a coupling, actuators (one with a motor
    datasheet, one gyroscopic), drives (one on a cylindrical joint's displacement), a PI motor,
    torque input, springs, friction, a profiled body force, spherical, universal and
    cylindrical joints, frames and limits."""
    import armdyn as ad
    from armdyn import profiles

    b = ad.ModelBuilder()
    box = _inertia
    # a two-link arm on y axes with actuators, limits, motor, spring and friction
    b.add_body("link1", 2.0, box(2.0, 0.05, 0.05, 0.5), (0.0, 0.0, 0.25))
    b.add_revolute("j1", "ground", "link1", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_body("link2", 1.0, box(1.0, 0.04, 0.04, 0.5), (0.0, 0.0, 0.75))
    b.add_revolute("j2", "link1", "link2", (0.0, 0.0, 0.5), (0.0, 1.0, 0.0))
    b.set_joint_limits("j2", -1.0, 1.0, 20.0, 3.0)
    motor = ad.Motor(
        name="m1",
        torque_constant=0.05,
        resistance=0.4,
        voltage=48.0,
        rotor_inertia=1e-5,
        thermal_resistance_winding=0.9,
        max_winding_temperature=155.0,
        brake_torque=0.5,
    )
    b.add_actuator("j1", 50.0, 1e-5, efficiency=0.9, friction_viscous=1e-4, motor=motor)
    b.add_actuator("j2", 30.0, 1e-5, gyroscopic=True, friction_coulomb=1e-3)
    b.add_motor("j2", profiles.cubic(0.0, 0.2, 0.0, 0.1), 50.0, 2.0, 20.0, ki=5.0)
    b.add_joint_spring_damper("j1", 1.0, 0.1, 0.05)
    b.add_joint_friction("j1", 0.01, 0.02)
    b.add_body_force("link1", force=(0.0, 0.0, -1.0), profile=profiles.quintic(0, 1, 0, 0.1))
    b.add_body_force("link2", torque=(0.0, 0.1, 0.0))
    b.add_spring_damper("tether", "ground", (0.3, 0.0, 1.0), "link2", (0.0, 0.0, 1.0), 10.0, 0.1)
    b.add_frame("tool", "link2", (0.0, 0.0, 1.0), (0.0, 1.0, 0.0, 0.0))
    b.add_frame("mark", "ground", (1.0, 1.0, 0.0))
    # gears on ground: a pair with backlash, an ideal gear, a torque input
    for k, name in enumerate(("wa", "wb", "wc")):
        x = 2.0 + 0.2 * k
        b.add_body(name, 0.5, box(0.5, 0.2, 0.2, 0.02), (x, 0.0, 0.0))
        b.add_revolute("r" + name, "ground", name, (x, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_gear_pair("mesh", "rwa", "rwb", 0.1, 0.1, backlash=1e-3, stiffness=1e4)
    b.add_gear("ideal", "rwb", "rwc", 0.1, 0.1)
    b.add_joint_torque("rwa", profiles.sine(0.1, 2.0, 0.0, 0.0))
    # coupled sliders; the leader driven by a spline
    b.add_body("s1", 1.0, box(1.0, 0.1, 0.1, 0.1), (0.0, 2.0, 0.0))
    b.add_prismatic("p1", "ground", "s1", (0.0, 2.0, 0.0), (1.0, 0.0, 0.0))
    b.add_body("s2", 1.0, box(1.0, 0.1, 0.1, 0.1), (0.0, 2.5, 0.0))
    b.add_prismatic("p2", "ground", "s2", (0.0, 2.5, 0.0), (1.0, 0.0, 0.0))
    b.add_coupling("c21", "p2", "p1", 0.5, 0.01)
    b.add_drive("p1", profiles.spline([0.0, 0.1, 0.2], [0.0, 0.01, 0.0]), name="slide")
    # slider-crank in the x-z plane at y = -1, closed by an inline joint
    y = -1.0
    b.add_body("crank", 1.0, box(1.0, 0.2, 0.05, 0.05), (0.1, y, 0.0))
    b.add_revolute("crank_pin", "ground", "crank", (0.0, y, 0.0), (0.0, 1.0, 0.0))
    b.add_body("rod", 1.0, box(1.0, 0.6, 0.05, 0.05), (0.5, y, 0.0))
    b.add_revolute("rod_pin", "crank", "rod", (0.2, y, 0.0), (0.0, 1.0, 0.0))
    b.add_body("piston", 1.0, box(1.0, 0.1, 0.1, 0.1), (0.8, y, 0.0))
    b.add_prismatic("bore", "ground", "piston", (0.8, y, 0.0), (1.0, 0.0, 0.0))
    b.add_inline("wrist_pin", "piston", "rod", (0.8, y, 0.0), (0.0, 1.0, 0.0))
    # a four-bar closed by a distance joint (a rod with ball ends)
    y = -2.0
    b.add_body("input", 1.0, box(1.0, 0.05, 0.05, 0.3), (0.0, y, 0.15))
    b.add_revolute("in_pin", "ground", "input", (0.0, y, 0.0), (0.0, 1.0, 0.0))
    b.add_body("output", 1.0, box(1.0, 0.05, 0.05, 0.4), (0.5, y, 0.2))
    b.add_revolute("out_pin", "ground", "output", (0.5, y, 0.0), (0.0, 1.0, 0.0))
    b.add_distance("coupler", "input", (0.0, y, 0.3), "output", (0.5, y, 0.4))
    # a spherical pendulum, a universal joint and a cylindrical joint driven along its axis
    b.add_body("ball", 1.0, box(1.0, 0.1, 0.1, 0.1), (3.0, -1.0, -0.5))
    b.add_spherical("socket", "ground", "ball", (3.0, -1.0, 0.0))
    b.add_body("cross", 1.0, box(1.0, 0.1, 0.1, 0.1), (4.0, -1.0, -0.5))
    b.add_universal("cardan", "ground", "cross", (4.0, -1.0, 0.0), (1, 0, 0), (0, 1, 0))
    b.add_body("sleeve", 1.0, box(1.0, 0.1, 0.1, 0.3), (5.0, -1.0, 0.0))
    b.add_cylindrical("shaft", "ground", "sleeve", (5.0, -1.0, 0.0), (0.0, 0.0, 1.0))
    b.add_drive("shaft", profiles.constant(0.0), coord=1)
    b.add_joint_spring_damper("shaft", 2.0, 0.1, 0.0, coord=0)
    return b.finalize()


def floating_model():
    """A floating base (free joint) carrying two revolute links, a prismatic one, a fixed
    sensor, limits, frames and a spring: a joint-space model."""
    import armdyn as ad

    b = ad.ModelBuilder()
    box = _inertia
    b.add_body("base", 5.0, box(5.0, 0.4, 0.3, 0.2), (0.0, 0.0, 1.0), (0.9, 0.1, 0.3, 0.3))
    b.add_free("float", "base")
    b.add_body("thigh", 1.0, box(1.0, 0.05, 0.05, 0.4), (0.2, 0.0, 0.8))
    b.add_revolute("hip", "base", "thigh", (0.2, 0.0, 1.0), (0.0, 1.0, 0.0))
    b.add_body("shin", 0.8, box(0.8, 0.04, 0.04, 0.4), (0.2, 0.0, 0.4))
    b.add_revolute("knee", "thigh", "shin", (0.2, 0.0, 0.6), (0.0, 1.0, 0.0))
    b.set_joint_limits("knee", -2.0, 0.5, 30.0, 8.0)
    b.add_body("foot", 0.3, box(0.3, 0.1, 0.05, 0.03), (0.2, 0.0, 0.15))
    b.add_prismatic("ankle", "shin", "foot", (0.2, 0.0, 0.2), (0.0, 0.0, 1.0))
    b.add_body("imu", 0.05, box(0.05, 0.02, 0.02, 0.01), (0.0, 0.1, 1.1))
    b.add_fixed("imu_mount", "base", "imu", (0.0, 0.1, 1.1))
    b.add_joint_spring_damper("ankle", 500.0, 5.0, 0.0)
    b.add_frame("sole", "foot", (0.2, 0.0, 0.1))
    b.add_actuator("hip", 100.0, 3e-5)
    return b.finalize()


def ur5_model():
    """The UR5 of example-robot-data (tests/data/urdf/arm6.urdf when it is not installed)."""
    import armdyn as ad

    sys.path.insert(0, str(ROOT))
    from benchmarks import common

    path = common.robot_urdf("ur5") or ROOT / "tests" / "data" / "urdf" / "arm6.urdf"
    return ad.load_urdf(str(path))


MODELS = {"builder": builder_model, "floating": floating_model, "ur5": ur5_model}


@functools.cache
def model_state(name: str) -> bytes:
    """The state bytes of model `name` (Model.__getstate__()[0])."""
    return bytes(MODELS[name]().__getstate__()[0])


# ---------------------------------------------------------------------------------------------
# mutations

INT_EXTREMES = (0, -1, -2, 2**31 - 1, 2**31, 2**32, 2**62, 2**63 - 1, -(2**63), 2**40)
FLOATS = (
    float("nan"),
    float("inf"),
    float("-inf"),
    1e308,
    -1e308,
    5e-324,
    0.0,
    -0.0,
)


def _candidates(data: bytes):
    """Offsets of 64-bit integers that look like counts or indices (-1 .. 2**20, the first of
    a run of zero bytes), and of 8-byte doubles of plausible magnitude."""
    ints, floats = [], []
    for i in range(len(data) - 7):
        (v,) = struct.unpack_from("<q", data, i)
        if -1 <= v <= 1 << 20 and (v != 0 or i == 0 or data[i - 1] != 0):
            ints.append(i)
        (x,) = struct.unpack_from("<d", data, i)
        if x == x and 1e-9 <= abs(x) <= 1e9:
            floats.append(i)
    return ints, floats


def _put(data: bytes, i: int, raw: bytes) -> bytes:
    return data[:i] + raw + data[i + len(raw) :]


def _mutate_int(data, rng, ints):
    i = rng.choice(ints)
    (v,) = struct.unpack_from("<q", data, i)
    if rng.random() < 0.6:
        new = v + rng.choice((1, -1, 2, -2, 8, -8))
    else:
        new = rng.choice((*INT_EXTREMES, len(data), len(data) // 8, rng.randrange(100)))
    new = max(-(2**63), min(2**63 - 1, new))
    return f"int@{i}:{v}->{new}", _put(data, i, struct.pack("<q", new))


def _mutate_float(data, rng, floats):
    i = rng.choice(floats)
    (x,) = struct.unpack_from("<d", data, i)
    new = rng.choice((*FLOATS, -x, x * (1 + 1e-9), x * 1e6, x * 1e-6))
    return f"float@{i}:{x!r}->{new!r}", _put(data, i, struct.pack("<d", new))


def _mutate_bytes(data, rng):
    n = len(data)
    kind = rng.choice(("flip", "set", "flips"))
    out = bytearray(data)
    picks = rng.randrange(2, 9) if kind == "flips" else 1
    where = []
    for _ in range(picks):
        i = rng.randrange(n)
        where.append(i)
        out[i] = out[i] ^ (1 << rng.randrange(8)) if kind != "set" else rng.randrange(256)
    return f"{kind}@{where}", bytes(out)


def _mutate_segment(data, rng):
    n = len(data)
    kind = rng.choice(("truncate", "cut_tail", "extend", "insert", "delete", "dup", "swap"))
    if kind == "truncate":
        k = rng.randrange(n)
        return f"truncate@{k}", data[:k]
    if kind == "cut_tail":
        k = rng.randrange(1, 17)
        return f"cut_tail:{k}", data[:-k]
    if kind == "extend":
        tail = rng.choice((b"\0" * rng.randrange(1, 64), rng.randbytes(rng.randrange(1, 64))))
        return f"extend:{len(tail)}", data + tail
    i = rng.randrange(n)
    k = rng.randrange(1, 65)
    if kind == "insert":
        return f"insert@{i}:{k}", data[:i] + rng.randbytes(k) + data[i:]
    if kind == "delete":
        return f"delete@{i}:{k}", data[:i] + data[i + k :]
    if kind == "dup":
        return f"dup@{i}:{k}", data[: i + k] + data[i : i + k] + data[i + k :]
    j = rng.randrange(n)
    a, b = sorted((i, j))
    if b < a + k:  # overlapping: swap two adjacent segments
        b = a + k
    seg_a, seg_b = data[a : a + k], data[b : b + k]
    out = data[:a] + seg_b + data[a + k : b] + seg_a + data[b + len(seg_b) :]
    return f"swap@{a},{b}:{k}", out


def mutants(data: bytes, seed: int, count: int):
    """`count` mutants of `data` as (label, bytes), reproducible from `seed`. Mutation kinds:
    counts and indices (+-1, extremes), floats (NaN, inf, 1e308, ...), bytes (flips, sets),
    segments (truncation, extension, insertion, deletion, duplication, swap), the header's
    format version, and a few of two mutations at once."""
    rng = random.Random(seed)
    ints, floats = _candidates(data)
    out = []
    while len(out) < count:
        r = rng.random()
        if r < 0.35:
            label, new = _mutate_int(data, rng, ints)
        elif r < 0.55:
            label, new = _mutate_float(data, rng, floats)
        elif r < 0.72:
            label, new = _mutate_bytes(data, rng)
        elif r < 0.92:
            label, new = _mutate_segment(data, rng)
        elif r < 0.94:
            v = rng.choice((0, 2, 3, 255, 2**32 - 1))
            label, new = f"version:{v}", _put(data, 8, struct.pack("<I", v))
        else:
            la, new = _mutate_int(data, rng, ints)
            lb, new = _mutate_float(new, rng, floats)
            label = la + "+" + lb
        if new != data:
            out.append((label, new))
    return out


# ---------------------------------------------------------------------------------------------
# the child: load and use each mutant, one result line each


def _exercise(ad, np, model, data):
    """Use a loaded model: a pickle round trip (the same bytes; bytes of an older format
    version that load are written in the current one, which then round-trips), forward
    dynamics (joint-space models), two RK4 steps of a simulation."""
    import pickle as pk

    again = pk.loads(pk.dumps(model))
    stored = bytes(again.__getstate__()[0])
    if (
        stored[8:12] != data[8:12]
        and struct.unpack_from("<I", data, 8)[0] < struct.unpack_from("<I", stored, 8)[0]
    ):
        data = stored  # an older version, loaded and written in the current one
        again = pk.loads(pk.dumps(again))
        stored = bytes(again.__getstate__()[0])
    if stored != data:
        return "mismatch: the loaded model stores other bytes"
    if model.joint_space:
        q, qd = ad.joint_coordinates(model, model.u0, model.v0)
        try:
            qdd = ad.forward_dynamics(model, q, qd, np.zeros(model.n_dofs))
        except (ad.ModelError, ad.SolverError):
            pass
        else:
            if qdd.shape != (model.n_dofs,):
                return "bad forward_dynamics shape"
    try:
        ad.simulate(model, 2e-3, integrator="rk4", dt=1e-3, limits="ignore")
    except (ad.ModelError, ad.SolverError):
        pass
    return "ok"


def child_main():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    import armdyn as ad
    import numpy as np

    batch = pickle.load(sys.stdin.buffer)
    out = sys.stdout
    for index, data in batch:
        try:
            model = ad.Model.__new__(ad.Model)
            model.__setstate__((data,))
        except ad.ModelError:
            verdict = "refused"
        except BaseException as e:  # every other type is the finding
            verdict = f"other: {type(e).__name__}: {str(e)[:200]!r}"
        else:
            try:
                verdict = "loaded " + _exercise(ad, np, model, data)
            except BaseException as e:
                verdict = f"other: in use: {type(e).__name__}: {str(e)[:200]!r}"
        out.write(f"{index}\t{verdict}\n")
        out.flush()


# ---------------------------------------------------------------------------------------------
# the parent: batches in children, culprits of a dead child named by running them alone


def _run_child(batch, timeout):
    """(results {index: verdict}, death) of one child on `batch`; death is None, 'timeout' or
    the signal's name."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    proc = subprocess.Popen(
        [sys.executable, str(Path(__file__).resolve()), "--child"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
    )
    try:
        out, err = proc.communicate(pickle.dumps(batch), timeout=timeout)
        death = None
        if proc.returncode < 0:
            death = signal.Signals(-proc.returncode).name
        elif proc.returncode != 0:
            death = f"exit {proc.returncode}: {err.decode(errors='replace')[-300:]}"
    except subprocess.TimeoutExpired:
        proc.kill()
        out, _ = proc.communicate()
        death = "timeout"
    results = {}
    for line in out.decode(errors="replace").splitlines():
        index, _, verdict = line.partition("\t")
        results[int(index)] = verdict
    return results, death


def run_mutants(items, batch=BATCH):
    """{index: verdict} for [(index, bytes)]: 'refused', 'loaded ok', or a failure ('crash:
    SIGSEGV', 'hang', 'other: ...', 'loaded mismatch ...')."""
    verdicts = {}
    pending = list(items)
    while pending:
        chunk, pending = pending[:batch], pending[batch:]
        results, death = _run_child(chunk, BATCH_TIMEOUT)
        if death is None:
            verdicts.update(results)
            continue
        # the first mutant without a result is the suspect: run it alone
        rest = [it for it in chunk if it[0] not in results]
        if rest:
            _, alone_death = _run_child(rest[:1], SINGLE_TIMEOUT)
            if alone_death is not None:
                verdicts.update(results)
                verdicts[rest[0][0]] = _death_verdict(alone_death)
                pending = rest[1:] + pending
                continue
        # it passes alone (or the child died after its last result): bisect the batch
        verdicts.update(_bisect(chunk))
    return verdicts


def _bisect(chunk):
    """{index: verdict} of `chunk`, each child that dies split in halves down to its culprit."""
    results, death = _run_child(chunk, BATCH_TIMEOUT if len(chunk) > 1 else SINGLE_TIMEOUT)
    if death is None:
        return results
    if len(chunk) == 1:
        return {chunk[0][0]: _death_verdict(death)}
    half = len(chunk) // 2
    return {**_bisect(chunk[:half]), **_bisect(chunk[half:])}


def _death_verdict(death):
    return "hang" if death == "timeout" else f"crash: {death}"


def fuzz(name: str, part: int, count: int):
    """[(label, verdict)] of `count` mutants of model `name`, seed fixed by (name, part)."""
    data = model_state(name)
    seed = zlib.crc32(f"{name}:{part}".encode())
    items = mutants(data, seed, count)
    verdicts = run_mutants([(k, new) for k, (_, new) in enumerate(items)])
    return [(items[k][0], verdicts[k]) for k in range(len(items))]


def is_failure(verdict: str) -> bool:
    return verdict not in ("refused", "loaded ok")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--models", default=",".join(MODELS), help="comma-separated model names")
    ap.add_argument("--per-model", type=int, default=2000, help="mutants per model")
    ap.add_argument("--parts", type=int, default=2, help="seeds per model (split evenly)")
    args = ap.parse_args()
    if args.child:
        child_main()
        return
    total = collections.Counter()
    for name in args.models.split(","):
        counts = collections.Counter()
        for part in range(args.parts):
            for label, verdict in fuzz(name, part, args.per_model // args.parts):
                kind = verdict.split(":")[0].split(" ")[0] if is_failure(verdict) else verdict
                counts[kind] += 1
                if is_failure(verdict):
                    print(f"  {name}[{part}] {label}: {verdict}")
        print(f"{name}: {len(model_state(name))} bytes, {dict(counts)}")
        total.update(counts)
    n = sum(total.values())
    fails = sum(v for k, v in total.items() if is_failure(k))
    print(f"total: {n} mutants, {fails} failures: {dict(total)}")


if __name__ == "__main__":
    main()
