"""The motor's datasheet fields of issue 33 (rotor inertia, mass, two-node thermal model, winding
temperature limit, holding brake) on armdyn.Motor: one list (Motor.FIELDS = the C++
MotorSpec::fields(), armdyn.sizing.MOTOR_FIELDS) that the constructor, properties, repr, ==,
pickling and the model bytes follow; Motor.from_row; the bytes of format 2 (before these fields)
still load; hostile bytes in the new fields name the field."""

from __future__ import annotations

import inspect
import math
import pickle
import struct
from pathlib import Path

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn.sizing import MOTOR_FIELDS, make_motor, what_if_actuators
from armdyn.sizing.what_if import _swept_actuator

DATA = Path(__file__).resolve().parents[1] / "data" / "model_bytes"

OLD_FIELDS = (
    "torque_constant",
    "resistance",
    "voltage",
    "no_load_speed",
    "continuous_torque",
    "peak_torque",
    "max_speed",
    "thermal_resistance",
    "thermal_time_constant",
)
NEW_FIELDS = {
    "rotor_inertia": ("kg m^2", 3.3e-5),
    "mass": ("kg", 0.89),
    "thermal_resistance_winding": ("K/W", 0.9),
    "thermal_resistance_housing": ("K/W", 1.6),
    "thermal_time_constant_winding": ("s", 38.0),
    "thermal_time_constant_housing": ("s", 1450.0),
    "max_winding_temperature": ("degC", 155.0),
    "brake_torque": ("N m", 0.6),
}
OLD_VALUES = dict(
    zip(OLD_FIELDS, (0.05, 0.4, 48.0, 900.0, 0.3, 1.0, 1000.0, 2.0, 30.0), strict=True)
)


def full_motor(name="datasheet-motor"):
    return ad.Motor(name=name, **OLD_VALUES, **{k: v for k, (_, v) in NEW_FIELDS.items()})


def test_one_list_of_fields():
    assert ad.Motor.FIELDS == OLD_FIELDS + tuple(NEW_FIELDS)
    assert MOTOR_FIELDS == (*ad.Motor.FIELDS, "name")
    # the constructor's keywords are the list (keyword-only, each defaulting to None)
    doc = ad.Motor.__init__.__doc__.splitlines()[0]
    keywords = [
        p.split(":")[0].strip() for p in doc[doc.index("*,") + 2 : doc.rindex(")")].split(",")
    ]
    assert keywords == ["name", *ad.Motor.FIELDS]
    for f, (unit, _) in NEW_FIELDS.items():
        assert f"[{unit}]" in getattr(ad.Motor, f).__doc__
        assert f"{f} [{unit}]" in ad.Motor.__doc__ and f"{f} [{unit}]" in ad.Motor.__init__.__doc__


@pytest.mark.parametrize("field", list(NEW_FIELDS))
def test_new_field_optional_positive_and_round_trips(field):
    value = NEW_FIELDS[field][1]
    m = ad.Motor(name="x", **{field: value})
    assert getattr(m, field) == value
    assert all(getattr(m, f) is None for f in ad.Motor.FIELDS if f != field)
    assert getattr(ad.Motor(), field) is None
    assert repr(m) == f"armdyn.Motor(name='x', {field}={value!r})"
    assert eval(repr(m), {"armdyn": ad}) == m
    assert pickle.loads(pickle.dumps(m)) == m
    assert m != ad.Motor(name="x") and m != ad.Motor(name="x", **{field: 2 * value})
    assert m == make_motor(name="x", **{field: value})
    for bad in (0.0, -value):
        with pytest.raises(ad.ModelError, match=rf"Motor: {field} must be finite and > 0"):
            ad.Motor(**{field: bad})
    for bad in (math.inf, -math.inf, math.nan, "1.0"):
        with pytest.raises(ad.ModelError, match=rf"Motor: {field} must be a finite real number"):
            ad.Motor(**{field: bad})


def test_unknown_keywords():
    with pytest.raises(TypeError):
        ad.Motor(brake=1.0)
    with pytest.raises(ad.ModelError, match=r"unknown datasheet key\(s\) \['brake'\]"):
        make_motor(brake=1.0)


def _model(motor):
    b = ad.ModelBuilder()
    inertia = np.diag([0.01, 0.01, 0.002])
    b.add_body("link1", 2.0, inertia, (0.0, 0.0, 0.25))
    b.add_revolute("j1", "ground", "link1", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_body("link2", 1.0, inertia, (0.0, 0.0, 0.75))
    b.add_revolute("j2", "link1", "link2", (0.0, 0.0, 0.5), (0.0, 1.0, 0.0))
    b.add_actuator("j1", 50.0, 1e-5, efficiency=0.9, motor=motor)
    b.add_actuator("j2", 30.0, 2e-5)
    return b


def test_model_bytes_carry_every_field():
    motor = full_motor()
    b = _model(motor)
    model = b.finalize()
    again = pickle.loads(pickle.dumps(model))
    assert again.actuators[0].motor == motor and again.actuators[1].motor is None
    assert again.__getstate__() == model.__getstate__()
    assert pickle.loads(pickle.dumps(b)).finalize().actuators[0].motor == motor


def _load(data: bytes):
    model = ad.Model.__new__(ad.Model)
    model.__setstate__((data,))
    return model


def test_format_2_bytes_still_load():
    """tests/data/model_bytes/format2_*.bin: the state of `_model(Motor(name="m1",
    **OLD_VALUES))` (finalized, and its builder) written by armdyn before these fields (format
    version 2): the motor loads with them not given, the model as built today."""
    old = (DATA / "format2_model.bin").read_bytes()
    assert struct.unpack_from("<I", old, 8)[0] == 2
    model = _load(old)
    motor = model.actuators[0].motor
    assert motor == ad.Motor(name="m1", **OLD_VALUES)
    assert all(getattr(motor, f) is None for f in NEW_FIELDS)
    today = _model(ad.Motor(name="m1", **OLD_VALUES)).finalize()
    q = np.array([0.3, -0.2])
    assert np.array_equal(ad.mass_matrix(model, q), ad.mass_matrix(today, q))
    # it is written again in today's format, as today's model is
    assert model.__getstate__() == today.__getstate__()
    assert struct.unpack_from("<I", model.__getstate__()[0], 8)[0] == 4
    builder = ad.ModelBuilder.__new__(ad.ModelBuilder)
    builder.__setstate__(((DATA / "format2_draft.bin").read_bytes(), True))
    assert builder.finalize().__getstate__() == today.__getstate__()
    # other versions are refused, naming the range read
    for version in (1, 5):
        other = old[:8] + struct.pack("<I", version) + old[12:]
        with pytest.raises(ad.ModelError, match=rf"format version {version}, this armdyn reads "):
            _load(other)


def test_a_motor_pickled_before_the_new_fields_loads():
    """A Motor's pickled state is a dict of its fields: one without the new keys (as pickled
    before them) loads with them not given."""
    old_state = {"name": "m1", **OLD_VALUES}
    motor = ad.Motor.__new__(ad.Motor)
    motor.__setstate__(old_state)
    assert motor == ad.Motor(name="m1", **OLD_VALUES)
    assert set(full_motor().__getstate__()) == {"name", *ad.Motor.FIELDS}


def _motor_at(data: bytes, name: str) -> int:
    """The offset of the motor's first datasheet double (after its name) in model bytes."""
    tag = struct.pack("<q", len(name)) + name.encode()
    at = data.index(tag)
    assert data.find(tag, at + 1) == -1
    return at + len(tag)


@pytest.mark.parametrize("field", list(NEW_FIELDS))
def test_hostile_bytes_in_a_new_field_name_it(field):
    data = bytes(_model(full_motor()).finalize().__getstate__()[0])
    at = _motor_at(data, "datasheet-motor") + 8 * ad.Motor.FIELDS.index(field)
    assert struct.unpack_from("<d", data, at)[0] == NEW_FIELDS[field][1]

    def put(x):
        return data[:at] + struct.pack("<d", x) + data[at + 8 :]

    where = r"model data: actuators\[0\] on 'j1'\.motor: motor: "
    for bad in (0.0, -1.0, math.inf, -math.inf, -0.0):
        with pytest.raises(ad.ModelError, match=where + rf"{field} must be finite and > 0"):
            _load(put(bad))
    # NaN is "not given"
    assert getattr(_load(put(math.nan)).actuators[0].motor, field) is None
    with pytest.raises(ad.ModelError, match="truncated"):
        _load(data[: at + 4])
    # format-3 bytes labelled format 2: the motor's new fields are read as what follows it
    as_v2 = data[:8] + struct.pack("<I", 2) + data[12:]
    with pytest.raises(ad.ModelError, match="model data: "):
        _load(as_v2)


def test_from_row_of_a_mapping():
    values = {**OLD_VALUES, **{k: v for k, (_, v) in NEW_FIELDS.items()}}
    assert ad.Motor.from_row({"name": "datasheet-motor", **values}) == full_motor()
    # other keys ignored; None and NaN are "not given"; numpy numbers accepted
    row = {
        "peak_torque": np.float64(1.5),
        "mass": 2,
        "brake_torque": None,
        "rotor_inertia": float("nan"),
        "thermal_resistance": np.nan,
        "source": "illustrative",
        "cost": 120.0,
    }
    assert ad.Motor.from_row(row) == ad.Motor(peak_torque=1.5, mass=2.0)
    assert ad.Motor.from_row({}) == ad.Motor()


def test_from_row_of_a_pandas_series():
    frame = pd.DataFrame(
        {
            "peak_torque": [1.0, 2.0],
            "brake_torque": [0.5, np.nan],
            "max_winding_temperature": [155.0, 130.0],
            "source": ["illustrative", "datasheet"],
        },
        index=pd.Index(["M1", "M2"], name="name"),
    )
    m1 = ad.Motor.from_row(frame.loc["M1"])  # an object Series named by the index
    assert m1 == ad.Motor(
        name="M1", peak_torque=1.0, brake_torque=0.5, max_winding_temperature=155.0
    )
    m2 = ad.Motor.from_row(frame.loc["M2"])
    assert m2 == ad.Motor(name="M2", peak_torque=2.0, max_winding_temperature=130.0)
    numeric = frame.drop(columns="source")
    assert ad.Motor.from_row(numeric.loc["M2"]) == m2
    # the row's own name entry wins over the Series' name; pandas' NA is "not given"
    row = pd.Series({"name": "EC 45", "peak_torque": pd.NA, "mass": 0.3}, name="ignored")
    assert ad.Motor.from_row(row) == ad.Motor(name="EC 45", mass=0.3)
    unnamed = pd.Series({"mass": 0.3})  # name None, and a default integer name is no name
    assert ad.Motor.from_row(unnamed).name == ""
    assert ad.Motor.from_row(frame.reset_index(drop=True).iloc[0]).name == ""


def test_from_row_bad_rows_name_the_culprit():
    with pytest.raises(ad.ModelError, match=r"Motor.from_row 'M9': brake_torque must be finite"):
        ad.Motor.from_row({"name": "M9", "brake_torque": -1.0})
    with pytest.raises(ad.ModelError, match=r"Motor.from_row 'M9': mass must be finite and > 0"):
        ad.Motor.from_row(pd.Series({"mass": np.inf}, name="M9"))
    with pytest.raises(ad.ModelError, match=r"Motor.from_row: mass must be a real number"):
        ad.Motor.from_row({"mass": "heavy"})
    with pytest.raises(ad.ModelError, match=r"Motor.from_row: name must be a str"):
        ad.Motor.from_row({"name": 3})
    for not_a_row in ("mass", [1.0], 3.0, None):
        with pytest.raises(ad.ModelError, match=r"Motor.from_row: row must be a mapping"):
            ad.Motor.from_row(not_a_row)
    assert "from_row" in str(inspect.signature(ad.Motor.from_row)) or ad.Motor.from_row.__doc__


def test_what_if_actuators_take_the_new_fields():
    model = _model(None).finalize()
    names = list(model.coord_names)
    bare = ad.ModelBuilder()
    bare.add_body("a", 1.0, 0.1 * np.eye(3), (0.0, 0.0, 0.0))
    bare.add_revolute("pivot", "ground", "a", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    plain = bare.finalize()
    motor = {"name": "M", "rotor_inertia": 4e-5, "brake_torque": 0.2, "mass": 0.5}
    (a,) = what_if_actuators(plain, ["pivot"], {"pivot": {"gear_ratio": 50.0, "motor": motor}})
    assert a.rotor_inertia == 4e-5 and a.motor == ad.Motor(**motor)
    # the spec's own rotor inertia wins (it may include the gearbox's input side)
    (a,) = what_if_actuators(
        plain, ["pivot"], {"pivot": {"gear_ratio": 50.0, "rotor_inertia": 6e-5, "motor": motor}}
    )
    assert a.rotor_inertia == 6e-5
    with pytest.raises(ad.ModelError, match=r"\[pivot\] needs rotor_inertia \(in the spec or"):
        what_if_actuators(plain, ["pivot"], {"pivot": {"gear_ratio": 50.0, "motor": {"mass": 1.0}}})
    swept = _swept_actuator("pivot", {"motor": motor}, None)
    assert swept.rotor_inertia == 4e-5 and swept.motor.brake_torque == 0.2
    with pytest.raises(ad.ModelError, match="'pivot' needs a rotor_inertia"):
        _swept_actuator("pivot", {"motor": {"mass": 1.0}}, None)
    assert names == ["j1", "j2"]
