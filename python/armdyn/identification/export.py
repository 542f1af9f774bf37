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
from xml.sax.saxutils import unescape as xml_unescape

import numpy as np

from armdyn import _core

__all__ = ["with_parameters", "write_urdf"]

_BODY = 10  # parameters per body
_COORD = 4  # parameters per joint coordinate
_NOTE = "armdyn:"  # the comments write_urdf adds start with it (replaced on a second export)


def _checked_pi(model, pi, fn: str) -> tuple[np.ndarray, list[str]]:
    """pi as a finite float vector of the model's length, or a ModelError naming the culprit."""
    if not isinstance(model, _core.Model):
        raise _core.ModelError(f"{fn}: model must be an armdyn.Model, got {type(model).__name__}")
    names = _core.dynamic_parameter_names(model)
    try:
        p = np.array(pi, dtype=float)
    except (TypeError, ValueError) as e:
        raise _core.ModelError(f"{fn}: pi must be an array of numbers ({e})") from None
    if p.shape != (len(names),):
        raise _core.ModelError(
            f"{fn}: pi must have shape ({len(names)},) (dynamic_parameter_names(model)), "
            f"got {p.shape}"
        )
    bad = np.flatnonzero(~np.isfinite(p))
    if bad.size:
        i = int(bad[0])
        raise _core.ModelError(f"{fn}: pi[{i}] ('{names[i]}') must be finite, got {p[i]}")
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
      the model's. A body without a frame of its name (a builder's model: its parameter frame
      was its body frame) gets one at its old body frame, so that the new model's parameters
      are about the same frames as ``pi``;
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
    that violate the triangle inequality). Either way ``m >= 0``, a
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
        raise _core.ModelError(f"{fn}: physical_inertia must be True or False")
    if urdf is not None:
        try:
            write_urdf(urdf, model, p)
        except (_core.ModelError, _core.UrdfError) as e:
            raise type(e)(f"{fn}: urdf: {e}") from None
    return _core.model_with_dynamic_parameters(model, p, bool(physical_inertia))


# ----------------------------------------------------------------------------------- URDF ---


def _urdf_text(urdf, fn: str) -> str:
    """The URDF's XML: a path (str or os.PathLike) to a regular file of at most
    armdyn._core.URDF_MAX_BYTES bytes, or the XML itself (str, UTF-8 bytes), as load_urdf."""
    limit = _core.URDF_MAX_BYTES
    if isinstance(urdf, bytes):
        try:
            urdf = urdf.decode("utf-8")
        except UnicodeDecodeError as e:
            raise _core.UrdfError(f"{fn}: urdf bytes are not UTF-8 ({e})") from None
    if isinstance(urdf, os.PathLike) or (
        isinstance(urdf, str) and not urdf.lstrip("\ufeff \t\r\n").startswith("<")
    ):
        path = Path(urdf)
        try:
            if not path.is_file():
                raise OSError("not a regular file")
            if path.stat().st_size > limit:
                raise OSError(f"larger than armdyn._core.URDF_MAX_BYTES = {limit} bytes")
            return path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError, ValueError) as e:
            raise _core.UrdfError(f"{fn}: cannot read the URDF file '{path}': {e}") from None
    if not isinstance(urdf, str):
        raise _core.UrdfError(
            f"{fn}: urdf must be a path or the XML text (str or bytes), got {type(urdf).__name__}"
        )
    if len(urdf) > limit:
        raise _core.UrdfError(f"{fn}: the URDF text is longer than {limit} characters")
    return urdf


_TOKEN = re.compile(
    r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<![A-Za-z][^>]*>"
    r"|<(?P<close>/?)(?P<tag>[A-Za-z_][\w:.\-]*)(?P<attrs>(?:[^>\"']|\"[^\"]*\"|'[^']*')*?)"
    r"(?P<empty>/?)>",
    re.S,
)
_ATTR = re.compile(r"([A-Za-z_][\w:.\-]*)\s*=\s*(\"[^\"]*\"|'[^']*')")


class _Node:
    """An element's place in the text: [start, end), its start tag [start, open_end), its
    end tag [close, end) (close == end for an empty element <x/>), its attributes (escaped as
    written) with their value spans, its child elements and comments."""

    def __init__(self, tag: str, start: int, open_end: int, attrs: str, attrs_at: int) -> None:
        self.tag, self.start, self.open_end = tag, start, open_end
        self.close = self.end = open_end
        self.attrs: dict[str, tuple[str, int, int]] = {}
        for m in _ATTR.finditer(attrs):
            v0, v1 = attrs_at + m.start(2) + 1, attrs_at + m.end(2) - 1
            self.attrs[m.group(1)] = (xml_unescape(m.group(2)[1:-1], {"&quot;": '"'}), v0, v1)
        self.children: list[_Node] = []
        self.comments: list[tuple[int, int, str]] = []

    def get(self, name: str, default: str | None = None) -> str | None:
        return self.attrs[name][0] if name in self.attrs else default

    def find(self, tag: str) -> _Node | None:
        return next((c for c in self.children if c.tag == tag), None)


def _scan(text: str, fn: str) -> _Node:
    """The <robot> element of the URDF as _Nodes (positions in text), after xml.etree checked
    that the text is well-formed."""
    try:
        ET.fromstring(text)
    except ET.ParseError as e:
        raise _core.UrdfError(f"{fn}: the URDF is not well-formed XML: {e}") from None
    stack: list[_Node] = []
    root = None
    for m in _TOKEN.finditer(text):
        if m.group("tag") is None:
            if stack and m.group(0).startswith("<!--"):
                stack[-1].comments.append((m.start(), m.end(), m.group(0)[4:-3]))
            continue
        if m.group("close"):
            node = stack.pop()
            node.close, node.end = m.start(), m.end()
            continue
        node = _Node(m.group("tag"), m.start(), m.end(), m.group("attrs"), m.start("attrs"))
        if stack:
            stack[-1].children.append(node)
        elif root is None:
            root = node
        if not m.group("empty"):
            stack.append(node)
    if root is None or root.tag != "robot":
        tag = root.tag if root is not None else "none"
        raise _core.UrdfError(f"{fn}: the URDF's root element is <{tag}>, not <robot>")
    return root


def _num(x: float) -> str:
    """A float written to round-trip exactly (shortest repr)."""
    return repr(float(x) + 0.0)  # + 0.0: no "-0.0"


def _line_indent(text: str, pos: int) -> str:
    """The whitespace between the line's start and pos ("" when other text precedes pos)."""
    line = text.rfind("\n", 0, pos) + 1
    lead = text[line:pos]
    return lead if not lead.strip() else ""


def _child_indent(text: str, node: _Node) -> str:
    """The indentation of node's children (its first child's, else node's own + 2 spaces)."""
    if node.children:
        return _line_indent(text, node.children[0].start)
    return _line_indent(text, node.start) + "  "


def _cut(text: str, start: int, end: int) -> tuple[int, int]:
    """[start, end) widened to its whole line(s) when nothing else is on them."""
    line = text.rfind("\n", 0, start) + 1
    stop = text.find("\n", end)
    stop = len(text) if stop < 0 else stop
    if not text[line:start].strip() and not text[end:stop].strip():
        return line, min(stop + 1, len(text))
    return start, end


def _inertial_of(p10: np.ndarray, body: str, fn: str) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about it), all in the parameter (link) frame."""
    m, h = float(p10[0]), np.asarray(p10[1:4], dtype=float)
    i_o = np.array([[p10[4], p10[5], p10[7]], [p10[5], p10[6], p10[8]], [p10[7], p10[8], p10[9]]])
    if m < 0.0:
        raise _core.ModelError(f"{fn}: body '{body}': mass ('{body}.m') must be >= 0, got {m}")
    if m == 0.0:
        if np.any(h != 0.0):
            raise _core.ModelError(
                f"{fn}: body '{body}': zero mass with a nonzero first moment {h}: no centre of "
                "mass (not physically consistent)"
            )
        return m, np.zeros(3), i_o
    c = h / m
    return m, c, i_o - m * (c @ c * np.eye(3) - np.outer(c, c))


def _inertial_xml(
    m: float, c: np.ndarray, inertia: np.ndarray, indent: str, inner: str, notes=()
) -> str:
    """An <inertial> element, its first line unindented, its children at inner (the comments
    `notes` first), its end tag at indent."""
    keys = {
        "ixx": (0, 0),
        "ixy": (0, 1),
        "ixz": (0, 2),
        "iyy": (1, 1),
        "iyz": (1, 2),
        "izz": (2, 2),
    }
    moments = " ".join(f'{k}="{_num(inertia[ij])}"' for k, ij in keys.items())
    xyz = " ".join(_num(v) for v in c)
    kept = "".join(f"\n{inner}{note}" for note in notes)
    return (
        f'<inertial>{kept}\n{inner}<origin xyz="{xyz}" rpy="0 0 0"/>'
        f'\n{inner}<mass value="{_num(m)}"/>\n{inner}<inertia {moments}/>\n{indent}</inertial>'
    )


Edit = tuple[int, int, str]  # replace text[start:end] by the string


def _insert_first(text: str, node: _Node, xml: str) -> list[Edit]:
    """Edits that put xml (one line, unindented) as node's first child."""
    indent = _child_indent(text, node)
    if node.close == node.end and text[node.open_end - 2] == "/":  # <x .../>: open it
        own = _line_indent(text, node.start)
        head = text[node.start : node.open_end - 2].rstrip()
        return [(node.start, node.end, f"{head}>\n{indent}{xml}\n{own}</{node.tag}>")]
    return [(node.open_end, node.open_end, f"\n{indent}{xml}")]


def _insert_last(text: str, node: _Node, xml: str) -> list[Edit]:
    """Edits that put xml (one line) as node's last child (node not empty: a joint)."""
    indent = _child_indent(text, node)
    if node.close == node.end:
        return _insert_first(text, node, xml)
    last = max([c.end for c in node.children] + [e for _, e, _ in node.comments] + [node.open_end])
    return [(last, last, f"\n{indent}{xml}")]


def _set_attrs(text: str, node: _Node, values: dict[str, str]) -> list[Edit]:
    """Edits that set node's attributes (in place when present, appended otherwise)."""
    edits: list[Edit] = []
    new = []
    for k, v in values.items():
        if k in node.attrs:
            _, v0, v1 = node.attrs[k]
            edits.append((v0, v1, v))
        else:
            new.append(f' {k}="{v}"')
    if new:
        at = node.open_end - (2 if text[node.open_end - 2] == "/" else 1)
        while text[at - 1].isspace():
            at -= 1
        edits.append((at, at, "".join(new)))
    return edits


def _note(text: str) -> str:
    """An XML comment (a "--" inside a name would end it early: spaced out)."""
    return f"<!-- {_NOTE} {text.replace('--', '- -')} -->"


def _drop_notes(text: str, joints: dict[str, _Node]) -> list[Edit]:
    """Edits removing the joints' rotor-inertia comments of an earlier write_urdf (a new export
    writes them again; a merged link's comment stays, its <inertial> being gone)."""
    return [
        (*_cut(text, a, b), "")
        for joint in joints.values()
        for a, b, body in joint.comments
        if body.strip().startswith(_NOTE)
    ]


def _mimic_sources(joints: dict[str, _Node], coords: list[str]) -> dict[str, tuple[str, float]]:
    """Per URDF joint with a coordinate: (the independent coordinate it drives, its scale)."""
    out: dict[str, tuple[str, float]] = {}
    for name in joints:
        j, scale, seen = name, 1.0, set()
        while j not in coords and j in joints and j not in seen:
            mimic = joints[j].find("mimic")
            if mimic is None:
                break
            seen.add(j)
            try:
                scale *= float(mimic.get("multiplier", "1"))
            except ValueError:
                break
            j = mimic.get("joint", "")
        if j in coords:
            out[name] = (j, scale)
    return out


def _dynamics_value(joint: _Node, attr: str) -> float:
    dyn = joint.find("dynamics")
    try:
        return float(dyn.get(attr, "0")) if dyn is not None else 0.0
    except ValueError:
        return 0.0


def _friction_edits(text, joints, sources, coord: str, fv: float, fc: float) -> list[Edit]:
    """Edits scaling the <dynamics> of coord's joints (its own, its mimic followers') to fv, fc
    (load_urdf reflects a follower's friction with its multiplier's square, resp. modulus)."""
    mine = [(name, s) for name, (c, s) in sources.items() if c == coord]
    values: dict[str, dict[str, str]] = {}
    for attr, target, power in (("damping", fv, 2), ("friction", fc, 1)):
        total = sum(abs(s) ** power * _dynamics_value(joints[n], attr) for n, s in mine)
        for name, _ in mine:
            if total > 0.0:
                new = target * (_dynamics_value(joints[name], attr) / total)  # 1 source: exact
            elif name == coord:
                new = target
            else:
                continue
            dyn = joints[name].find("dynamics")
            if new != 0.0 or (dyn is not None and attr in dyn.attrs):
                values.setdefault(name, {})[attr] = _num(new)
    edits: list[Edit] = []
    for name, attrs in values.items():
        dyn = joints[name].find("dynamics")
        if dyn is not None:
            edits += _set_attrs(text, dyn, attrs)
        else:
            fields = " ".join(f'{k}="{v}"' for k, v in attrs.items())
            edits += _insert_last(text, joints[name], f"<dynamics {fields}/>")
    return edits


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
    else is kept byte for byte: ``xml.etree`` checks that the document is well-formed, and
    the changes are spliced into the original text (the replaced ``<inertial>`` elements, the
    ``damping``/``friction`` attribute values, the added elements and comments indented as
    their neighbours); comments, attribute quoting, namespaces and layout elsewhere are
    untouched. Comments from an earlier export (``armdyn: ...``) are replaced, so exporting
    again gives the same text.

    ``path``: also written there (UTF-8). Returns the text. Raises ModelError naming the
    culprit on a ``pi`` of the wrong shape, a non-finite entry, a negative mass, friction or
    ``Ia``, a zero mass with a first moment; ModelError naming the link or joint when the URDF
    does not have one of the model's bodies or joint coordinates; UrdfError on a file that
    cannot be read or is not a URDF.
    """
    fn = "write_urdf"
    p, names = _checked_pi(model, pi, fn)
    text = _urdf_text(urdf, fn)
    root = _scan(text, fn)
    links = {el.get("name"): el for el in root.children if el.tag == "link"}
    joints = {el.get("name"): el for el in root.children if el.tag == "joint"}
    n_bodies = sum(n.endswith(".m") for n in names)  # only a body's mass entry ends so
    bodies = [names[_BODY * i][: -len(".m")] for i in range(n_bodies)]
    coords = [n[: -len(".fv")] for n in names[_BODY * n_bodies :: _COORD]]  # no floating base
    for b in bodies:
        if b not in links:
            raise _core.ModelError(f"{fn}: the URDF has no link '{b}' (a body of the model)")
    for c in coords:
        if c not in joints:
            raise _core.ModelError(
                f"{fn}: the URDF has no joint '{c}' (a joint coordinate of the model)"
            )
    n_body = _BODY * n_bodies
    _check_friction(p, names, n_body, fn)
    inertials = [_inertial_of(p[_BODY * i : _BODY * (i + 1)], b, fn) for i, b in enumerate(bodies)]
    edits = _drop_notes(text, joints)
    for b, (m, c, inertia) in zip(bodies, inertials, strict=True):
        old = links[b].find("inertial")
        if old is not None:
            own = _line_indent(text, old.start)
            notes = [text[a:b] for a, b, _ in old.comments]  # the old one's comments kept
            xml = _inertial_xml(m, c, inertia, own, _child_indent(text, old), notes)
            edits.append((old.start, old.end, xml))
        else:
            indent = _child_indent(text, links[b])
            xml = _inertial_xml(m, c, inertia, indent, indent + "  ")
            edits += _insert_first(text, links[b], xml)
    edits += _merged_edits(text, model, links, set(bodies))
    sources = _mimic_sources(joints, coords)
    for k, c in enumerate(coords):
        o = n_body + _COORD * k
        edits += _friction_edits(text, joints, sources, c, p[o], p[o + 1])
        if p[o + 3] != 0.0:
            note = _note(
                f"rotor inertia Ia = {_num(p[o + 3])} kg m^2 (reflected to the joint; no URDF "
                "element: armdyn.identification.with_parameters adds it as an actuator)"
            )
            edits += _insert_first(text, joints[c], note)
    out = _apply(text, edits)
    if path is not None:
        Path(path).write_text(out, encoding="utf-8")
    return out


def _check_friction(p: np.ndarray, names: list[str], start: int, fn: str) -> None:
    for i in range(start, p.size):
        if names[i].rsplit(".", 1)[1] in ("fv", "fc", "Ia") and p[i] < 0.0:
            raise _core.ModelError(f"{fn}: '{names[i]}' must be >= 0, got {p[i]}")


def _merged_edits(text: str, model, links: dict[str, _Node], bodies: set[str]) -> list[Edit]:
    """Edits dropping the <inertial> of the links merged into a body through fixed joints (a
    comment in its place)."""
    edits: list[Edit] = []
    for name in model.frame_names:
        link = links.get(name)
        if link is None or name in bodies:
            continue
        body = model.frame(name)["body"]
        inertial = link.find("inertial")
        if body not in bodies or inertial is None:
            continue
        note = _note(
            f"inertial merged into link '{body}' (one armdyn body through fixed joints; the "
            "identified parameters are there)"
        )
        a, b = _cut(text, inertial.start, inertial.end)
        whole = a != inertial.start
        edits.append((a, b, f"{_line_indent(text, inertial.start)}{note}\n" if whole else note))
    return edits


def _apply(text: str, edits: list[Edit]) -> str:
    """text with the edits (non-overlapping) applied."""
    out, at = [], 0
    for a, b, new in sorted(edits, key=lambda e: (e[0], e[1])):
        if a < at:
            raise RuntimeError(f"write_urdf: overlapping edits at {a}")  # a bug, not an input
        out += [text[at:a], new]
        at = b
    out.append(text[at:])
    return "".join(out)
