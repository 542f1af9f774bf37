"""The identified parameters back into models: an armdyn model and a URDF.

:func:`with_parameters` makes a new :class:`armdyn.Model` whose
:func:`armdyn.dynamic_parameters` equal a parameter vector ``pi``; :func:`write_urdf` writes
the URDF the model came from with ``pi``'s inertials and joint friction.

``pi`` is :func:`armdyn.dynamic_parameters`'s vector (names
:func:`armdyn.dynamic_parameter_names`): per body ``m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz,
Izz`` about its parameter frame (a URDF link's frame), then per joint coordinate ``fv, fc,
offset, Ia``. The offsets are measurement biases (a torque sensor's or a current's), not
dynamics: both functions ignore them.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

import armdyn
from armdyn import _core

__all__ = ["with_parameters", "write_urdf"]

_BODY = 10  # parameters per body
_COORD = 4  # parameters per joint coordinate
_NOTE = "armdyn:"  # the comments write_urdf adds start with it (replaced on a second export)


def _checked_pi(model, pi, fn: str) -> tuple[np.ndarray, list[str]]:
    """pi as a finite float vector of the model's length, or a ModelError naming the culprit."""
    if not isinstance(model, _core.Model):
        raise armdyn.ModelError(f"{fn}: model must be an armdyn.Model, got {type(model).__name__}")
    names = armdyn.dynamic_parameter_names(model)
    try:
        p = np.array(pi, dtype=float)
    except (TypeError, ValueError) as e:
        raise armdyn.ModelError(f"{fn}: pi must be an array of numbers ({e})") from None
    if p.shape != (len(names),):
        raise armdyn.ModelError(
            f"{fn}: pi must have shape ({len(names)},) (dynamic_parameter_names(model)), "
            f"got {p.shape}"
        )
    bad = np.flatnonzero(~np.isfinite(p))
    if bad.size:
        i = int(bad[0])
        raise armdyn.ModelError(f"{fn}: pi[{i}] ('{names[i]}') must be finite, got {p[i]}")
    return p, names


def with_parameters(model, pi, *, urdf=None, physical_inertia: bool = True):
    """A new model (``model`` unchanged) whose dynamic parameters are ``pi``.

    ``armdyn.dynamic_parameters(new)`` equals ``pi`` (to round-off) but for the offsets, which
    are measurement biases, not dynamics (ignored: the new model's are 0), and
    ``armdyn.inverse_dynamics(new, q, qd, qdd)`` equals
    ``armdyn.joint_torque_regressor(model, q, qd, qdd) @ pi`` (offsets 0). The model is copied
    in C++ (``armdyn._core.model_with_dynamic_parameters``) and finalized again, so every
    cache that depends on the masses is made afresh:

    - each body's mass, centre of mass and inertia about it come from its 10 numbers about
      the parameter frame. An armdyn body's frame has its origin at its centre of mass, so
      the body frame moves with it (axes kept) and every point held in the body (joint
      points, named frames, ...) moves back: the geometry, frame poses and joint axes are
      the model's;
    - each joint coordinate's friction sources (its joint's, a mimic follower's, an
      actuator's motor side) are scaled to ``fv`` and ``fc`` (their smoothing kept); a
      coordinate without viscous or Coulomb friction gets it on its joint (Coulomb smoothing
      1e-3, the regressor's column for it);
    - each coordinate's actuators' rotor inertias are scaled so that their reflected inertia
      N^2 J sums to ``Ia`` (the rotor bodies' thin-disc inertias with them); a coordinate
      without actuator and ``Ia > 0`` gets one, of gear ratio 1 and rotor inertia ``Ia`` (a
      gear-reduced armature: ``tau += Ia qdd``), named ``<joint>_armature``.

    ``physical_inertia`` (the setting of :class:`armdyn.ModelBuilder` and
    :func:`armdyn.load_urdf`): True (default), each body's parameters must be physically
    consistent (its pseudo-inertia positive semidefinite: ``m >= 0`` and the inertia about the
    centre of mass positive semidefinite with the triangle inequality); False, the inertia
    about the centre of mass need only be positive semidefinite (published or identified sets
    that violate the triangle inequality, e.g. Gaz et al.'s Panda). Either way ``m >= 0``, a
    zero mass has a zero first moment and ``fv, fc, Ia >= 0``; a model cannot hold other
    values (a negative mass or a non-positive-semidefinite inertia has no dynamics to
    simulate).

    ``urdf`` (the model's URDF, path or XML text) is optional: the C++ copy adds the actuator
    an ``Ia`` on a coordinate without one needs, so no rebuild from the URDF is required. When
    given, it is checked to describe the model (every body a link, every joint coordinate a
    joint; :func:`write_urdf`'s checks), a ModelError naming the missing one otherwise.

    Raises ModelError naming the culprit (the entry of ``pi`` by
    :func:`armdyn.dynamic_parameter_names`, the body, the joint) on a ``pi`` of the wrong
    shape, a non-finite entry, values the model cannot hold (above), a model the regressor
    refuses (springs, loads, inputs, motors, gear pairs) or a ``urdf`` that does not match.
    """
    fn = "with_parameters"
    p, _ = _checked_pi(model, pi, fn)
    if not isinstance(physical_inertia, (bool, np.bool_)):
        raise armdyn.ModelError(f"{fn}: physical_inertia must be True or False")
    if urdf is not None:
        write_urdf(urdf, model, p)
    return _core.model_with_dynamic_parameters(model, p, bool(physical_inertia))


# ----------------------------------------------------------------------------------- URDF ---


def _urdf_text(urdf, fn: str) -> str:
    """The URDF's XML: a path (str or os.PathLike) to a file, or the XML itself (str, bytes)."""
    if isinstance(urdf, bytes):
        try:
            return urdf.decode("utf-8")
        except UnicodeDecodeError as e:
            raise armdyn.UrdfError(f"{fn}: urdf bytes are not UTF-8 ({e})") from None
    if isinstance(urdf, os.PathLike) or (isinstance(urdf, str) and not urdf.lstrip().startswith("<")):
        path = Path(urdf)
        try:
            return path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as e:
            raise armdyn.UrdfError(f"{fn}: cannot read the URDF file '{path}': {e}") from None
    if isinstance(urdf, str):
        return urdf
    raise armdyn.UrdfError(
        f"{fn}: urdf must be a path or the XML text (str or bytes), got {type(urdf).__name__}"
    )


def _root_span(text: str, fn: str) -> tuple[int, int]:
    """Where the <robot> element starts and ends in text (outside comments)."""
    comments = [m.span() for m in re.finditer(r"<!--.*?-->", text, re.S)]

    def outside(i: int) -> bool:
        return not any(a <= i < b for a, b in comments)

    starts = [m.start() for m in re.finditer(r"<robot[\s>/]", text) if outside(m.start())]
    ends = [m.end() for m in re.finditer(r"</robot\s*>", text) if outside(m.start())]
    if not starts:
        raise armdyn.UrdfError(f"{fn}: the URDF has no <robot> element")
    end = ends[-1] if ends else None
    if end is None:  # <robot .../> (empty) or no closing tag: the parser decides
        end = len(text.rstrip())
    return starts[0], end


def _parse(text: str, fn: str) -> ET.Element:
    """The <robot> element, comments kept, namespace prefixes registered as written."""
    try:
        for _, (prefix, uri) in ET.iterparse(_StringSource(text), events=("start-ns",)):
            if prefix:
                ET.register_namespace(prefix, uri)
        parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
        root = ET.fromstring(text, parser=parser)
    except ET.ParseError as e:
        raise armdyn.UrdfError(f"{fn}: the URDF is not well-formed XML: {e}") from None
    if root.tag != "robot":
        raise armdyn.UrdfError(f"{fn}: the URDF's root element is <{root.tag}>, not <robot>")
    return root


class _StringSource:
    """A file-like read() over a str (ET.iterparse takes a file)."""

    def __init__(self, text: str) -> None:
        self._data = text.encode("utf-8")
        self._pos = 0

    def read(self, n: int = -1) -> bytes:
        end = len(self._data) if n < 0 else self._pos + n
        chunk = self._data[self._pos : end]
        self._pos += len(chunk)
        return chunk


def _num(x: float) -> str:
    """A float written to round-trip exactly (shortest repr)."""
    return repr(float(x))


def _indent_of(el: ET.Element) -> tuple[str, str]:
    """(child indent, the element's own closing indent) from el's whitespace, or defaults."""
    inner = el.text if el.text and not el.text.strip() else "\n    "
    closing = el[-1].tail if len(el) and el[-1].tail and not el[-1].tail.strip() else "\n  "
    return inner, closing


def _inertial_of(p10: np.ndarray, body: str, fn: str) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about it), all in the parameter (link) frame."""
    m, h = float(p10[0]), np.asarray(p10[1:4], dtype=float)
    i_o = np.array([[p10[4], p10[5], p10[7]], [p10[5], p10[6], p10[8]], [p10[7], p10[8], p10[9]]])
    if m < 0.0:
        raise armdyn.ModelError(f"{fn}: body '{body}': mass ('{body}.m') must be >= 0, got {m}")
    if m == 0.0:
        if np.any(h != 0.0):
            raise armdyn.ModelError(
                f"{fn}: body '{body}': zero mass with a nonzero first moment {h}: no centre of "
                "mass (not physically consistent)"
            )
        return m, np.zeros(3), i_o
    c = h / m
    return m, c, i_o - m * (c @ c * np.eye(3) - np.outer(c, c))


def _set_inertial(link: ET.Element, m: float, c: np.ndarray, inertia: np.ndarray) -> None:
    """Replace (or add, as the first child) link's <inertial>."""
    inner, _ = _indent_of(link)
    old = link.find("inertial")
    new = ET.Element("inertial")
    new.text = inner + "  "
    origin = ET.SubElement(new, "origin", {"xyz": " ".join(_num(v) for v in c), "rpy": "0 0 0"})
    origin.tail = inner + "  "
    mass = ET.SubElement(new, "mass", {"value": _num(m)})
    mass.tail = inner + "  "
    keys = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}
    el = ET.SubElement(new, "inertia", {k: _num(inertia[ij]) for k, ij in keys.items()})
    el.tail = inner
    if old is not None:
        new.tail = old.tail
        index = list(link).index(old)
        link.remove(old)
        link.insert(index, new)
    else:
        new.tail = inner if len(link) else _indent_of(link)[1]
        if not len(link):
            link.text = inner
        link.insert(0, new)


def _add_note(el: ET.Element, text: str) -> None:
    """An XML comment as el's first child ("armdyn: ...")."""
    inner, closing = _indent_of(el)
    note = ET.Comment(f" {_NOTE} {text} ")
    note.tail = inner if len(el) else closing
    if not len(el):
        el.text = inner
    el.insert(0, note)


def _drop_notes(root: ET.Element) -> None:
    """Remove the comments an earlier write_urdf added (a second export replaces them)."""
    for parent in root.iter():
        for child in list(parent):
            if child.tag is ET.Comment and (child.text or "").strip().startswith(_NOTE):
                _remove_keeping_layout(parent, child)


def _remove_keeping_layout(parent: ET.Element, child: ET.Element) -> None:
    """Remove child, its whitespace with it (the previous sibling keeps its own tail)."""
    kids = list(parent)
    i = kids.index(child)
    if i == len(kids) - 1:  # the last child: its tail is the parent's closing indent
        if i > 0:
            kids[i - 1].tail = child.tail
        else:
            parent.text = child.tail
    parent.remove(child)


def _mimic_sources(joints: dict[str, ET.Element], coords: list[str], fn: str):
    """Per URDF joint with a coordinate: (the independent coordinate it drives, its scale)."""
    out: dict[str, tuple[str, float]] = {}
    for name in joints:
        j, scale, seen = name, 1.0, set()
        while j not in coords:
            mimic = joints[j].find("mimic") if j in joints else None
            if mimic is None or j in seen:
                break
            seen.add(j)
            scale *= float(mimic.get("multiplier", "1"))
            j = mimic.get("joint", "")
        if j in coords:
            out[name] = (j, scale)
    return out


def _set_friction(joints, sources, coord: str, fv: float, fc: float) -> None:
    """Scale the <dynamics> of coord's joints (its own and its mimic followers') to fv, fc."""
    mine = [(name, s) for name, (c, s) in sources.items() if c == coord]

    def value(name: str, attr: str) -> float:
        dyn = joints[name].find("dynamics")
        return float(dyn.get(attr, "0")) if dyn is not None else 0.0

    for attr, target, power in (("damping", fv, 2), ("friction", fc, 1)):
        total = sum(abs(s) ** power * value(n, attr) for n, s in mine)
        for name, _ in mine:
            joint = joints[name]
            dyn = joint.find("dynamics")
            if total > 0.0:
                new = value(name, attr) * (target / total)
            elif name == coord:
                new = target
            else:
                continue
            if dyn is None:
                if new == 0.0:
                    continue
                inner, closing = _indent_of(joint)
                dyn = ET.SubElement(joint, "dynamics")
                if len(joint) > 1:
                    joint[-2].tail = inner
                dyn.tail = closing
            dyn.set(attr, _num(new))


def _check_friction(p: np.ndarray, names: list[str], start: int, fn: str) -> None:
    for i in range(start, p.size):
        if names[i].rsplit(".", 1)[1] in ("fv", "fc", "Ia") and p[i] < 0.0:
            raise armdyn.ModelError(f"{fn}: '{names[i]}' must be >= 0, got {p[i]}")


def write_urdf(urdf, model, pi, path=None) -> str:
    """The URDF ``urdf`` (a path or the XML text) with ``pi``'s inertials and joint friction.

    ``model`` is the model the URDF gave (:func:`armdyn.load_urdf`, or
    :func:`armdyn.urdf_builder` + actuators); ``pi`` its parameter vector
    (:func:`armdyn.dynamic_parameter_names`). Written:

    - each body's link (the link the body is named after: its frame is the parameter frame)
      gets ``<inertial>`` with ``<origin xyz=`` the centre of mass in the link frame ``rpy="0
      0 0">``, ``<mass>`` and ``<inertia>`` about the centre of mass in the link's axes;
    - the links merged into a body through fixed joints (e.g. the UR5's ``ee_link`` and
      ``tool0`` into ``wrist_3_link``) lose their ``<inertial>`` (the merged body's parameters
      are all on its own link), with an XML comment saying so;
    - each joint coordinate's joint gets ``<dynamics damping="fv" friction="fc">`` (other
      attributes kept): a coordinate whose joints (its own, its mimic followers') carry
      friction has it scaled to ``fv``, ``fc`` (``load_urdf`` then reflects it to exactly
      ``pi``'s values), else it goes on its own joint; ``<dynamics>`` is added only where
      nonzero;
    - the rotor inertia ``Ia`` has no URDF element: it is written as an XML comment in the
      joint (``<!-- armdyn: rotor inertia Ia = ... -->``); :func:`with_parameters` adds it to
      a model as an actuator (gear ratio 1), so ``with_parameters(load_urdf(text), pi)`` is the
      whole identified model. The offsets (measurement biases) are not written.

    ``armdyn.load_urdf`` of the result gives ``dynamic_parameters`` equal to ``pi``'s body and
    friction entries (to round-off; with the options the model was loaded with). Everything
    else is kept: the document is parsed by ``xml.etree`` with its comments, and the text
    before and after ``<robot>`` (XML declaration, header comments) is copied byte for byte;
    inside ``<robot>`` the unchanged elements are re-serialized by ``xml.etree`` (the same
    elements, attributes, text and comments; quoting and empty-element spacing may differ,
    unused namespace declarations are dropped). Comments from an earlier export
    (``armdyn: ...``) are replaced.

    ``path``: also written there (UTF-8). Returns the text. Raises ModelError naming the
    culprit on a ``pi`` of the wrong shape, a non-finite entry, a negative mass, friction or
    ``Ia``, a zero mass with a first moment; ModelError naming the link or joint when the URDF
    does not have one of the model's bodies or joint coordinates; UrdfError on a file that
    cannot be read or is not a URDF.
    """
    fn = "write_urdf"
    p, names = _checked_pi(model, pi, fn)
    text = _urdf_text(urdf, fn)
    start, end = _root_span(text, fn)
    root = _parse(text, fn)
    links = {el.get("name"): el for el in root.findall("link")}
    joints = {el.get("name"): el for el in root.findall("joint")}
    n_bodies = sum(n.endswith(".m") for n in names)  # only a body's mass entry ends so
    bodies = [names[_BODY * i][: -len(".m")] for i in range(n_bodies)]
    coords = list(model.coord_names)
    for b in bodies:
        if b not in links:
            raise armdyn.ModelError(f"{fn}: the URDF has no link '{b}' (a body of the model)")
    for c in coords:
        if c not in joints:
            raise armdyn.ModelError(
                f"{fn}: the URDF has no joint '{c}' (a joint coordinate of the model)"
            )
    n_body = _BODY * len(bodies)
    _check_friction(p, names, n_body, fn)
    inertials = [_inertial_of(p[_BODY * i : _BODY * (i + 1)], b, fn) for i, b in enumerate(bodies)]
    _drop_notes(root)
    for b, (m, c, inertia) in zip(bodies, inertials):
        _set_inertial(links[b], m, c, inertia)
    _clear_merged(root, model, links, set(bodies))
    sources = _mimic_sources(joints, coords, fn)
    for k, c in enumerate(coords):
        o = n_body + _COORD * k
        _set_friction(joints, sources, c, p[o], p[o + 1])
        if p[o + 3] != 0.0:
            _add_note(
                joints[c],
                f"rotor inertia Ia = {_num(p[o + 3])} kg m^2 (reflected to the joint; no URDF "
                "element: armdyn.identification.with_parameters adds it as an actuator)",
            )
    out = text[:start] + ET.tostring(root, encoding="unicode") + text[end:]
    if path is not None:
        Path(path).write_text(out, encoding="utf-8")
    return out


def _clear_merged(root: ET.Element, model, links: dict, bodies: set[str]) -> None:
    """Drop the <inertial> of the links merged into a body through fixed joints."""
    for name in model.frame_names:
        link = links.get(name)
        if link is None or name in bodies:
            continue
        body = model.frame(name)["body"]
        inertial = link.find("inertial")
        if body not in bodies or inertial is None:
            continue
        _remove_keeping_layout(link, inertial)
        _add_note(
            link,
            f"inertial merged into link '{body}' (one armdyn body through fixed joints; the "
            "identified parameters are there)",
        )
