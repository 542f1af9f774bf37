"""Ready-made models: small classic mechanisms used by the figures, tests and examples."""

from armdyn.scenes.basic import (
    double_pendulum,
    four_bar,
    free_body,
    simple_pendulum,
    slider_crank,
)

__all__ = ["double_pendulum", "four_bar", "free_body", "simple_pendulum", "slider_crank"]
