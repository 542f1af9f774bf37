"""MJCF loading: :func:`load_mjcf` reads a MuJoCo model (a file or its XML text) through the
``mujoco`` package's own parser and compiler, and maps the compiled ``MjModel`` onto
:class:`armdyn.ModelBuilder`; :func:`mjcf_info` returns what the model came from and how its
coordinates relate to MuJoCo's (``qpos``/``qvel`` -> ``q``/``qd``, the actuators' gears, what
was not mapped). Every MJCF element and what armdyn does with it: docs/mjcf.md.

The stages: :func:`_compile` (the source checked, then MuJoCo's parser and compiler),
:class:`_TreeMapper` (bodies, joints, frames), :class:`_Mapper` (equalities, actuators, the
list of what is not mapped, the info), then one ``UserWarning`` listing what was not mapped."""

from __future__ import annotations

import os
import warnings
import weakref
from dataclasses import dataclass, field

import numpy as np

from armdyn import _checks, _core

#: largest MJCF file or XML string (and file it references) load_mjcf reads [bytes]: 64 MiB
MJCF_MAX_BYTES = 64 << 20

#: most attributes one XML element may have (MuJoCo's XML parser is quadratic in them)
MJCF_MAX_ATTRIBUTES = 1000

#: how far apart (in metres, relative to the model's extent) two points a connect or weld joins
#: may be at MuJoCo's qpos0 for the loop to count as assembled there
ASSEMBLY_TOLERANCE = 1e-9

_JOINT_KINDS = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}
_EQ_KINDS = {0: "connect", 1: "weld", 2: "joint", 3: "tendon", 4: "flex"}

#: the models load_mjcf made, and their MjcfInfo (weak: the registry keeps no model alive)
_INFOS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class MjcfActuator:
    """One MuJoCo actuator as the MJCF defines it (armdyn applies no actuator force: drive the
    joint with ``ModelBuilder.add_joint_torque`` / the ``tau`` of the dynamics functions, where
    a joint actuator's force ``f`` acts as the torque ``gear * f`` on ``joint``).

    ``transmission`` is MuJoCo's (``"joint"``, ``"jointinparent"``, ``"tendon"``, ``"site"``,
    ``"slidercrank"``, ``"body"``); ``target`` the joint's armdyn name for joint transmissions
    (else the MuJoCo element's name); ``gear`` MuJoCo's 6 gear numbers (a joint uses
    ``gear[0]``); ``ctrlrange`` / ``forcerange`` the ranges (None when not limited); ``dyntype``,
    ``gaintype``, ``biastype`` MuJoCo's actuator dynamics (not simulated by armdyn)."""

    name: str
    transmission: str
    target: str
    gear: tuple[float, ...]
    ctrlrange: tuple[float, float] | None
    forcerange: tuple[float, float] | None
    dyntype: str
    gaintype: str
    biastype: str


@dataclass(frozen=True)
class MjcfInfo:
    """How an armdyn model made by :func:`load_mjcf` relates to MuJoCo's compiled model.

    ``source``: the file's absolute path, or the XML text. ``bodies``: MuJoCo body id -> the
    armdyn body (``"ground"`` for the world body and for bodies welded to it by
    ``fixed_base=True``). ``joints``: MuJoCo joint name (or ``joint<id>`` when unnamed) -> the
    armdyn joint name. ``sites`` / ``body_frames``: MuJoCo site / body name -> the armdyn frame
    name. ``actuators``: :class:`MjcfActuator` per MuJoCo actuator, in MuJoCo's order.
    ``unmapped``: every item the warning listed (what armdyn does not represent).
    ``qpos0``: MuJoCo's reference configuration (armdyn's joint coordinates are 0 there).
    Use :meth:`q_from_qpos`, :meth:`qpos_from_q`, :meth:`qd_from_qvel`, :meth:`velocity_map`
    and :meth:`qacc_from` to move states between the two."""

    source: str
    bodies: tuple[str, ...]
    joints: dict[str, str]
    sites: dict[str, str]
    body_frames: dict[str, str]
    actuators: tuple[MjcfActuator, ...]
    unmapped: tuple[str, ...]
    qpos0: np.ndarray
    nv_mujoco: int
    # per armdyn independent coordinate / dof: where it comes from in MuJoCo's qpos / qvel
    _q_src: tuple = field(repr=False, default=())
    _dof_cols: tuple = field(repr=False, default=())
    _followers: tuple = field(repr=False, default=())

    def qpos_from_q(self, q) -> np.ndarray:
        """MuJoCo's ``qpos`` at armdyn's ``q`` (the inverse of :meth:`q_from_qpos`): ``qpos0``
        where armdyn has no coordinate (a free joint welded by ``fixed_base=True``), each
        coupling follower from its leader (``multiplier * q_leader + offset``)."""
        q = np.asarray(q, dtype=float)
        qpos, k = self.qpos0.copy(), 0
        for kind, adr in self._q_src:
            if kind == "free":
                qpos[adr : adr + 7], k = q[k : k + 7], k + 7
            else:
                qpos[adr], k = self.qpos0[adr] + q[k], k + 1
        for _ in self._followers:  # enough passes for any chain of couplings
            for fol, lead, mult, offset in self._followers:
                qpos[fol] = self.qpos0[fol] + mult * (qpos[lead] - self.qpos0[lead]) + offset
        return qpos

    def q_from_qpos(self, qpos) -> np.ndarray:
        """armdyn's ``q`` (``model.coord_names``) at MuJoCo's ``qpos``: a hinge's or slide's
        ``qpos - qpos0``; a free joint's 7 entries as they are (position of the body frame in
        world, then the scalar-first quaternion: both use the same). Coupling followers (joint
        equalities) and joints welded by ``fixed_base=True`` take no entry."""
        qpos = np.asarray(qpos, dtype=float)
        out = []
        for kind, adr in self._q_src:
            if kind == "free":
                out.extend(qpos[adr : adr + 7])
            else:
                out.append(qpos[adr] - self.qpos0[adr])
        return np.array(out)

    def velocity_map(self, qpos) -> np.ndarray:
        """``T`` (nv, n_dofs) with ``qvel = T @ qd`` at ``qpos``: 1 for a hinge's or slide's own
        dof; a coupling follower's row holds its multiplier in its leader's column; a free
        joint's linear rows hold the body's rotation ``R`` (MuJoCo's free-joint linear velocity
        is in world axes, armdyn's in the body's axes; the angular ones are both in the body's
        axes). So ``M_armdyn = T.T @ M_mujoco @ T``."""
        qpos = np.asarray(qpos, dtype=float)
        t = np.zeros((self.nv_mujoco, len(self._dof_cols)))
        for col, entries in enumerate(self._dof_cols):
            for kind, row, coef, qadr in entries:
                if kind == "freelin":
                    t[row : row + 3, col : col + 3] = _quat_to_mat(qpos[qadr + 3 : qadr + 7])
                elif kind == "freeang":
                    t[row : row + 3, col : col + 3] = np.eye(3)
                elif kind == "dof":
                    t[row, col] += coef
        return t

    def qd_from_qvel(self, qpos, qvel) -> np.ndarray:
        """armdyn's ``qd`` (``model.dof_names``) at MuJoCo's ``qpos``, ``qvel`` (the
        least-squares inverse of :meth:`velocity_map`; exact when ``qvel`` satisfies the
        couplings)."""
        t = self.velocity_map(qpos)
        return np.linalg.lstsq(t, np.asarray(qvel, dtype=float), rcond=None)[0]

    def qacc_from(self, qpos, qd, qdd) -> np.ndarray:
        """MuJoCo's ``qacc`` for armdyn's ``qdd`` at ``qpos`` and armdyn's ``qd``:
        ``T qdd + Tdot qd``; the only ``Tdot`` term is a free joint's, whose linear
        acceleration in MuJoCo is ``R (a + w x v)`` for armdyn's body-axes ``v``, ``a`` and
        angular velocity ``w``."""
        qpos = np.asarray(qpos, dtype=float)
        qd = np.asarray(qd, dtype=float)
        acc = self.velocity_map(qpos) @ np.asarray(qdd, dtype=float)
        for col, entries in enumerate(self._dof_cols):
            for kind, row, _coef, qadr in entries:
                if kind == "freelin":
                    rot = _quat_to_mat(qpos[qadr + 3 : qadr + 7])
                    acc[row : row + 3] += rot @ np.cross(qd[col + 3 : col + 6], qd[col : col + 3])
        return acc


def mjcf_info(model: _core.Model) -> MjcfInfo | None:
    """The :class:`MjcfInfo` of a model :func:`load_mjcf` returned (None for any other model:
    a builder's, a copy, an unpickled one)."""
    return _INFOS.get(model)


def _quat_to_mat(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _mat_to_quat(mat) -> np.ndarray:
    import mujoco

    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(mat, dtype=float).reshape(9))
    return q


# ---------------------------------------------------------------------------------------------
# stage 1: the source, checked, then MuJoCo's parser and compiler


def _import_mujoco():
    try:
        import mujoco
    except ImportError as err:
        raise ImportError(
            "armdyn.load_mjcf needs the 'mujoco' package (pip install mujoco, or armdyn[mjcf]): "
            "MJCF is read by MuJoCo's own parser and compiler"
        ) from err
    return mujoco


def _source_kind(source) -> tuple[str, str]:
    """(``"xml"``, text) or (``"path"``, path) for a str / os.PathLike / UTF-8 bytes source."""
    if isinstance(source, (bytes, bytearray, memoryview)):
        data = bytes(source)
        if len(data) > MJCF_MAX_BYTES:
            raise _core.ModelError(_too_large("MJCF bytes", len(data)))
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as err:
            raise _core.ModelError(
                f"MJCF bytes are not valid UTF-8 (byte offset {err.start}); pass XML as UTF-8 "
                "bytes or str, or a path as str"
            ) from None
        if not _is_xml(text):
            raise _core.ModelError(
                f"MJCF bytes must hold XML (starting with '<'), got {data[:40]!r}; pass a path "
                "as str or os.PathLike"
            )
        return "xml", text
    if isinstance(source, os.PathLike):
        path = os.fspath(source)
        if isinstance(path, bytes):
            path = os.fsdecode(path)
        return "path", path
    if not isinstance(source, str):
        raise TypeError(
            "load_mjcf: expected a path (str or os.PathLike) or MJCF XML (str or bytes), got "
            f"{type(source).__name__}"
        )
    try:
        source.encode("utf-8")
    except UnicodeEncodeError as err:
        raise _core.ModelError(
            f"load_mjcf: source holds a lone surrogate at index {err.start}: not valid Unicode text"
        ) from None
    return ("xml", source) if _is_xml(source) else ("path", source)


def _is_xml(text: str) -> bool:
    return text.lstrip("\ufeff").lstrip().startswith("<")


class _Scan:
    """One linear pass of Python's expat over the XML before MuJoCo sees it: the root element,
    the ``file=`` references and asset folders, and the refusals MuJoCo's tinyxml2 cannot make
    cheaply (it is quadratic in the attributes of one element) or at all
    (a DOCTYPE, whose entities MJCF never uses)."""

    REFS = ("file", "meshdir", "texturedir", "assetdir")

    def __init__(self, text: str, label: str):
        import xml.parsers.expat

        self.label, self.root, self.refs = label, "", []
        parser = xml.parsers.expat.ParserCreate()
        parser.ordered_attributes = True
        parser.StartElementHandler = self._element
        parser.StartDoctypeDeclHandler = self._doctype
        self.parser = parser
        try:
            parser.Parse(text, True)
        except xml.parsers.expat.ExpatError as err:
            raise _core.ModelError(
                f"{label}: not well-formed XML: {xml.parsers.expat.ErrorString(err.code)} "
                f"(line {err.lineno}, column {err.offset + 1})"
            ) from None

    def _element(self, name: str, attrs: list) -> None:
        if not self.root:
            self.root = name
        if len(attrs) > 2 * MJCF_MAX_ATTRIBUTES:
            raise _core.ModelError(
                f"{self.label}: element <{name[:40]}> on line {self.parser.CurrentLineNumber} "
                f"has {len(attrs) // 2} attributes, more than the limit of "
                f"{MJCF_MAX_ATTRIBUTES} (armdyn.mjcf.MJCF_MAX_ATTRIBUTES)"
            )
        for key, value in zip(attrs[::2], attrs[1::2], strict=True):
            if key in self.REFS and value:
                self.refs.append((key, value))

    def _doctype(self, name, *_args) -> None:
        raise _core.ModelError(
            f"{self.label}: has a DOCTYPE (<!DOCTYPE {str(name)[:40]}>, line "
            f"{self.parser.CurrentLineNumber}): MJCF uses none, and its entities are refused"
        )


def _check_root(scan: _Scan) -> None:
    """MuJoCo also reads URDF (its own import): load_mjcf takes MJCF only (<mujoco>)."""
    if scan.root != "mujoco":
        hint = "; for a URDF use armdyn.load_urdf" if scan.root == "robot" else ""
        raise _core.ModelError(
            f"{scan.label}: the root element is <{scan.root[:40]}>, not <mujoco>: not MJCF{hint}"
        )


def _too_large(what: str, size: int) -> str:
    return (
        f"{what} is {size} bytes, more than the limit of {MJCF_MAX_BYTES} bytes "
        f"({MJCF_MAX_BYTES >> 20} MiB, armdyn.mjcf.MJCF_MAX_BYTES)"
    )


def _shown_path(path: str) -> str:
    return repr(path if len(path) <= 80 else path[:38] + "..." + path[-38:])


def _check_file(path: str, what: str) -> bytes:
    """The bytes of a regular file of at most MJCF_MAX_BYTES: a missing file, a directory, a
    FIFO or a device is a ModelError naming it (MuJoCo would block on a FIFO)."""
    try:
        return _checks.regular_file(path, what, MJCF_MAX_BYTES)
    except FileNotFoundError:
        raise _core.ModelError(f"{what} {_shown_path(path)} does not exist") from None
    except OSError as err:
        raise _core.ModelError(
            f"{what} {_shown_path(path)} cannot be read: {err.strerror or err}"
        ) from None


def _check_references(scan: _Scan, base: str, seen: set[str]) -> None:
    """Every ``file=`` the XML (and the files it includes) names that exists must be a regular
    file of at most MJCF_MAX_BYTES: checked before MuJoCo opens it (a FIFO would block it); an
    included XML file is scanned as the model is. Paths are tried relative to ``base`` and to
    the <compiler>'s asset folders."""
    dirs = [base] + [os.path.join(base, v) for k, v in scan.refs if k != "file"]
    for kind, value in scan.refs:
        if kind != "file":
            continue
        for d in dirs if not os.path.isabs(value) else [""]:
            cand = os.path.normpath(os.path.join(d, value))
            if cand in seen or not os.path.lexists(cand):
                continue
            seen.add(cand)
            data = _check_file(cand, "MJCF referenced file")
            if cand.lower().endswith(".xml"):
                try:
                    sub = data.decode("utf-8")
                except UnicodeDecodeError:
                    continue  # MuJoCo reports it
                what = f"MJCF included file {_shown_path(cand)}"
                _check_references(_Scan(sub, what), base, seen)


def _compile(source):
    """(MjModel, the source as recorded, a label for messages, MuJoCo's warnings): the source
    checked (type, size, a regular file, the files it references), then MuJoCo's parser and
    compiler (its warnings collected, not written to MUJOCO_LOG.TXT); MuJoCo's refusal becomes
    a ModelError quoting its message (element and line)."""
    mujoco = _import_mujoco()
    kind, value = _source_kind(source)
    if kind == "xml":
        if len(value) > MJCF_MAX_BYTES:  # characters: a lower bound of the bytes
            raise _core.ModelError(_too_large("MJCF string", len(value)))
        if "\x00" in value:
            raise _core.ModelError(
                f"MJCF string: contains a NUL byte at offset {value.index(chr(0))}"
            )
        scan = _Scan(value, "MJCF string")
        _check_root(scan)
        _check_references(scan, os.getcwd(), set())
        label, recorded = "MJCF string", value
        load = mujoco.MjModel.from_xml_string
    else:
        data = _check_file(value, "MJCF file")
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as err:
            raise _core.ModelError(
                f"MJCF file {_shown_path(value)} is not valid UTF-8 (byte offset {err.start})"
            ) from None
        if not _is_xml(text):
            raise _core.ModelError(
                f"MJCF file {_shown_path(value)} does not hold XML (it does not start with '<')"
            )
        scan = _Scan(text, f"MJCF file {_shown_path(value)}")
        _check_root(scan)
        _check_references(scan, os.path.dirname(os.path.abspath(value)), set())
        label, recorded = f"MJCF file {_shown_path(value)}", os.path.abspath(value)
        load = mujoco.MjModel.from_xml_path
    said: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(said.append)  # not MuJoCo's default: a MUJOCO_LOG.TXT in cwd
    try:
        mj = load(value)
    except (ValueError, mujoco.FatalError) as err:
        msg = " | ".join(line for line in str(err).splitlines() if line.strip())
        raise _core.ModelError(f"{label}: MuJoCo refused it: {msg}") from None
    finally:
        mujoco.set_mju_user_warning(previous)
    return mj, recorded, label, [f"MuJoCo's compiler warned: {m.strip()}" for m in said]


# ---------------------------------------------------------------------------------------------
# stage 2: the compiled model onto the builder


def _name(mj, objtype, i: int) -> str:
    import mujoco

    return mujoco.mj_id2name(mj, objtype, i) or ""


class _Names:
    """Unique armdyn names: the MuJoCo name when free, else ``<kind><id>`` (then suffixed)."""

    def __init__(self, reserved=()):
        self.taken = set(reserved)

    def take(self, wanted: str, fallback: str) -> str:
        name = wanted if wanted and wanted not in self.taken else fallback
        base, k = name, 1
        while name in self.taken:
            name, k = f"{base}_{k}", k + 1
        self.taken.add(name)
        return name


class _TreeMapper:
    """The compiled MjModel at qpos0 (``mj_kinematics`` world poses) onto a ModelBuilder."""

    def __init__(self, mj, label: str, fixed_base: bool, gravity, physical_inertia: bool):
        import mujoco

        self.mujoco = mujoco
        self.mj, self.label, self.fixed_base = mj, label, fixed_base
        self.d = mujoco.MjData(mj)
        self.d.qpos[:] = mj.qpos0
        mujoco.mj_kinematics(mj, self.d)
        grav = np.array(mj.opt.gravity, dtype=float) if gravity is None else gravity
        self.b = _core.ModelBuilder(gravity=grav, physical_inertia=physical_inertia)
        self.gravity = np.asarray(grav, dtype=float)
        self.unmapped: list[str] = []
        self.body_names = _Names({"ground"})
        self.joint_names = _Names()
        self.frame_names = _Names()
        self.bodies = ["ground"] * mj.nbody
        self.joints: dict[str, str] = {}
        self.jname: dict[int, str] = {}  # MuJoCo joint id -> armdyn joint (hinge/slide/ball)
        self.sites: dict[str, str] = {}
        self.body_frames: dict[str, str] = {}
        self.followers: dict[int, tuple[int, float]] = {}  # joint id -> (leader id, multiplier)
        self.welded_free: list[int] = []
        self.frictionloss: list[str] = []  # "'name' value" per joint that has one
        self.extent = max(float(mj.stat.extent), 1.0)
        flags, off = int(mj.opt.disableflags), mujoco.mjtDisableBit
        self.no_spring = bool(flags & int(off.mjDSBL_SPRING))
        self.no_damper = bool(flags & int(off.mjDSBL_DAMPER))
        self.no_equality = bool(flags & (int(off.mjDSBL_EQUALITY) | int(off.mjDSBL_CONSTRAINT)))

    # -- helpers ------------------------------------------------------------------------------
    def _finite(self, what: str, values) -> None:
        a = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(a)):
            raise _core.ModelError(f"{self.label}: {what} is not finite: {np.round(a, 6).tolist()}")

    def _call(self, what: str, fn, *args, **kw):
        try:
            return fn(*args, **kw)
        except _core.ModelError as err:
            raise _core.ModelError(f"{self.label}: {what}: {err}") from None

    def body_label(self, i: int) -> str:
        n = _name(self.mj, self.mujoco.mjtObj.mjOBJ_BODY, i)
        return f"body '{n}'" if n else f"body {i} (unnamed)"

    def joint_label(self, j: int) -> str:
        n = _name(self.mj, self.mujoco.mjtObj.mjOBJ_JOINT, j)
        return f"joint '{n}'" if n else f"joint {j} (unnamed)"

    # -- bodies -------------------------------------------------------------------------------
    def add_bodies(self) -> None:
        mj, d = self.mj, self.d
        for i in range(1, mj.nbody):
            what = self.body_label(i)
            self._finite(f"{what}: position at qpos0", d.xpos[i])
            self._finite(f"{what}: orientation at qpos0", d.xquat[i])
            self._finite(f"{what}: centre of mass at qpos0", d.xipos[i])
            self._finite(f"{what}: mass", [mj.body_mass[i]])
            self._finite(f"{what}: inertia", mj.body_inertia[i])
            self._finite(f"{what}: inertia axes", mj.body_iquat[i])
            name = self.body_names.take(_name(mj, self.mujoco.mjtObj.mjOBJ_BODY, i), f"body{i}")
            rot = _quat_to_mat(mj.body_iquat[i])
            inertia = rot @ np.diag(mj.body_inertia[i]) @ rot.T
            self._call(
                what,
                self.b.add_body,
                name,
                float(mj.body_mass[i]),
                inertia,
                d.xipos[i].copy(),
                d.xquat[i].copy(),
            )
            self.bodies[i] = name
            if mj.body_mocapid[i] >= 0:
                self.unmapped.append(f"mocap {what}: welded to the world at its qpos0 pose")

    def add_gravcomp(self) -> None:
        """``<body gravcomp>``: MuJoCo's passive force ``-gravcomp * mass * gravity`` at the
        centre of mass is a constant world force on the body (``add_body_force``), exact; when
        a joint routes it through actuators (``actuatorgravcomp``) it is listed instead."""
        mj = self.mj
        bodies = np.flatnonzero(mj.body_gravcomp != 0)
        if len(bodies) == 0:
            return
        if np.any(mj.jnt_actgravcomp != 0):
            self.unmapped.append("body gravcomp routed through actuators (actuatorgravcomp)")
            return
        for i in bodies:
            self._finite(f"{self.body_label(i)}: gravcomp", [mj.body_gravcomp[i]])
            force = -float(mj.body_gravcomp[i]) * float(mj.body_mass[i]) * self.gravity
            if self.bodies[i] != "ground":
                self._call(self.body_label(i), self.b.add_body_force, self.bodies[i], force)

    # -- joints -------------------------------------------------------------------------------
    def add_joints(self) -> None:
        mj = self.mj
        for i in range(1, mj.nbody):
            parent = self.bodies[mj.body_parentid[i]]
            jids = list(range(mj.body_jntadr[i], mj.body_jntadr[i] + mj.body_jntnum[i]))
            if mj.body_mocapid[i] >= 0:
                jids = []
            if not jids:
                jn = self.joint_names.take(f"{self.bodies[i]}_weld", f"{self.bodies[i]}_weld")
                self._call(self.body_label(i), self.b.add_fixed, jn, parent, self.bodies[i])
                continue
            for k, j in enumerate(jids):
                if k < len(jids) - 1:  # a massless body between this joint and the next
                    child = self.body_names.take(
                        f"{self.bodies[i]}__{_name(mj, self.mujoco.mjtObj.mjOBJ_JOINT, j)}",
                        f"{self.bodies[i]}__joint{j}",
                    )
                    self._call(
                        self.body_label(i),
                        self.b.add_body,
                        child,
                        0.0,
                        np.zeros(3),
                        self.d.xpos[i].copy(),
                        self.d.xquat[i].copy(),
                    )
                else:
                    child = self.bodies[i]
                self.add_joint(j, parent, child, i)
                parent = child

    def add_joint(self, j: int, parent: str, child: str, body: int) -> None:
        mj, d = self.mj, self.d
        kind = _JOINT_KINDS[int(mj.jnt_type[j])]
        what = self.joint_label(j)
        mname = _name(mj, self.mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"
        self._finite(f"{what}: anchor at qpos0", d.xanchor[j])
        self._finite(f"{what}: axis at qpos0", d.xaxis[j])
        name = self.joint_names.take(mname, f"joint{j}")
        self.joints[mname] = name
        point, axis = d.xanchor[j].copy(), d.xaxis[j].copy()
        if kind == "hinge":
            self._call(what, self.b.add_revolute, name, parent, child, point, axis)
        elif kind == "slide":
            self._call(what, self.b.add_prismatic, name, parent, child, point, axis)
        elif kind == "ball":
            self._call(what, self.b.add_spherical, name, parent, child, point)
        elif self.fixed_base:
            self._call(what, self.b.add_fixed, name, parent, child, d.xpos[body].copy())
            self.welded_free.append(j)
            self.unmapped.append(
                f"free {what}: welded to the world at qpos0 (fixed_base=True; pass "
                "fixed_base=False to keep it free)"
            )
            return
        else:
            self._call(what, self.b.add_free, name, child, d.xpos[body].copy())
        self.jname[j] = name
        self.add_joint_data(j, kind, name, what)

    def add_joint_data(self, j: int, kind: str, name: str, what: str) -> None:
        """Limits, damping, armature, stiffness of one joint (hinge and slide: mapped; ball and
        free: listed as not mapped when present), frictionloss (never mapped)."""
        mj = self.mj
        dof = mj.jnt_dofadr[j]
        ndof = {"free": 6, "ball": 3}.get(kind, 1)
        damping = np.array(mj.dof_damping[dof : dof + ndof])
        armature = np.array(mj.dof_armature[dof : dof + ndof])
        stiffness = float(mj.jnt_stiffness[j])
        for label, vals in (
            ("damping", damping),
            ("armature", armature),
            ("stiffness", [stiffness]),
        ):
            self._finite(f"{what}: {label}", vals)
        floss = mj.dof_frictionloss[dof : dof + ndof]
        if np.any(floss != 0):
            self.frictionloss.append(f"{what.removeprefix('joint ')} {float(np.max(floss)):g}")
        if kind in ("ball", "free"):
            for label, vals in (
                ("damping", damping),
                ("armature", armature),
                ("stiffness", [stiffness]),
            ):
                if np.any(np.asarray(vals) != 0):
                    self.unmapped.append(f"{kind} {what}: {label} {float(np.max(vals)):g}")
            if kind == "ball" and mj.jnt_limited[j]:
                self.unmapped.append(f"ball {what}: range (cone limit)")
            return
        qadr = mj.jnt_qposadr[j]
        q0 = float(mj.qpos0[qadr])
        if mj.jnt_limited[j]:
            lo, hi = (float(v) - q0 for v in mj.jnt_range[j])
            self._finite(f"{what}: range", [lo, hi])
            self._call(what, self.b.set_joint_limits, name, lo, hi)
        if damping[0] != 0 and not self.no_damper:
            self._call(what, self.b.add_joint_friction, name, viscous=float(damping[0]))
        if stiffness != 0 and not self.no_spring:
            rest = float(mj.qpos_spring[qadr]) - q0
            self._finite(f"{what}: springref", [rest])
            self._call(what, self.b.add_joint_spring_damper, name, stiffness=stiffness, rest=rest)
        if armature[0] != 0:
            self._call(what, self.b.add_actuator, name, 1.0, float(armature[0]))

    # -- frames -------------------------------------------------------------------------------
    def add_frames(self) -> None:
        mj, d, obj = self.mj, self.d, self.mujoco.mjtObj
        for i in range(mj.nbody):
            mname = _name(mj, obj.mjOBJ_BODY, i) or ("world" if i == 0 else f"body{i}")
            fname = self.frame_names.take(self.bodies[i] if i else mname, f"body{i}")
            self._call(
                self.body_label(i), self.b.add_frame, fname, self.bodies[i],
                d.xpos[i].copy(), d.xquat[i].copy(),
            )  # fmt: skip
            self.body_frames[mname] = fname
        for s in range(mj.nsite):
            mname = _name(mj, obj.mjOBJ_SITE, s) or f"site{s}"
            self._finite(f"site '{mname}': pose at qpos0", d.site_xpos[s])
            fname = self.frame_names.take(mname, f"site:{mname}")
            body = self.bodies[mj.site_bodyid[s]]
            self._call(
                f"site '{mname}'", self.b.add_frame, fname, body,
                d.site_xpos[s].copy(), _mat_to_quat(d.site_xmat[s]),
            )  # fmt: skip
            self.sites[mname] = fname


def _gravity(gravity):
    if gravity is None:
        return None
    g = _checks.array("load_mjcf", "gravity", gravity, ndim=1, finite=True)
    if g.shape != (3,):
        raise _core.ModelError(f"load_mjcf: gravity must be 3 numbers, got shape {g.shape}")
    return g


class _Mapper(_TreeMapper):
    """The equalities and actuators, the list of what is not mapped, and the info."""

    # -- equalities ---------------------------------------------------------------------------
    def add_equalities(self) -> None:
        mj, obj = self.mj, self.mujoco.mjtObj
        if mj.neq and self.no_equality:
            self.unmapped.append(
                f"{mj.neq} equalities: the MJCF disables them (option flag equality or "
                "constraint), as MuJoCo"
            )
            return
        residual = self._equality_residuals()
        for e in range(mj.neq):
            kind = _EQ_KINDS.get(int(mj.eq_type[e]), f"type {int(mj.eq_type[e])}")
            ename = _name(mj, obj.mjOBJ_EQUALITY, e)
            what = f"equality {kind} '{ename}'" if ename else f"equality {kind} {e} (unnamed)"
            if not mj.eq_active0[e]:
                self.unmapped.append(f"{what}: inactive at the start (eq active='false')")
                continue
            name = self.joint_names.take(ename, f"equality{e}")
            self._finite(f"{what}: data", mj.eq_data[e])
            if kind in ("connect", "weld"):
                self.add_loop(e, kind, what, name, residual.get(e, 0.0))
            elif kind == "joint":
                self.add_joint_equality(e, what, name)
            elif kind == "tendon":
                self.add_tendon_equality(e, what, name)
            else:
                self.unmapped.append(f"{what}: {kind} equalities are not mapped")

    def _equality_residuals(self) -> dict[int, float]:
        """MuJoCo's own residual of each active equality at qpos0 (``efc_pos`` of its rows)."""
        mujoco, mj = self.mujoco, self.mj
        if mj.neq == 0:
            return {}
        flags = int(mj.opt.disableflags)
        mj.opt.disableflags = (
            flags
            & ~int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
            & ~int(mujoco.mjtDisableBit.mjDSBL_EQUALITY)
        )
        try:
            d = mujoco.MjData(mj)
            d.qpos[:] = mj.qpos0
            mujoco.mj_forward(mj, d)
        finally:
            mj.opt.disableflags = flags
        out: dict[int, float] = {}
        eq_rows = d.efc_type == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        for row in np.flatnonzero(eq_rows):
            e = int(d.efc_id[row])
            out[e] = max(out.get(e, 0.0), abs(float(d.efc_pos[row])))
        return out

    def _eq_objects(self, e: int, kind: str):
        """(body1, body2, world anchor) of a connect / weld: the anchor on body1 (connect) or
        body2 (weld), or site1's position for sites."""
        mj, d = self.mj, self.d
        o1, o2 = int(mj.eq_obj1id[e]), int(mj.eq_obj2id[e])
        if int(mj.eq_objtype[e]) == int(self.mujoco.mjtObj.mjOBJ_SITE):
            return mj.site_bodyid[o1], mj.site_bodyid[o2], d.site_xpos[o1].copy()
        if kind == "connect":
            return o1, o2, d.xpos[o1] + d.xmat[o1].reshape(3, 3) @ mj.eq_data[e, 0:3]
        return o1, o2, d.xpos[o2] + d.xmat[o2].reshape(3, 3) @ mj.eq_data[e, 0:3]

    def add_loop(self, e: int, kind: str, what: str, name: str, residual: float) -> None:
        b1, b2, anchor = self._eq_objects(e, kind)
        if residual > ASSEMBLY_TOLERANCE * self.extent:
            raise _core.ModelError(
                f"{self.label}: {what}: not satisfied at qpos0 (MuJoCo's residual {residual:.3g}): "
                "armdyn's loop joints are rigid and assembled at the model's reference pose; "
                "give the MJCF a qpos0 (joint ref) where the loop is closed"
            )
        p, c = self.bodies[b1], self.bodies[b2]
        if p == c:
            self.unmapped.append(f"{what}: joins '{p}' to itself (both welded to the world)")
            return
        add = self.b.add_spherical if kind == "connect" else self.b.add_fixed
        self._call(what, add, name, p, c, np.asarray(anchor, dtype=float))
        if kind == "weld" and float(self.mj.eq_data[e, 10]) != 1.0:
            self.unmapped.append(f"{what}: torquescale (a soft-constraint weight; rigid here)")

    def add_joint_equality(self, e: int, what: str, name: str) -> None:
        mj = self.mj
        j1, j2 = int(mj.eq_obj1id[e]), int(mj.eq_obj2id[e])
        coef = np.array(mj.eq_data[e, 0:5], dtype=float)
        why = None
        if j2 < 0:
            why = "no joint2 (a joint held at a constant)"
        elif np.any(coef[2:] != 0):
            why = f"polycoef {coef.tolist()} is not linear"
        elif coef[1] == 0:
            why = "polycoef's linear term is 0"
        elif j1 not in self.jname or j2 not in self.jname:
            why = "a joint welded by fixed_base=True or not a hinge or slide"
        elif mj.jnt_type[j1] != mj.jnt_type[j2] or mj.jnt_type[j1] not in (2, 3):
            why = "the two joints are not both hinges or both slides"
        if why is not None:
            self.unmapped.append(f"{what}: {why}")
            return
        self._call(
            what, self.b.add_coupling, name, self.jname[j1], self.jname[j2],
            float(coef[1]), float(coef[0]),
        )  # fmt: skip

    def add_tendon_equality(self, e: int, what: str, name: str) -> None:
        """A ``tendon`` equality on one fixed tendon of two joints ``c1 q1 + c2 q2`` (MuJoCo:
        ``L - L0 = a0``, L0 the length at qpos0) is the coupling ``q2 = -(c1/c2) q1 + a0/c2``
        (the tendon's second joint follows its first); any other is listed."""
        mj = self.mj
        t1, t2 = int(mj.eq_obj1id[e]), int(mj.eq_obj2id[e])
        adr, num = int(mj.tendon_adr[t1]), int(mj.tendon_num[t1])
        wraps = range(adr, adr + num)
        joints = [int(mj.wrap_objid[w]) for w in wraps]
        coef = [float(mj.wrap_prm[w]) for w in wraps]
        why = None
        if t2 >= 0:
            why = "between two tendons"
        elif num != 2 or any(int(mj.wrap_type[w]) != 1 for w in wraps):  # 1: mjWRAP_JOINT
            why = "not a fixed tendon of exactly two joints"
        elif any(j not in self.jname for j in joints) or coef[0] == 0 or coef[1] == 0:
            why = "a joint welded by fixed_base=True, not a hinge or slide, or a zero coef"
        elif mj.jnt_type[joints[0]] != mj.jnt_type[joints[1]] or joints[0] == joints[1]:
            why = "the tendon's two joints are not both hinges or both slides"
        if why is not None:
            self.unmapped.append(f"{what}: {why}")
            return
        a0 = float(mj.eq_data[e, 0])
        self._call(
            what, self.b.add_coupling, name, self.jname[joints[1]], self.jname[joints[0]],
            -coef[0] / coef[1], a0 / coef[1],
        )  # fmt: skip

    # -- actuators ----------------------------------------------------------------------------
    def actuators(self) -> tuple[MjcfActuator, ...]:
        mujoco, mj = self.mujoco, self.mj
        out = []
        for a in range(mj.nu):
            trn = mujoco.mjtTrn(int(mj.actuator_trntype[a])).name.removeprefix("mjTRN_").lower()
            tid = int(mj.actuator_trnid[a, 0])
            if trn in ("joint", "jointinparent"):
                mname = _name(mj, mujoco.mjtObj.mjOBJ_JOINT, tid) or f"joint{tid}"
                target = self.joints.get(mname, mname)
            else:
                objtype = {
                    "tendon": mujoco.mjtObj.mjOBJ_TENDON,
                    "site": mujoco.mjtObj.mjOBJ_SITE,
                    "slidercrank": mujoco.mjtObj.mjOBJ_SITE,
                    "body": mujoco.mjtObj.mjOBJ_BODY,
                }.get(trn)
                target = (_name(mj, objtype, tid) if objtype is not None else "") or str(tid)
            out.append(
                MjcfActuator(
                    name=_name(mj, mujoco.mjtObj.mjOBJ_ACTUATOR, a) or f"actuator{a}",
                    transmission=trn,
                    target=target,
                    gear=tuple(float(g) for g in mj.actuator_gear[a]),
                    ctrlrange=tuple(map(float, mj.actuator_ctrlrange[a]))
                    if mj.actuator_ctrllimited[a]
                    else None,
                    forcerange=tuple(map(float, mj.actuator_forcerange[a]))
                    if mj.actuator_forcelimited[a]
                    else None,
                    dyntype=mujoco.mjtDyn(int(mj.actuator_dyntype[a])).name[6:].lower(),
                    gaintype=mujoco.mjtGain(int(mj.actuator_gaintype[a])).name[7:].lower(),
                    biastype=mujoco.mjtBias(int(mj.actuator_biastype[a])).name[7:].lower(),
                )
            )
        return tuple(out)

    # -- what is not mapped -------------------------------------------------------------------
    def collect_unmapped(self) -> None:
        mj, u = self.mj, self.unmapped
        if self.frictionloss:
            u.append(
                "frictionloss (dry friction, a constraint in MuJoCo) of joints "
                + ", ".join(self.frictionloss)
            )
        n_coll = int(np.count_nonzero((mj.geom_contype != 0) | (mj.geom_conaffinity != 0)))
        if n_coll or mj.npair:
            u.append(f"contacts: {n_coll} colliding geoms, {mj.npair} explicit contact pairs")
        if mj.nexclude:
            u.append(f"{mj.nexclude} contact exclusions")
        if mj.nu:
            u.append(
                f"{mj.nu} actuators apply no force (their transmissions and gears: "
                "armdyn.mjcf.mjcf_info(model).actuators)"
            )
        if mj.ntendon:
            u.append(f"{mj.ntendon} tendons (their springs, dampers, limits and lengths)")
        if np.any(mj.jnt_limited != 0) or mj.neq:
            u.append(
                "solref/solimp/margin of joint limits and equalities (soft constraints): "
                "armdyn's loop joints and couplings are rigid; ranges are recorded as "
                "model.coord_lower/coord_upper, enforced only by simulate(limits=True)"
            )
        if np.any(mj.jnt_actfrclimited != 0):
            u.append("joint actuatorfrcrange (limits on the actuators' total force)")
        if mj.opt.density or mj.opt.viscosity or np.any(mj.opt.wind != 0):
            u.append("fluid forces (option density, viscosity, wind)")
        for count, what in (
            (mj.nsensor, "sensors"),
            (mj.nkey, "keyframes (convert their qpos with mjcf_info(model).q_from_qpos)"),
            (mj.nflex, "flexes (deformable bodies)"),
            (mj.nskin, "skins"),
            (mj.nplugin, "plugins"),
        ):
            if count:
                u.append(f"{count} {what}")
        visual = [
            f"{n} {w}"
            for n, w in ((mj.ncam, "cameras"), (mj.nlight, "lights"), (mj.nmat, "materials"),
                         (mj.ntex, "textures"))
            if n
        ]  # fmt: skip
        if visual:
            u.append("visual elements (no effect on the dynamics): " + ", ".join(visual))
        for off, what in ((self.no_spring, "stiffness"), (self.no_damper, "damping")):
            if off and np.any((mj.jnt_stiffness if what == "stiffness" else mj.dof_damping) != 0):
                u.append(f"joint {what}: the MJCF disables it (option flag), as MuJoCo")
        if not self.fixed_base and not np.any(mj.jnt_type == 0):
            u.append("fixed_base=False: the MJCF has no free joint, so nothing floats")

    # -- the info -----------------------------------------------------------------------------
    def info(self, model: _core.Model, recorded: str) -> MjcfInfo:
        mj = self.mj
        couplings = {c["follower"]: (c["leader"], c["multiplier"]) for c in model.couplings}
        coords, dofs = list(model.coord_names), list(model.dof_names)
        q_src, cols = [], [[] for _ in dofs]
        for j, name in self.jname.items():
            kind = _JOINT_KINDS[int(mj.jnt_type[j])]
            qadr, dadr = int(mj.jnt_qposadr[j]), int(mj.jnt_dofadr[j])
            if kind == "free" and f"{name}:x" in coords:
                q_src.append((coords.index(f"{name}:x"), ("free", qadr)))
                c = dofs.index(f"{name}:vx")
                cols[c].append(("freelin", dadr, 1.0, qadr))
                cols[c + 3].append(("freeang", dadr + 3, 1.0, qadr))
            elif kind in ("hinge", "slide"):
                if name in coords:
                    q_src.append((coords.index(name), ("joint", qadr)))
                lead, mult = name, 1.0
                while lead in couplings and lead not in dofs:
                    lead, m = couplings[lead]
                    mult *= m
                if lead in dofs:
                    cols[dofs.index(lead)].append(("dof", dadr, mult, qadr))
        q_src.sort()
        adr_of = {name: int(mj.jnt_qposadr[j]) for j, name in self.jname.items()}
        followers = tuple(
            (adr_of[c["follower"]], adr_of[c["leader"]], c["multiplier"], c["offset"])
            for c in model.couplings
            if c["follower"] in adr_of and c["leader"] in adr_of
        )
        return MjcfInfo(
            source=recorded,
            bodies=tuple(self.bodies),
            joints=dict(self.joints),
            sites=dict(self.sites),
            body_frames=dict(self.body_frames),
            actuators=self.actuators(),
            unmapped=tuple(self.unmapped),
            qpos0=np.array(mj.qpos0, dtype=float),
            nv_mujoco=int(mj.nv),
            _q_src=tuple(src for _, src in q_src),
            _dof_cols=tuple(tuple(c) for c in cols),
            _followers=followers,
        )


def load_mjcf(
    source,
    fixed_base: bool = True,
    *,
    physical_inertia: bool = True,
    gravity=None,
    warn: bool = True,
) -> _core.Model:
    """Load a MuJoCo MJCF model (a file or its XML text) into a finalized Model.

    MuJoCo's own parser and compiler read it (``mujoco.MjModel.from_xml_path`` /
    ``from_xml_string``: defaults, ``<include>``, inertias from geoms, ``<compiler angle=>``
    and every other MJCF rule are MuJoCo's); the compiled model, posed at ``qpos0`` by
    ``mj_kinematics``, is mapped onto :class:`armdyn.ModelBuilder`:

    - each MuJoCo body is a body (mass, centre of mass, inertia; its axes the body frame's)
      and a named frame at its body frame (the world body's is ``"world"``); each site a frame;
    - hinge, slide, ball and free joints are revolute, prismatic, spherical and free joints
      (several joints in one body: a chain through massless bodies ``<body>__<joint>``); a body
      without joints is welded to its parent; armdyn's joint coordinates are 0 at ``qpos0``;
    - hinge/slide ``range`` -> joint limits, ``damping`` -> viscous joint friction, ``stiffness``
      / ``springref`` -> a joint spring, ``armature`` -> an actuator of gear ratio 1 and rotor
      inertia ``armature`` (the gear-reduced model: exactly MuJoCo's ``M + diag(armature)``);
    - ``<equality>``: ``connect`` -> a spherical joint and ``weld`` -> a fixed joint between the
      two bodies at the anchor (closing loops; they must hold at qpos0), a ``joint`` equality
      with a linear ``polycoef`` -> ``add_coupling(name, joint1, joint2, a1, a0)``, a
      ``tendon`` equality on a fixed tendon of two joints -> a coupling likewise;
    - ``<body gravcomp>`` -> a constant world force ``-gravcomp * mass * gravity`` at the
      body's centre of mass (MuJoCo's gravity compensation);
    - actuators apply no force: :func:`mjcf_info` lists their transmissions and gears.

    ``fixed_base=True`` welds every free joint to the world at its qpos0 pose; ``False`` keeps
    them (armdyn's free-joint ``qd`` has the linear velocity in the body's axes, MuJoCo's in
    world axes: :meth:`MjcfInfo.velocity_map`). ``gravity`` (3 numbers) overrides
    ``<option gravity>``. Everything not mapped (contacts, tendons, soft-constraint parameters,
    actuator dynamics, sensors, ...) is listed in ONE ``UserWarning`` (``warn=False``: none;
    always in ``mjcf_info(model).unmapped``). See docs/mjcf.md.

    Raises:
        ModelError: a missing or irregular file or referenced file (a directory, a FIFO, a
            device), a file or string over ``MJCF_MAX_BYTES``, what MuJoCo refuses (its message,
            with the element and line), a non-finite number MuJoCo accepts (naming the body or
            joint), a connect / weld not closed at qpos0, what the builder refuses (naming the
            body or joint), a bad option type.
        TypeError: ``source`` is neither str, bytes nor os.PathLike.
        ImportError: the ``mujoco`` package is not installed.
    """
    fixed = _checks.flag("load_mjcf", "fixed_base", fixed_base)
    phys = _checks.flag("load_mjcf", "physical_inertia", physical_inertia)
    do_warn = _checks.flag("load_mjcf", "warn", warn)
    grav = _gravity(gravity)
    mj, recorded, label, said = _compile(source)
    if grav is None and int(mj.opt.disableflags) & int(
        _import_mujoco().mjtDisableBit.mjDSBL_GRAVITY
    ):
        grav = np.zeros(3)
    mapper = _Mapper(mj, label, fixed, grav, phys)
    mapper.unmapped.extend(said)
    mapper.add_bodies()
    mapper.add_joints()
    mapper.add_gravcomp()
    mapper.add_equalities()
    mapper.add_frames()
    mapper.collect_unmapped()
    try:
        model = mapper.b.finalize()
    except _core.ModelError as err:
        raise _core.ModelError(f"{label}: {err}") from None
    info = mapper.info(model, recorded)
    _INFOS[model] = info
    if do_warn and info.unmapped:
        warnings.warn(
            f"armdyn.load_mjcf: not mapped from {label}:\n  - " + "\n  - ".join(info.unmapped),
            UserWarning,
            stacklevel=2,
        )
    return model
