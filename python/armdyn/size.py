"""The ``armdyn size`` command's former module: its names are :mod:`armdyn.sizing.cli`'s
(``from armdyn.size import read_actuators`` keeps working)."""

from armdyn.sizing import cli as _cli


def __getattr__(name: str):
    return getattr(_cli, name)
