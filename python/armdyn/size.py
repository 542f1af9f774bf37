"""The old path of :mod:`armdyn.sizing.cli` (the ``armdyn size`` command), kept so that
existing imports work (``from armdyn.size import read_actuators``): every name is looked up
there. The sizing lives in the package :mod:`armdyn.sizing`."""

from armdyn.sizing import cli as _cli


def __getattr__(name: str):
    return getattr(_cli, name)


def __dir__() -> list[str]:
    return dir(_cli)
