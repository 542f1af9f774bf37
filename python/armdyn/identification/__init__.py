"""Identification: bring a model to a measured robot.

The dynamics are linear in the model's dynamic parameters, ``tau = Y(q, qd, qdd) @ pi``
(:func:`armdyn.joint_torque_regressor`, :func:`armdyn.dynamic_parameters`,
:func:`armdyn.dynamic_parameter_names`). From there: the identifiable (base) combinations of pi,
an excitation motion that makes them well conditioned, logged motions read and differentiated,
least-squares and physically consistent estimates with their uncertainties, a validation on
other data, and the identified model written back as a URDF and an armdyn model.
"""

from armdyn._core import dynamic_parameter_names, dynamic_parameters, joint_torque_regressor
from armdyn.identification.estimate import Identification, identify
from armdyn.identification.physical import is_physical, physical_violations, pseudo_inertia

__all__ = [
    "Identification",
    "dynamic_parameter_names",
    "dynamic_parameters",
    "identify",
    "is_physical",
    "joint_torque_regressor",
    "physical_violations",
    "pseudo_inertia",
]
