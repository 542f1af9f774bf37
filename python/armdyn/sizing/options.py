"""The options of the drivetrain checks, declared once (:class:`SizingOptions`): the ambient
temperature, the required life, the brake's safety factor, the emergency stops over the life
and the copper's resistance law. :func:`armdyn.select_drivetrain`, :func:`armdyn.sizing_report`
and the ``armdyn size`` / ``armdyn select`` commands take them (``options=`` or keywords), with
these defaults."""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from armdyn import _checks


@dataclass(frozen=True)
class SizingOptions:
    """Options of the drivetrain checks (SI units, temperatures in °C).

    Attributes:
        ambient_temperature: the air around the motor [°C] (the thermal model's ambient node).
        required_life: the service life the gearbox and its output bearing must reach [h].
        brake_safety_factor: the holding brake must hold this many times the largest gravity
            torque along the cycle (SEW recommends at least 2).
        emergency_stops: emergency stops expected over the required life (each a momentary
            peak of the gearbox, checked against its allowed count).
        bearing_load_factor: the output bearing's load factor f_w (1 to 1.2 smooth running,
            1.2 to 1.5 normal, 1.5 to 3 with impacts: Harmonic Drive's tables).
        copper_temperature_coefficient: the winding resistance's rise [1/K] (copper: 0.00393);
            0 keeps the datasheet resistance at every temperature.
        resistance_temperature: the temperature at which the datasheet gives the resistance
            [°C].
    """

    ambient_temperature: float = 40.0
    required_life: float = 20000.0
    brake_safety_factor: float = 2.0
    emergency_stops: float = 1000.0
    bearing_load_factor: float = 1.5
    copper_temperature_coefficient: float = 0.00393
    resistance_temperature: float = 25.0

    def __post_init__(self) -> None:
        who = "SizingOptions"
        _checks.number(who, "ambient_temperature", self.ambient_temperature, lo=-273.15)
        for name in ("required_life", "brake_safety_factor", "bearing_load_factor"):
            _checks.number(who, name, getattr(self, name), lo=0.0, lo_open=True)
        _checks.number(who, "emergency_stops", self.emergency_stops, lo=0.0)
        _checks.number(
            who, "copper_temperature_coefficient", self.copper_temperature_coefficient, lo=0.0
        )
        _checks.number(who, "resistance_temperature", self.resistance_temperature, lo=-273.15)


#: the option names, in declaration order
OPTION_NAMES: tuple[str, ...] = tuple(f.name for f in fields(SizingOptions))


def sizing_options(options: SizingOptions | None = None, **overrides: Any) -> SizingOptions:
    """``options`` (default :class:`SizingOptions`) with ``overrides`` applied; an unknown name
    is a ModelError naming it and the known ones."""
    unknown = sorted(set(overrides) - set(OPTION_NAMES))
    if unknown:
        from armdyn import _core

        raise _core.ModelError(
            f"sizing options: unknown option(s) {unknown} (known: {list(OPTION_NAMES)})"
        )
    base = options if options is not None else SizingOptions()
    if not isinstance(base, SizingOptions):
        from armdyn import _core

        raise _core.ModelError(
            f"sizing options: options must be a SizingOptions, got {type(base).__name__}"
        )
    return replace(base, **overrides)
