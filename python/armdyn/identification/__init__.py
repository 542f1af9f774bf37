"""Identification: bring a model to a measured robot.

The dynamics are linear in the model's dynamic parameters, ``tau = Y(q, qd, qdd) @ pi``
(:func:`armdyn.joint_torque_regressor`, :func:`armdyn.dynamic_parameters`,
:func:`armdyn.dynamic_parameter_names`), and so is the energy, ``E = h(q, qd) @ pi``
(:func:`armdyn.energy_regressor`: identification from energy needs no accelerations). From
there: the identifiable (base) combinations of pi, an excitation motion that makes them well
conditioned, logged motions read and differentiated, least-squares and physically consistent
estimates with their uncertainties, a validation on other data, and the identified model written
back as a URDF and an armdyn model.
"""

from armdyn import _core
from armdyn.identification.base import BaseParameters, base_parameters
from armdyn.identification.estimate import Identification, identify
from armdyn.identification.excitation import (
    Excitation,
    fourier_excitation,
    fourier_series,
    random_fourier,
)
from armdyn.identification.export import with_parameters, write_urdf
from armdyn.identification.log import MotionLog, differentiate, load_log, log_from_arrays
from armdyn.identification.physical import is_physical, physical_violations, pseudo_inertia
from armdyn.identification.report import write_report
from armdyn.identification.validate import Validation, validate

dynamic_parameter_names = _core.dynamic_parameter_names
dynamic_parameters = _core.dynamic_parameters
energy_regressor = _core.energy_regressor
joint_torque_regressor = _core.joint_torque_regressor

__all__ = [
    "BaseParameters",
    "Excitation",
    "Identification",
    "MotionLog",
    "Validation",
    "base_parameters",
    "differentiate",
    "dynamic_parameter_names",
    "dynamic_parameters",
    "energy_regressor",
    "fourier_excitation",
    "fourier_series",
    "identify",
    "is_physical",
    "joint_torque_regressor",
    "load_log",
    "log_from_arrays",
    "physical_violations",
    "pseudo_inertia",
    "random_fourier",
    "validate",
    "with_parameters",
    "write_report",
    "write_urdf",
]
