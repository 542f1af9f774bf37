"""Ready-made models: small classic mechanisms used by the figures, tests and examples."""

from armdyn.scenes.basic import (
    double_pendulum,
    four_bar,
    free_body,
    simple_pendulum,
    slider_crank,
    slider_driven_to_dead_centre,
    spring_mass_pendulum,
)
from armdyn.scenes.extreme import (
    bricard,
    heavy_top,
    mass_ratio_chain,
    nan_force_pendulum,
    random_chain,
)
from armdyn.scenes.geared_arm import geared_arm_6dof
from armdyn.scenes.paper import five_dof_arm, three_dof_arm

__all__ = [
    "bricard",
    "double_pendulum",
    "five_dof_arm",
    "four_bar",
    "free_body",
    "geared_arm_6dof",
    "heavy_top",
    "mass_ratio_chain",
    "nan_force_pendulum",
    "random_chain",
    "simple_pendulum",
    "slider_crank",
    "slider_driven_to_dead_centre",
    "spring_mass_pendulum",
    "three_dof_arm",
]
