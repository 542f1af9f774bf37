"""Ready-made models: small classic mechanisms used by the figures, tests and examples.

The papers' arms moved to :mod:`armdyn.papers` (``armdyn.papers.five_dof.five_dof_arm`` /
``three_dof_arm``, ``armdyn.papers.geared_arm.geared_arm_6dof``); ``armdyn.scenes.five_dof_arm``,
``three_dof_arm`` and ``geared_arm_6dof`` still find them, imported on first use (``import
armdyn`` does not import the papers)."""

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
from armdyn.scenes.machines import delta_robot, palletizer, pick_and_place

__all__ = [
    "bricard",
    "delta_robot",
    "double_pendulum",
    "four_bar",
    "free_body",
    "heavy_top",
    "mass_ratio_chain",
    "nan_force_pendulum",
    "palletizer",
    "pick_and_place",
    "random_chain",
    "simple_pendulum",
    "slider_crank",
    "slider_driven_to_dead_centre",
    "spring_mass_pendulum",
]


def __getattr__(name: str):
    """The papers' arms at their old paths (a re-export, on first use)."""
    if name in ("five_dof_arm", "three_dof_arm"):
        from armdyn.papers import five_dof

        return getattr(five_dof, name)
    if name == "geared_arm_6dof":
        from armdyn.papers.geared_arm import geared_arm_6dof

        return geared_arm_6dof
    if name in ("paper", "geared_arm"):  # the old submodules (re-exporting shims)
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
