"""Peer models: the benchmark problems built in other libraries (Pinocchio, MuJoCo, Exudyn) to run
beside armdyn in ``python -m benchmarks.bench`` and ``python -m benchmarks.workprecision``.

Every peer imports :mod:`benchmarks.common` for its helpers; none imports the sweep
(:mod:`benchmarks.workprecision`), which calls the peers through their ``workprecision_curves``.
"""
