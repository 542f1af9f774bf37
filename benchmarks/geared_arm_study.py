"""The first paper's study on armdyn.papers.geared_arm.geared_arm_6dof (armdyn.papers.geared_study):
5 s runs with 1–4 motors on the waist's driven gear, 0.1 mm backlash, without and with anti-backlash
preload, plus the backlash-free arm. Writes docs/figures/geared_arm_torque.png (in the style of the
paper's Fig. 3 a–d) and benchmarks/results/geared_arm_study.json, and prints the table of
docs/geared_arm.md. `armdyn reproduce` runs the same study into its report folder.

    python -m benchmarks.geared_arm_study        (from the repository root)
"""

from __future__ import annotations

from armdyn.papers import geared_study

from benchmarks.common import RESULTS, ROOT


def main():
    rows = geared_study.run_study(
        ROOT / "docs" / "figures" / "geared_arm_torque.png",
        RESULTS / "geared_arm_study.json",
        command="python -m benchmarks.geared_arm_study",
    )
    print(geared_study.table(rows))


if __name__ == "__main__":
    main()
