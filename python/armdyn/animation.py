"""armdyn.animate: a run as one self-contained HTML file (the K3D-jupyter WebGL viewer inlined).

The viewer is K3D-jupyter's standalone snapshot (``k3d`` on PyPI, the ``viz`` extra): its
JavaScript is embedded in the file, so the page needs no network access. Links are drawn from the
URDF's ``<visual>`` elements (meshes STL/OBJ/DAE through ``trimesh``, boxes, cylinders and
spheres), or, for a model built with :class:`armdyn.ModelBuilder` and for bodies without any
``<visual>``, from each body's equivalent inertia box and rods from the joints to the centres of
mass. The viewer's *Controls → Animation* panel has the time slider and the play/pause toggle
("Play loop", "Stop loop" while playing).
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from armdyn import _core
from armdyn._rotation import quat_to_rot
from armdyn.urdf import urdf_source

__all__ = ["animate"]

_DEFAULT_COLOUR = (0.72, 0.74, 0.78)
_MESH_SUFFIXES = (".stl", ".obj", ".dae")


@dataclass
class Visual:
    """One drawable piece of a link, in the link frame (or, with ``body``, of a body in its
    centre-of-mass frame): triangles and an RGB colour in [0, 1]."""

    link: str
    vertices: np.ndarray  # (n, 3) float64, link frame [m]
    faces: np.ndarray  # (m, 3) int
    colour: tuple
    body: bool = False


def _import_viewer():
    try:
        import k3d  # noqa: F401
        import trimesh  # noqa: F401
    except ImportError as err:
        raise ImportError(
            f"armdyn.animate needs the optional viewer packages (missing: {err.name}); install "
            "them with: pip install 'armdyn[viz]'"
        ) from None


# ---------------------------------------------------------------------------------------------
# URDF <visual> parsing


def _floats(text: str | None, n: int, what: str, default=None) -> np.ndarray:
    if text is None:
        if default is None:
            raise _core.UrdfError(f"animate: {what} is missing")
        return np.array(default, dtype=float)
    try:
        vals = np.array([float(x) for x in text.split()], dtype=float)
    except ValueError:
        raise _core.UrdfError(f"animate: {what} = {text!r} is not {n} numbers") from None
    if vals.size != n or not np.all(np.isfinite(vals)):
        raise _core.UrdfError(f"animate: {what} = {text!r} is not {n} finite numbers")
    return vals


def _rpy_matrix(rpy) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _origin(elem, what: str) -> np.ndarray:
    t = np.eye(4)
    o = elem.find("origin")
    if o is not None:
        t[:3, 3] = _floats(o.get("xyz"), 3, f"{what} <origin xyz>", (0, 0, 0))
        t[:3, :3] = _rpy_matrix(_floats(o.get("rpy"), 3, f"{what} <origin rpy>", (0, 0, 0)))
    return t


def _package_roots(package: str, base: Path | None) -> list[Path]:
    """Candidate folders of ROS package ``package``: a folder of that name in the URDF's folder
    or any parent (and their ``share/``), then ``ROS_PACKAGE_PATH`` entries."""
    roots = []
    if base is not None:
        for parent in [base, *base.parents]:
            roots += [parent / package, parent / "share" / package]
            if parent.name == package:
                roots.append(parent)
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            roots.append(Path(entry) / package)
            if Path(entry).name == package:
                roots.append(Path(entry))
    return roots


def resolve_mesh(filename: str, base: Path | None, link: str) -> Path:
    """The file of a ``<mesh filename=...>``: ``package://pkg/rest`` (searched as
    :func:`_package_roots` says), ``file://`` or a path (relative to the URDF's folder)."""
    tried = []
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://") :].partition("/")
        for root in _package_roots(package, base):
            cand = root / rest
            tried.append(cand)
            if cand.is_file():
                return cand
    else:
        name = filename[len("file://") :] if filename.startswith("file://") else filename
        cand = Path(name)
        if not cand.is_absolute():
            cand = (base or Path.cwd()) / cand
        tried.append(cand)
        if cand.is_file():
            return cand
    shown = ", ".join(str(p) for p in dict.fromkeys(tried)) or "nowhere (no URDF folder)"
    raise _core.UrdfError(
        f"animate: link '{link}': mesh '{filename}' not found (looked at {shown}); pass "
        "urdf= as a file path so relative and package:// paths resolve, or set ROS_PACKAGE_PATH"
    )


def _load_mesh(path: Path, link: str) -> list[tuple[np.ndarray, np.ndarray, tuple | None]]:
    """(vertices, faces, colour or None) per piece of a mesh file (a DAE keeps its materials)."""
    import trimesh

    if path.suffix.lower() not in _MESH_SUFFIXES:
        raise _core.UrdfError(
            f"animate: link '{link}': mesh '{path}' has an unsupported format (STL, OBJ or DAE)"
        )
    if path.suffix.lower() == ".dae":
        try:
            import collada  # noqa: F401  (trimesh reads COLLADA through pycollada)
        except ImportError:
            raise ImportError(
                f"animate: link '{link}': reading the COLLADA mesh '{path}' needs pycollada; "
                "install the viewer packages with: pip install 'armdyn[viz]'"
            ) from None
    try:
        loaded = trimesh.load(str(path), force="scene")
    except Exception as err:
        raise _core.UrdfError(f"animate: link '{link}': cannot read mesh '{path}': {err}") from None
    # a COLLADA file's <unit meter=...> scales it to metres (as RViz reads it); STL and OBJ
    # carry no unit and are taken in metres
    factor = 1.0
    if path.suffix.lower() == ".dae" and loaded.units:
        from trimesh.units import unit_conversion

        factor = float(unit_conversion(loaded.units, "meters"))
    pieces = []
    for geom in loaded.dump():
        if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
            continue
        colour = None
        material = getattr(geom.visual, "material", None)
        main = getattr(material, "main_color", None) if material is not None else None
        if main is None and getattr(geom.visual, "kind", None) in ("face", "vertex"):
            main = geom.visual.main_color
        if main is not None:
            colour = tuple(float(c) / 255.0 for c in np.asarray(main)[:3])
        verts = factor * np.asarray(geom.vertices, float)
        pieces.append((verts, np.asarray(geom.faces, np.int64), colour))
    if not pieces:
        raise _core.UrdfError(f"animate: link '{link}': mesh '{path}' holds no triangles")
    return pieces


def _shape(geometry, link: str):
    """(vertices, faces) of a URDF box, cylinder (along z) or sphere, or None if not a shape."""
    import trimesh

    box, cyl, sph = geometry.find("box"), geometry.find("cylinder"), geometry.find("sphere")

    def size(elem, attr, n, shape):
        vals = _floats(elem.get(attr), n, f"link '{link}' <{shape} {attr}>")
        if np.any(vals <= 0):
            raise _core.UrdfError(
                f"animate: link '{link}' <{shape} {attr}> = {elem.get(attr)!r} must be positive"
            )
        return vals

    if box is not None:
        m = trimesh.creation.box(extents=size(box, "size", 3, "box"))
    elif cyl is not None:
        r = size(cyl, "radius", 1, "cylinder")[0]
        m = trimesh.creation.cylinder(radius=r, height=size(cyl, "length", 1, "cylinder")[0])
    elif sph is not None:
        m = trimesh.creation.icosphere(subdivisions=3, radius=size(sph, "radius", 1, "sphere")[0])
    else:
        return None
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def urdf_visuals(urdf: str | bytes | os.PathLike) -> list[Visual]:
    """Every ``<visual>`` of a URDF (a path, or the XML as str or UTF-8 bytes) as triangles in
    its link's frame."""
    if isinstance(urdf, (bytes, bytearray)):
        text = bytes(urdf).decode("utf-8")
    else:
        text = os.fspath(urdf)
        text = os.fsdecode(text) if isinstance(text, bytes) else text
    base = None
    if not text.lstrip("\ufeff").lstrip().startswith("<"):
        path = Path(text)
        if not path.is_file():
            raise _core.UrdfError(f"animate: URDF file '{text}' not found")
        base = path.resolve().parent
        text = path.read_text(encoding="utf-8")
    try:
        root = ET.fromstring(text.lstrip("\ufeff"))
    except ET.ParseError as err:
        raise _core.UrdfError(f"animate: the URDF is not well-formed XML: {err}") from None
    named = {}
    for mat in root.findall("material"):
        col = mat.find("color")
        if mat.get("name") and col is not None:
            named[mat.get("name")] = _floats(
                col.get("rgba"), 4, f"material '{mat.get('name')}' rgba"
            )[:3]
    visuals = []
    for link in root.findall("link"):
        lname = link.get("name", "")
        for vis in link.findall("visual"):
            where = f"link '{lname}' <visual>"
            t = _origin(vis, where)
            colour = None
            mat = vis.find("material")
            if mat is not None:
                col = mat.find("color")
                if col is not None:
                    colour = tuple(_floats(col.get("rgba"), 4, f"{where} material rgba")[:3])
                elif mat.get("name") in named:
                    colour = tuple(named[mat.get("name")])
            geometry = vis.find("geometry")
            if geometry is None:
                raise _core.UrdfError(f"animate: {where} has no <geometry>")
            shape = _shape(geometry, lname)
            if shape is not None:
                pieces = [(*shape, None)]
            else:
                mesh = geometry.find("mesh")
                if mesh is None or not mesh.get("filename"):
                    raise _core.UrdfError(
                        f"animate: {where}: geometry is none of box, cylinder, sphere, mesh"
                    )
                scale = _floats(mesh.get("scale"), 3, f"{where} mesh scale", (1, 1, 1))
                # a mirroring scale (odd number of negative factors) turns the triangles over
                flip = np.prod(np.sign(scale)) < 0
                pieces = [
                    (v * scale, f[:, ::-1] if flip else f, c)
                    for v, f, c in _load_mesh(
                        resolve_mesh(mesh.get("filename"), base, lname), lname
                    )
                ]
            for v, f, c in pieces:
                verts = v @ t[:3, :3].T + t[:3, 3]
                visuals.append(Visual(lname, verts, f, colour or c or _DEFAULT_COLOUR))
    return visuals


# ---------------------------------------------------------------------------------------------
# models without a URDF: equivalent inertia boxes and rods


def inertia_box(mass: float, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(extents (3,), axes (3, 3) as columns) of the uniform box with the body's mass and
    central inertia: I_x = m (b² + c²) / 12 ... gives a² = 6 (I_y + I_z − I_x) / m."""
    moments, axes = np.linalg.eigh(np.asarray(inertia, float))
    if mass <= 0:
        return np.full(3, 0.0), axes
    sq = 6.0 * (moments.sum() - 2.0 * moments) / mass
    return np.sqrt(np.clip(sq, 0.0, None)), axes


def builder_visuals(model, bodies=None) -> list[Visual]:
    """Per body (of ``bodies``, default all) its equivalent inertia box, thickened to 6 % of
    the model's largest joint-to-centre distance where thinner (rods, point masses, massless
    bodies), and a rod from each of its joint points to its centre of mass; in the body frame
    (origin at the centre of mass)."""
    import trimesh

    names = list(model.body_names)
    masses, inertias = np.asarray(model.masses), np.asarray(model.inertias)
    reach = [0.0] * len(names)
    rods = []
    for j in model.joint_names:
        jf = model.joint_frame(j)
        for side in ("parent", "child"):
            body = jf[side]
            p = np.asarray(jf[f"point_{side}"], float)
            if body != "ground":
                k = names.index(body)
                reach[k] = max(reach[k], float(np.linalg.norm(p)))
                if np.linalg.norm(p) > 0:
                    rods.append((body, p))
    scale = max(max(reach, default=0.0), 1e-3)
    visuals = []
    for k, name in enumerate(names):
        if bodies is not None and name not in bodies:
            continue
        ext, axes = inertia_box(masses[k], inertias[k])
        if ext.min() < 0.02 * max(ext.max(), scale):
            # a rod or a point: keep its length, give it a visible thickness
            ext = np.maximum(ext, 0.06 * scale)
        m = trimesh.creation.box(extents=ext)
        visuals.append(
            Visual(
                name, np.asarray(m.vertices) @ axes.T, np.asarray(m.faces), _DEFAULT_COLOUR, True
            )
        )
    for body, p in rods:
        if bodies is not None and body not in bodies:
            continue
        length = float(np.linalg.norm(p))
        cyl = trimesh.creation.cylinder(radius=0.025 * scale, height=length, sections=16)
        z = p / length
        x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
        x /= np.linalg.norm(x)
        rot = np.column_stack([x, np.cross(z, x), z])
        verts = np.asarray(cyl.vertices) @ rot.T + 0.5 * p
        visuals.append(Visual(body, verts, np.asarray(cyl.faces), (0.35, 0.38, 0.45), True))
    return visuals


def body_poses(model, u: np.ndarray) -> dict[str, np.ndarray]:
    """World pose (rows, 4, 4) of every body frame (origin at its centre of mass) from the
    Cartesian states ``u`` (rows, nq): position and Euler parameters (scalar first)."""
    out = {}
    for k, name in enumerate(model.body_names):
        e = u[:, 7 * k + 3 : 7 * k + 7]
        t = np.zeros((u.shape[0], 4, 4))
        t[:, :3, :3] = quat_to_rot(e / np.linalg.norm(e, axis=1, keepdims=True))
        t[:, :3, 3] = u[:, 7 * k : 7 * k + 3]
        t[:, 3, 3] = 1.0
        out[name] = t
    return out


# ---------------------------------------------------------------------------------------------


def frame_rows(t: np.ndarray, fps: float) -> np.ndarray:
    """Indices of the output rows shown: the first row, then each row at least 1/fps after the
    last one kept, and the last row (every row when the output is coarser than fps)."""
    keep = [0]
    step = 1.0 / fps
    for i in range(1, len(t)):
        if t[i] - t[keep[-1]] >= step * (1.0 - 1e-9):
            keep.append(i)
    if keep[-1] != len(t) - 1:
        keep.append(len(t) - 1)
    return np.asarray(keep)


def time_key(t: float) -> str:
    """The viewer's key of time ``t`` (shortest round-trip repr: float(key) == t)."""
    return repr(float(t))


def _shown_states(model, result, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, Cartesian states u) of the rows shown (:func:`frame_rows`), from a result's
    ``u`` or, for a joint-space one (``trajectory_run``: ``t``, ``q`` only), from its ``q``
    through :func:`armdyn.state_from_joints`."""
    name = type(result).__name__
    t = getattr(result, "t", None)
    u, q = getattr(result, "u", None), getattr(result, "q", None)
    if t is None or (u is None and q is None):
        raise _core.ModelError(
            "animate: result needs times t (n,) and Cartesian states u (n, nq) (simulate, "
            f"driven_inverse_dynamics) or joint coordinates q (trajectory_run); got {name}"
        )
    t = np.asarray(t, dtype=float)
    if u is not None:
        states, what, width = np.asarray(u, dtype=float), "u", model.nq
    else:
        states, what, width = np.asarray(q, dtype=float), "q", len(model.coord_names)
    if t.ndim != 1 or states.ndim != 2 or states.shape != (t.size, width):
        raise _core.ModelError(
            f"animate: result.{what} has shape {states.shape} for {t.shape} times, the model "
            f"needs ({t.size}, {width}): pass the model the run was made with"
        )
    if t.size == 0:
        error = getattr(result, "error", None)
        raise _core.ModelError("animate: the result has no rows" + (f" ({error})" if error else ""))
    finite = np.all(np.isfinite(states), axis=1) & np.isfinite(t)
    if not finite.all():
        bad = int(np.argmin(finite))
        raise _core.ModelError(f"animate: result has non-finite values at row {bad} (t = {t[bad]})")
    if np.any(np.diff(t) <= 0):
        bad = int(np.argmax(np.diff(t) <= 0)) + 1
        raise _core.ModelError(f"animate: result.t is not increasing at row {bad} (t = {t[bad]})")
    rows = frame_rows(t, fps)
    if what == "u":
        return t[rows], states[rows]
    return t[rows], np.array([_core.state_from_joints(model, qi)[0] for qi in states[rows]])


def _colour_int(c) -> int:
    r, g, b = (min(255, max(0, round(255 * float(x)))) for x in c[:3])
    return (r << 16) | (g << 8) | b


def animate(
    model: _core.Model,
    result: Any,
    path: str | os.PathLike[str],
    *,
    urdf: str | bytes | os.PathLike[str] | None = None,
    fps: float = 30.0,
    time: float | None = None,
    height: int = 600,
    grid: bool = True,
) -> Path:
    """Write the run ``result`` of ``model`` as one self-contained HTML file at ``path``.

    The page embeds the K3D viewer (WebGL; nothing is fetched when it is opened): drag to turn,
    scroll to zoom; *Controls → Animation* holds the time slider and *Play loop* (play/pause).
    Link geometry comes from the URDF's ``<visual>`` elements: meshes (STL, OBJ, DAE; ``scale``
    honoured, ``package://`` resolved from the URDF's folder and its parents, then
    ``ROS_PACKAGE_PATH``), boxes, cylinders and spheres, with their material colours. A model
    without a URDF, and each body none of whose links has a ``<visual>``, is drawn as the body's
    equivalent inertia box (the uniform box of the same mass and central inertia) with rods
    from its joints to its centre of mass.

    Args:
        model: the :class:`armdyn.Model` the run was made with.
        result: a :class:`SimulationResult`, :class:`InverseDynamicsResult` or anything with
            ``t`` (n,) and the Cartesian states ``u`` (n, model.nq); or a joint-space
            :class:`TrajectoryRun` (``t``, ``q`` (n, len(model.coord_names))).
        path: the HTML file to write.
        urdf: the URDF (a path, or the XML as str or UTF-8 bytes) of the link geometry;
            default: the one :func:`armdyn.load_urdf` loaded ``model`` from
            (:func:`armdyn.urdf.urdf_source`), else inertia boxes.
        fps: frames per second of simulated time kept (the output rows at least 1/fps apart,
            the first and the last; every row if the output is coarser). The viewer interpolates
            between frames when playing.
        time: the time shown when the page opens (default: the first output time).
        height: the viewer's height in pixels.
        grid: draw K3D's grid with axis ticks.

    Returns: the path written.

    Raises:
        ImportError: the ``viz`` extra (k3d, trimesh, pycollada) is not installed.
        ModelError: ``result`` does not belong to ``model``, has no rows, non-finite values or
            times that do not increase.
        UrdfError: a ``<visual>`` is malformed, a mesh is missing or unreadable, or a URDF link
            is not a frame of the model.
        ValueError: ``fps`` is not positive or ``time`` not finite.
    """
    _import_viewer()
    import k3d

    if isinstance(fps, bool) or not (
        isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0
    ):
        raise ValueError(f"animate: fps must be a positive number, got {fps!r}")
    if time is not None and not (isinstance(time, (int, float)) and math.isfinite(time)):
        raise ValueError(f"animate: time must be a finite number [s], got {time!r}")
    tr, ur = _shown_states(model, result, float(fps))
    source = urdf if urdf is not None else urdf_source(model)  # asked of the loader
    poses = {}
    if source is not None:
        visuals = urdf_visuals(source)
        frames = set(model.frame_names)
        missing = sorted({v.link for v in visuals} - frames)
        if missing:
            raise _core.UrdfError(
                f"animate: URDF link(s) {missing} are not frames of the model: is it the URDF "
                "the model was loaded from?"
            )
        poses = {
            (link, False): np.asarray(_core.frame_pose_cartesian(model, ur, link)).reshape(-1, 4, 4)
            for link in dict.fromkeys(v.link for v in visuals)
        }
        # bodies none of whose links has a <visual>: drawn as for a builder model
        drawn = {model.frame(v.link)["body"] for v in visuals}
        bare = [b for b in model.body_names if b not in drawn]
        if bare:
            visuals += builder_visuals(model, bare)
    else:
        visuals = builder_visuals(model)
    if any(v.body for v in visuals):
        poses.update({(b, True): t for b, t in body_poses(model, ur).items()})

    plot = k3d.plot(
        camera_up_axis="z",
        grid_visible=grid,
        height=int(height),
        time=float(tr[0] if time is None else time),
        name="armdyn",
    )
    for v in visuals:
        pose = poses[v.link, v.body]
        if np.all(pose == pose[0]):
            matrix = pose[0].astype(np.float32)
        else:
            matrix = {time_key(ti): pose[i].astype(np.float32) for i, ti in enumerate(tr)}
        obj = k3d.mesh(
            v.vertices.astype(np.float32),
            v.faces.astype(np.uint32),
            color=_colour_int(v.colour),
            name=v.link,
        )
        # a {time: matrix} dict is a K3D time series (set after construction: the factory's
        # model_matrix argument takes one matrix)
        obj.model_matrix = matrix
        plot += obj
    plot.snapshot_type = "full"
    html = plot.get_snapshot()
    out = Path(path)
    out.write_text(html, encoding="utf-8")
    return out
