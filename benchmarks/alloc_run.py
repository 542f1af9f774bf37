"""Run N RK4 steps of a small tree (block elimination), a redundant scene (pivoted dense path)
or the 44-body geared arm (block elimination with gears) (see alloc_per_step.sh)."""

import sys

import armdyn as ad
from armdyn import scenes
from armdyn.papers.geared_arm import geared_arm_6dof

kind, n = sys.argv[1], int(sys.argv[2])
if kind == "sparse":
    m = geared_arm_6dof(backlash=0.0)
    ad.simulate(m, n * 1e-5, integrator="rk4", dt=1e-5, output_dt=n * 1e-5 / 10)
else:
    m = scenes.double_pendulum() if kind == "tree" else scenes.four_bar()
    ad.simulate(m, n * 1e-3, integrator="rk4", dt=1e-3, output_dt=n * 1e-3 / 10)
