"""URDF loading and finalize() stay linear in the number of links (issue 31): a 20,000-link chain
loads under a memory limit, its gravity torques match the closed form, and the peak memory of a
5,000- and a 20,000-link chain grow like the links, not like their square. No wall-clock time is
asserted: ``python -m benchmarks.urdf_scaling`` measures the times."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from benchmarks.urdf_scaling import LENGTH, MASS, chain_urdf

# the child: load under an address-space limit, then the inverse dynamics at rest against the
# closed form; the peak resident memory of the load beyond the memory before it
CHILD = r"""
import json, resource, sys
limit = int(sys.argv[3])
if limit:
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
import numpy as np
import armdyn as ad
def status(key):  # kB
    for line in open("/proc/self/status"):
        if line.startswith(key + ":"):
            return int(line.split()[1])
# the peak resident memory of the load alone: Linux resets VmHWM to VmRSS on "5" in clear_refs
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
before = status("VmRSS")
m = ad.load_urdf(sys.argv[1])
peak = status("VmHWM")
n, L, mass, g = int(sys.argv[2]), float(sys.argv[4]), float(sys.argv[5]), 9.81
out = {"n_coords": m.n_coords, "nb": m.nb, "peak_mib": (peak - before) / 1024.0}
# the centres of mass at assembly: link k's at x = (k + 1/2) L on the x axis
x = np.asarray(m.u0).reshape(-1, 7)[:, :3]
ref = np.zeros_like(x)
ref[:, 0] = (np.arange(n) + 0.5) * L
out["com_err"] = float(np.abs(x - ref).max())
# at rest, straight along x under gravity -z, joint k (about y at x = k L) holds the links
# k..n-1: tau_k = -g m sum_{i>=k} ((i - k) + 1/2) L = -g m L (n - k)^2 / 2
z = np.zeros(n)
tau = np.asarray(ad.inverse_dynamics(m, z, z, z, method="joint"))
k = np.arange(n)
tau_ref = -g * mass * L * (n - k) ** 2 / 2.0
out["tau_rel_err"] = float(np.abs(tau - tau_ref).max() / np.abs(tau_ref).max())
print(json.dumps(out))
"""


def _child(tmp_path, n, limit=0):
    path = tmp_path / f"chain{n}.urdf"
    path.write_text(chain_urdf(n), encoding="utf-8")
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(path), str(n), str(limit), str(LENGTH), str(MASS)],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def chain20k(tmp_path_factory):
    # 7.2 MB of XML; before issue 31 it took 6.3 GiB (now about 200 MiB resident). The limit is
    # on the address space, which includes the interpreter, numpy and armdyn (about 110 MiB)
    return _child(tmp_path_factory.mktemp("chain"), 20000, limit=768 << 20)


def test_a_20000_link_chain_loads_under_a_768_mib_limit_with_exact_gravity_torques(chain20k):
    r = chain20k
    assert r["n_coords"] == 20000 and r["nb"] == 20000
    # measured 7e-10 m on positions up to 2,000 m (the assembly's round-off)
    assert r["com_err"] <= 1e-8
    # measured 2.6e-13 (the recursion sums 20,000 terms)
    assert r["tau_rel_err"] <= 1e-11


def test_peak_memory_of_loading_grows_like_the_links(chain20k, tmp_path):
    # each in a fresh process: the peak of the load beyond the resident memory before it
    small, large = _child(tmp_path, 5000)["peak_mib"], chain20k["peak_mib"]
    # 4x the links: linear memory gives 4x, quadratic 16x (before issue 31: 6,200 MiB against
    # 420 MiB, 15x); measured 4.0x
    assert large / small < 6.0, (small, large)
