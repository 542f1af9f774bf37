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

# (the compiled module as a leaf: `from armdyn._core import ...` would read as an import of the
# armdyn package, a cycle with armdyn's own import of this package; tests/docs/test_layout.py)
from armdyn import _core

dynamic_parameter_names = _core.dynamic_parameter_names
dynamic_parameters = _core.dynamic_parameters
energy_regressor = _core.energy_regressor
joint_torque_regressor = _core.joint_torque_regressor

__all__ = [
    "dynamic_parameter_names",
    "dynamic_parameters",
    "energy_regressor",
    "joint_torque_regressor",
]
