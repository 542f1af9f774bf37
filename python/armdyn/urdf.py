"""URDF loading: :func:`load_urdf` reads a URDF file or XML text through urdfdom into a finalized
Model, and remembers where each model came from; :func:`urdf_source` tells it (the viewer,
:func:`armdyn.animate`, asks it for the links' ``<visual>`` geometry)."""

from __future__ import annotations

import os
import warnings
import weakref

import numpy.typing as npt

from armdyn import _checks, _core

#: the URDF of each model load_urdf made: its file's absolute path or its XML text (weak: the
#: registry never keeps a model alive)
_SOURCES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def urdf_source(model: _core.Model) -> str | None:
    """The URDF ``model`` was loaded from by :func:`load_urdf`: the file's absolute path, or the
    XML text when it was loaded from text; None for a model made otherwise (a
    :class:`armdyn.ModelBuilder`, a copy or an unpickled model)."""
    return _SOURCES.get(model)


def _remember(model: _core.Model, source: str) -> None:
    """Record the URDF ``source`` (a path, made absolute, or the XML text) of ``model``."""
    if source.lstrip("\ufeff").lstrip().startswith("<"):
        _SOURCES[model] = source
    else:
        _SOURCES[model] = os.path.abspath(source)


def _loader_text(path_or_xml) -> str:
    """The text handed to the C++ loader: a str (XML or path), an os.PathLike, or bytes holding
    UTF-8 XML; anything else is a TypeError."""
    if isinstance(path_or_xml, (bytes, bytearray, memoryview)):
        data = bytes(path_or_xml)
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as err:
            raise _core.UrdfError(
                f"URDF bytes are not valid UTF-8 (byte offset {err.start}); pass XML as UTF-8 "
                "bytes or str, or a path as str"
            ) from None
        if not text.lstrip("\ufeff").lstrip().startswith("<"):
            raise _core.UrdfError(
                f"URDF bytes must hold XML (starting with '<'), got {data[:40]!r}"
                + ("..." if len(data) > 40 else "")
                + "; pass a path as str or os.PathLike"
            )
        return text
    if isinstance(path_or_xml, str):
        try:
            path_or_xml.encode("utf-8")
        except UnicodeEncodeError as err:
            raise _core.UrdfError(
                f"load_urdf: path_or_xml holds a lone surrogate {path_or_xml[err.start]!r} at "
                f"index {err.start}: not valid Unicode text (decode bytes with "
                "errors='strict', or pass the XML as UTF-8 bytes)"
            ) from None
        return path_or_xml
    if isinstance(path_or_xml, os.PathLike):
        path = os.fspath(path_or_xml)
        return path if isinstance(path, str) else _loader_text(path)
    raise TypeError(
        "load_urdf: expected a path (str or os.PathLike) or URDF XML (str or bytes), got "
        f"{type(path_or_xml).__name__}"
    )


def load_urdf(
    path_or_xml: str | bytes | os.PathLike[str],
    fixed_base: bool = True,
    gravity: npt.ArrayLike = (0.0, 0.0, -9.81),
    *,
    physical_inertia: bool = True,
    mimic: bool = True,
) -> _core.Model:
    """Load a URDF file (or XML string) through urdfdom into a finalized Model.

    Links joined by fixed joints are merged into one body; joint-space arrays follow the URDF's
    document order of its moving joints. With ``fixed_base`` the root link is welded to ground.
    Massless links (no ``<inertial>``, e.g. the "virtual" links between the joints of a 3-DOF
    hip) are massless bodies, accepted wherever every joint motion still carries inertia.

    With ``mimic`` (default), each ``<mimic joint= multiplier= offset=>`` becomes a coupling
    ``q = multiplier * q_joint + offset`` (:meth:`ModelBuilder.add_coupling`, named after the
    mimicking joint): the joint-space functions then take the independent coordinates
    (``model.coord_names``, followers removed), as Pinocchio's ``mimic=True`` models do, while
    simulation results report every joint (``model.joint_coord_names``). ``mimic=False`` gives
    every mimicking joint its own coordinate (Pinocchio's default).

    ``<dynamics damping friction>`` becomes joint friction (viscous, and Coulomb smoothed with
    ``armdyn._core.URDF_COULOMB_SMOOTHING``); ``<limit>`` gives ``model.coord_lower`` /
    ``coord_upper`` / ``coord_effort_limit`` / ``coord_velocity_limit``. See docs/urdf.md.

    ``path_or_xml``: a path (str or os.PathLike) to a regular file of at most
    ``armdyn._core.URDF_MAX_BYTES`` bytes, or the XML itself as str or UTF-8 bytes.

    A URDF with no moving joint loaded with ``fixed_base=True`` is a zero-DOF model (a structure
    that only carries loads): it loads with a ``UserWarning`` suggesting ``fixed_base=False``
    for a robot meant to move freely.

    Args:
        physical_inertia: True (default) refuses a link inertia that is not positive
            semi-definite or violates the triangle inequality, listing every such link with its
            principal moments. False accepts any positive semi-definite tensor (published or
            identified parameter sets, point masses); negative round-off moments down to
            -1e-12 of the largest are clamped to zero with a warning.

    Raises:
        UrdfError: missing or irregular file, malformed XML, bad numbers or names, unsupported
            joint type, invalid inertial data (the message names the element and attribute).
        TypeError: ``path_or_xml`` is neither str, bytes nor os.PathLike.
        ModelError: ``fixed_base``, ``physical_inertia`` or ``mimic`` not a bool, ``gravity``
            not three finite real numbers (naming the argument).
        ModelError: a joint whose motion carries no inertia (a massless leaf link, a point mass
            on its own joint axis), naming the joint and the body; a mass, inertia or distance
            beyond finalize()'s scale bounds (docs/api.md), naming the body or joint.
    """
    source = _loader_text(path_or_xml)
    model = _core.urdf_builder(
        source,
        _checks.flag("load_urdf", "fixed_base", fixed_base),
        _checks.array("load_urdf", "gravity", gravity, ndim=1, finite=True),
        physical_inertia=_checks.flag("load_urdf", "physical_inertia", physical_inertia),
        mimic=_checks.flag("load_urdf", "mimic", mimic),
    ).finalize()
    if model.nb == 0:
        warnings.warn(
            "armdyn: the URDF has no moving joint: with fixed_base=True it loads as a model with "
            "no degrees of freedom (nb = 0, n_coords = 0); pass fixed_base=False if the robot "
            "is meant to move freely",
            UserWarning,
            stacklevel=2,
        )
    _remember(model, source)
    return model
