"""What-if actuators: stand-ins with the attributes of ``model.actuators`` entries, built from a
``{joint: spec}`` (a dict or an object with those attributes; catalog parts may stand for the
numbers) for a joint the model does not actuate (:func:`what_if_actuators`, the ``actuators=``
of :func:`sizing_report`) or for the gear-ratio sweep; and motors from their datasheet keywords
(:func:`make_motor`). The numbers are checked by the rules of ``ModelBuilder.add_actuator``."""

from __future__ import annotations

from types import SimpleNamespace

from armdyn import _checks, _core
from armdyn.actuators import ROTOR_COULOMB_SMOOTHING

#: armdyn.Motor's keywords: its datasheet fields (``armdyn.Motor.FIELDS``, the C++ list
#: ``MotorSpec::fields()``) and ``name``; the one list the Python side uses
MOTOR_FIELDS = (*_core.Motor.FIELDS, "name")

#: the keys of an actuator spec (add_actuator's keywords)
_ACTUATOR_FIELDS = (
    "gear_ratio",
    "rotor_inertia",
    "efficiency",
    "friction_viscous",
    "friction_coulomb",
    "friction_smoothing",
    "motor",
    "gyroscopic",
)
#: the values of a spec's optional keys when neither the spec nor the model's actuator gives them
_DEFAULTS = {
    "efficiency": 1.0,
    "friction_viscous": 0.0,
    "friction_coulomb": 0.0,
    "motor": None,
}
#: the keys the gear-ratio sweep takes from a spec (or the model's actuator): every one but the
#: ratio it sweeps and gyroscopic
_SWEPT_FIELDS = tuple(f for f in _ACTUATOR_FIELDS if f not in ("gear_ratio", "gyroscopic"))


def make_motor(**datasheet):
    """An :class:`armdyn.Motor` from datasheet keywords: :data:`MOTOR_FIELDS` (SI, motor side;
    the units in ``armdyn.Motor``'s docstring); an unknown key is a ModelError naming it."""
    unknown = sorted(set(datasheet) - set(MOTOR_FIELDS))
    if unknown:
        raise _core.ModelError(f"motor: unknown datasheet key(s) {unknown}; known {MOTOR_FIELDS}")
    return _core.Motor(**datasheet)


def what_if_actuators(model, names, actuators) -> list:
    """Stand-in actuators (the attributes of ``model.actuators`` entries) from
    ``{joint: spec}``: ``gear_ratio`` and ``rotor_inertia`` required (``rotor_inertia``: else
    the motor's datasheet value), ``efficiency`` (1),
    ``friction_viscous``, ``friction_coulomb`` (0), ``friction_smoothing`` (None: 1e-3 |N|)
    and ``motor`` (an :class:`armdyn.Motor`, a dict of its keywords, a catalog row, or None)
    optional; a dict or an object with those attributes. Catalog parts may stand for the
    numbers: ``gearbox`` (a :class:`armdyn.sizing.catalog.Gearbox` or a row of
    ``catalog.gearboxes``) gives ``gear_ratio`` (its ``ratio``) and ``efficiency``, and the
    rotor inertia is then the motor's ``rotor_inertia`` plus the gearbox's ``input_inertia``;
    a value the spec gives wins."""
    own = {str(a.joint) for a in (getattr(model, "actuators", None) or [])}
    dofs = list(model.dof_names)
    out = []
    for joint, spec in actuators.items():
        joint = str(joint)
        if joint in own:
            raise _core.ModelError(
                f"actuators: joint {joint!r} already has an actuator in the model; size it with "
                "the model's own, or sweep it with gear_ratio_sweep"
            )
        if joint not in names or joint not in dofs:
            raise _core.ModelError(f"actuators: {joint!r} is not a joint coordinate ({dofs})")

        allowed = (*_ACTUATOR_FIELDS, "gearbox")
        unknown = sorted(set(spec) - set(allowed)) if isinstance(spec, dict) else []
        if unknown:
            raise _core.ModelError(f"actuators: [{joint}] unknown key(s) {unknown}")
        motor = _spec_motor(joint, spec)
        gearbox = spec.get("gearbox") if isinstance(spec, dict) else getattr(spec, "gearbox", None)

        def get(key, default=None, spec=spec, motor=motor, gearbox=gearbox):
            if isinstance(spec, dict):
                value = spec.get(key)
            else:
                value = getattr(spec, key, None)
            if value is None:
                value = _from_parts(key, motor, gearbox)
            return default if value is None else value

        for key in ("gear_ratio", "rotor_inertia"):
            if get(key) is None:
                raise _core.ModelError(
                    f"actuators: [{joint}] needs {key}"
                    + (" (in the spec or its motor's datasheet)" if key == "rotor_inertia" else "")
                )
        if get("gyroscopic", False):
            raise _core.ModelError(
                f"actuators: [{joint}] gyroscopic rotors need the actuator in the model "
                "(ModelBuilder.add_actuator); the what-if evaluation is the gear-reduced model"
            )
        out.append(
            SimpleNamespace(
                joint=joint,
                rotor_joint=None,
                dof=dofs.index(joint),
                **_actuator_numbers(f"actuators: [{joint}]", get),
                motor=motor,
                gyroscopic=False,
            )
        )
    return out


def _spec_motor(joint: str, spec):
    """The spec's motor: an armdyn.Motor, None, a dict of Motor keywords (make_motor: an unknown
    key is an error), or a catalog row (a pandas Series or other mapping: Motor.from_row, its
    other columns ignored)."""
    motor = spec.get("motor") if isinstance(spec, dict) else getattr(spec, "motor", None)
    if isinstance(motor, dict):
        return make_motor(**motor)
    if motor is not None and not isinstance(motor, _core.Motor) and hasattr(motor, "keys"):
        return _core.Motor.from_row(motor)
    return motor


def _part_value(part, key: str):
    """A part's value: an attribute (a catalog Gearbox) or an entry (a row, a mapping); None
    when it has none or it is NaN."""
    value = part.get(key) if hasattr(part, "keys") else getattr(part, key, None)
    if value is None or (isinstance(value, float) and value != value):
        return None
    return value


def _from_parts(key: str, motor, gearbox):
    """What the spec's parts give for an actuator key it leaves out: a gearbox (a catalog
    Gearbox or row) its ``ratio`` and ``efficiency``; the rotor inertia is the motor's
    ``rotor_inertia`` plus the gearbox's ``input_inertia`` (the gearbox's alone needs the
    motor's: None without it)."""
    if gearbox is not None and key in ("gear_ratio", "efficiency"):
        return _part_value(gearbox, "ratio" if key == "gear_ratio" else "efficiency")
    if key == "rotor_inertia" and motor is not None:
        j = getattr(motor, "rotor_inertia", None)
        if j is not None and gearbox is not None:
            j += _part_value(gearbox, "input_inertia") or 0.0
        return j
    return None


def _actuator_numbers(who: str, get) -> dict:
    """The numeric actuator keys of a what-if spec, checked by the rules of
    ``ModelBuilder.add_actuator`` (a ModelError naming the key and what it allows)."""
    gear_ratio = _checks.number(who, "gear_ratio", get("gear_ratio"))
    if gear_ratio == 0.0:
        raise _core.ModelError(f"{who}: gear_ratio must be a finite nonzero number, got 0")
    return dict(
        gear_ratio=gear_ratio,
        rotor_inertia=_checks.number(who, "rotor_inertia", get("rotor_inertia"), lo=0.0),
        efficiency=_checks.number(
            who,
            "efficiency",
            get("efficiency", _DEFAULTS["efficiency"]),
            lo=0.0,
            lo_open=True,
            hi=1.0,
        ),
        friction_viscous=_checks.number(
            who, "friction_viscous", get("friction_viscous", _DEFAULTS["friction_viscous"]), lo=0.0
        ),
        friction_coulomb=_checks.number(
            who, "friction_coulomb", get("friction_coulomb", _DEFAULTS["friction_coulomb"]), lo=0.0
        ),
        friction_smoothing=_checks.number(
            who, "friction_smoothing", get("friction_smoothing"), none=True
        ),
    )


def _swept_actuator(joint: str, spec, existing) -> SimpleNamespace:
    """The stand-in actuator the gear-ratio sweep evaluates on ``joint`` (its ``gear_ratio``
    set per ratio): each value of :data:`_SWEPT_FIELDS` from ``spec`` (a dict, an object with
    those attributes, or None), else from the model's own actuator ``existing``, else the
    default (``rotor_inertia``: else the motor's datasheet value). An inherited default Coulomb
    smoothing (add_actuator's 1e-3 |N₀|) becomes None, so that at ratio N it is 1e-3 |N|."""
    if isinstance(spec, dict):
        unknown = sorted(set(spec) - set(_ACTUATOR_FIELDS))
        if unknown:
            raise _core.ModelError(f"gear_ratio_sweep: [{joint}] unknown key(s) {unknown}")
        if spec.get("gyroscopic", False):
            raise _core.ModelError(
                f"gear_ratio_sweep: [{joint}] the closed-form sweep is the gear-reduced model "
                "(gyroscopic=False)"
            )
    values = {}
    for name in _SWEPT_FIELDS:
        if isinstance(spec, dict):
            value = spec.get(name, getattr(existing, name, _DEFAULTS.get(name)))
        elif spec is not None:
            value = getattr(spec, name, getattr(existing, name, _DEFAULTS.get(name)))
        else:
            value = getattr(existing, name, _DEFAULTS.get(name))
        if (
            name == "friction_smoothing"
            and value is not None
            and existing is not None
            and not (isinstance(spec, dict) and name in spec)
            and abs(value - ROTOR_COULOMB_SMOOTHING * abs(existing.gear_ratio))
            <= 1e-15 * abs(value)
        ):
            value = None  # add_actuator's default 1e-3 |N0|: at ratio N it is 1e-3 |N|
        if name == "motor" and isinstance(value, dict):
            value = make_motor(**value)
        values[name] = value
    if values["rotor_inertia"] is None:  # the motor's datasheet value
        values["rotor_inertia"] = getattr(values["motor"], "rotor_inertia", None)
    if values["rotor_inertia"] is None:
        raise _core.ModelError(
            f"gear_ratio_sweep: joint {joint!r} needs a rotor_inertia (in the spec or its "
            "motor's datasheet)"
        )
    return SimpleNamespace(joint=joint, gear_ratio=1.0, **values)
