"""Identification: bring a model to a measured robot.

The dynamics are linear in the model's dynamic parameters, ``tau = Y(q, qd, qdd) @ pi``
(:func:`armdyn.joint_torque_regressor`, :func:`armdyn.dynamic_parameters`,
:func:`armdyn.dynamic_parameter_names`). From there: the identifiable (base) combinations of pi,
an excitation motion that makes them well conditioned, logged motions read and differentiated,
least-squares and physically consistent estimates with their uncertainties, a validation on
other data, and the identified model written back as a URDF and an armdyn model.
"""

from armdyn._core import dynamic_parameter_names, dynamic_parameters, joint_torque_regressor
from armdyn.identification.base import BaseParameters, base_parameters
from armdyn.identification.excitation import (
    Excitation,
    fourier_excitation,
    fourier_series,
    random_fourier,
)
from armdyn.identification.export import with_parameters, write_urdf
from armdyn.identification.log import MotionLog, differentiate, load_log, log_from_arrays

__all__ = [
    "BaseParameters",
    "Excitation",
    "MotionLog",
    "base_parameters",
    "differentiate",
    "dynamic_parameter_names",
    "dynamic_parameters",
    "fourier_excitation",
    "fourier_series",
    "joint_torque_regressor",
    "load_log",
    "log_from_arrays",
    "random_fourier",
    "with_parameters",
    "write_urdf",
]
