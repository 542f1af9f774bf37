"""Run N RK4 steps of a tree or a redundant scene (see alloc_per_step.sh)."""

import sys

import armdyn as ad
from armdyn import scenes

kind, n = sys.argv[1], int(sys.argv[2])
m = scenes.double_pendulum() if kind == "tree" else scenes.four_bar()
ad.simulate(m, n * 1e-3, integrator="rk4", dt=1e-3, output_dt=n * 1e-3 / 10)
