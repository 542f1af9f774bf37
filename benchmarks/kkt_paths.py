"""Dense Schur Cholesky against the block elimination at small sizes: forward dynamics per state
on random spatial chains of n revolute links (5 rows each), `model.with_kkt_path("dense")`
against the path finalize() picks, through the public
``armdyn.forward_dynamics(..., method="cartesian")`` on a batch of states (one C++ loop). This
measurement is why no model is put on the dense path for being small (block_sparse.hpp).

    python benchmarks/kkt_paths.py
"""

from __future__ import annotations

import time

import armdyn as ad
import numpy as np
from armdyn import scenes


def per_call(model, n, count=20000):
    """Median seconds per state of forward dynamics on the KKT path, over 5 batches."""
    q = np.tile(np.linspace(0.1, 0.5, n), (count, 1))
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        ad.forward_dynamics(model, q, q, q, method="cartesian")
        times.append((time.perf_counter() - t0) / count)
    return float(np.median(times))


def main():
    print("| links | rows | dense [µs] | block [µs] | block / dense |")
    print("|---|---|---|---|---|")
    for n in (3, 4, 5, 6, 7, 8, 10, 12, 16):
        model = scenes.random_chain(n)
        dense = per_call(model.with_kkt_path("dense"), n)
        block = per_call(model, n)
        print(f"| {n} | {model.nc} | {1e6 * dense:.2f} | {1e6 * block:.2f} | {block / dense:.2f} |")


if __name__ == "__main__":
    main()
