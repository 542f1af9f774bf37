"""The old path of :mod:`armdyn.papers.geared_study` (the six-DOF paper's geared-arm study),
kept so that existing imports work: every name is looked up there. The papers' reproduction
lives in :mod:`armdyn.papers`, apart from the library."""

from armdyn.papers import geared_study as _papers_module


def __getattr__(name: str):
    return getattr(_papers_module, name)


def __dir__() -> list[str]:
    return dir(_papers_module)
