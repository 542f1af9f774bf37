"""The old path of :mod:`armdyn.papers.five_dof` (the arms of the five-DOF validation paper),
kept so that existing imports work: every name is looked up there. The papers' reproduction
lives in :mod:`armdyn.papers`, apart from the library."""

from armdyn.papers import five_dof as _papers_module


def __getattr__(name: str):
    return getattr(_papers_module, name)


def __dir__() -> list[str]:
    return dir(_papers_module)
