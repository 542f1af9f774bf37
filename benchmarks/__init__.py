"""armdyn's benchmark harness (not installed with the package): speed and work–precision against
peer libraries, the peer models, the reference solutions of the standard problems and the
studies behind docs/. Run from the repository root as ``python -m benchmarks.<script>``; see
benchmarks/README.md."""
