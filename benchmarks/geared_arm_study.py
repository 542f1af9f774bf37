"""The first paper's study on armdyn.scenes.geared_arm_6dof (armdyn.geared_study): 5 s runs
with 1–4 motors on the waist's driven gear, 0.1 mm backlash, without and with anti-backlash
preload, plus the backlash-free arm. Writes docs/figures/geared_arm_torque.png (in the style of
the paper's Fig. 3 a–d) and docs/results/geared_arm_study.json, and prints the table of
docs/geared_arm.md. `armdyn reproduce` runs the same study into its report folder.

    python benchmarks/geared_arm_study.py
"""

from __future__ import annotations

from pathlib import Path

from armdyn import geared_study

ROOT = Path(__file__).resolve().parents[1]


def main():
    rows = geared_study.run_study(
        ROOT / "docs" / "figures" / "geared_arm_torque.png",
        ROOT / "docs" / "results" / "geared_arm_study.json",
        command="python benchmarks/geared_arm_study.py",
    )
    print(geared_study.table(rows))


if __name__ == "__main__":
    main()
