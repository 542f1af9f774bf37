#!/usr/bin/env bash
# Heap allocations per integration step, measured as the difference in valgrind's allocation count
# between runs of N and 2N RK4 steps with the same number of outputs.
# Usage: bash benchmarks/alloc_per_step.sh   (needs valgrind and an installed armdyn)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
py="$(python -c "import sys; print(sys.executable)")"
count() { valgrind --tool=memcheck "$py" "$here/alloc_run.py" "$1" "$2" 2>&1 |
  sed -n 's/.*total heap usage: \([0-9,]*\) allocs.*/\1/p' | tr -d ,; }
for kind in tree redundant sparse; do
  a=$(count "$kind" 1000); b=$(count "$kind" 2000)
  echo "$kind: $(( (b - a) / 1000 )) allocations per step ($a for 1000 steps, $b for 2000)"
done
