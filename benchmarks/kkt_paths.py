"""Dense Schur Cholesky against the block elimination at small sizes: forward dynamics per call
on random spatial chains of n revolute links (5 rows each), `model.with_kkt_path("dense")`
against the path finalize() picks, in the C++ timing loop. This measurement is why no model
is put on the dense path for being small (block_sparse.hpp).

    python benchmarks/kkt_paths.py
"""

from __future__ import annotations

import numpy as np
from armdyn import _core, scenes


def per_call(model, n, count=20000):
    fd = _core.JointSpaceForwardDynamics(model)
    q = np.linspace(0.1, 0.5, n)
    return float(np.median([_core._time_forward_loop(fd, q, q, q, count) for _ in range(5)]))


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
