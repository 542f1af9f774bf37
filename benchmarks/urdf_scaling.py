"""URDF loading and ``finalize()`` against the number of links (issue 31): time and peak memory of
a long serial chain, which must grow linearly.

``python -m benchmarks.urdf_scaling [--sizes 1000 2000 ...] [--out DIR]`` writes, for each n
(default 1,000, 2,000, 5,000, 10,000 and 20,000 links), the chain URDF of :func:`chain_urdf` to a
temporary file and, in a fresh child process (so that each peak is its own):

- ``armdyn._core.urdf_builder(path, ...)``: reading, checking and parsing the XML and building
  the bodies and joints (``load``);
- ``builder.finalize()``: topology, assembly, rank analysis and the model checks (``finalize``);

each as wall-clock and CPU seconds (``time.perf_counter`` and ``time.process_time``; on a shared
machine the CPU time is the steadier figure), and the peak resident memory of the two beyond
the memory before them (``peak MiB``: Linux's ``VmHWM`` of ``/proc/self/status``, reset to
``VmRSS`` after ``import armdyn`` by writing 5 to ``/proc/self/clear_refs``). The table is
printed and written to ``benchmarks/results/urdf_scaling.json``, with the ratios of the largest
to the smallest size (linear: equal to the ratio of the sizes; quadratic: its square).

The armdyn measured is the one ``import armdyn`` finds: the installed package, or a build
given on ``PYTHONPATH``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from .common import RESULTS, machine, write_json

SIZES = (1000, 2000, 5000, 10000, 20000)
LENGTH, MASS = 0.1, 1.0  # each link: 0.1 m long, 1 kg, its centre of mass half-way along it


def chain_urdf(n: int, length: float = LENGTH, mass: float = MASS) -> str:
    """A fixed-base planar chain of ``n`` revolute joints about y along x: link ``k`` (``link<k>``,
    joint ``joint<k>``) turns about its joint at x = k * length, carries ``mass`` at x = (k + 1/2)
    * length with inertia diag(0.001, 0.002, 0.002) kg m^2; the root link ``base`` is massless.
    About 360 bytes per link (20,000 links: 7.2 MB)."""
    inertial = (
        f'<inertial><origin xyz="{length / 2} 0 0"/><mass value="{mass}"/>'
        '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial>'
    )
    parts = ['<robot name="chain">', '<link name="base"/>']
    for k in range(n):
        parent = "base" if k == 0 else f"link{k - 1}"
        x = 0.0 if k == 0 else length
        parts.append(f'<link name="link{k}">{inertial}</link>')
        parts.append(
            f'<joint name="joint{k}" type="revolute"><parent link="{parent}"/>'
            f'<child link="link{k}"/><origin xyz="{x} 0 0"/><axis xyz="0 1 0"/>'
            '<limit lower="-3" upper="3" effort="100" velocity="10"/></joint>'
        )
    parts.append("</robot>")
    return "\n".join(parts)


# the child: one load and one finalize, its own peak memory
CHILD = r"""
import json, sys, time
import armdyn
from armdyn import _core
def status(key):  # kB
    for line in open("/proc/self/status"):
        if line.startswith(key + ":"):
            return int(line.split()[1])
with open("/proc/self/clear_refs", "w") as f:  # resets VmHWM, the peak, to VmRSS
    f.write("5")
before = status("VmRSS")
w0, c0 = time.perf_counter(), time.process_time()
b = _core.urdf_builder(sys.argv[1], True, (0.0, 0.0, -9.81), physical_inertia=True, mimic=True)
w1, c1 = time.perf_counter(), time.process_time()
m = b.finalize()
w2, c2 = time.perf_counter(), time.process_time()
peak = status("VmHWM")
assert m.n_coords == int(sys.argv[2]), m.n_coords
print(json.dumps({"load_s": w1 - w0, "load_cpu_s": c1 - c0, "finalize_s": w2 - w1,
                  "finalize_cpu_s": c2 - c1, "peak_mib": (peak - before) / 1024.0,
                  "armdyn": armdyn.__file__}))
"""


def measure(n: int) -> dict:
    """One child process: load and finalize the n-link chain (see the module docstring)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"chain{n}.urdf"
        text = chain_urdf(n)
        path.write_text(text, encoding="utf-8")
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
        out = subprocess.run(
            [sys.executable, "-c", CHILD, str(path), str(n)],
            capture_output=True,
            text=True,
            env=env,
            check=False,
        )
    if out.returncode != 0:
        raise RuntimeError(f"n = {n}: the child failed:\n{out.stderr[-2000:]}")
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row["links"] = n
    row["urdf_mb"] = len(text.encode()) / 1e6
    return row


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    rows = []
    print(
        f"{'links':>7} {'MB':>5} {'load s':>8} {'(cpu)':>7} {'finalize s':>10} {'(cpu)':>7} "
        f"{'peak MiB':>9}"
    )
    for n in args.sizes:
        r = measure(n)
        rows.append(r)
        print(
            f"{n:>7} {r['urdf_mb']:>5.1f} {r['load_s']:>8.2f} {r['load_cpu_s']:>7.2f} "
            f"{r['finalize_s']:>10.2f} {r['finalize_cpu_s']:>7.2f} {r['peak_mib']:>9.1f}",
            flush=True,
        )
    first, last = rows[0], rows[-1]
    ratios = {
        "links": last["links"] / first["links"],
        **{k: last[k] / max(first[k], 1e-9) for k in ("load_cpu_s", "finalize_cpu_s", "peak_mib")},
    }
    print("largest/smallest: " + ", ".join(f"{k} x{v:.1f}" for k, v in ratios.items()))
    path = write_json(
        args.out / "urdf_scaling.json",
        {
            "command": "python -m benchmarks.urdf_scaling",
            "machine": machine(),
            "rows": rows,
            "ratios_largest_to_smallest": ratios,
        },
    )
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
