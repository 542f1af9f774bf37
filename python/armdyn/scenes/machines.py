"""Closed-loop machines: a palletizing arm held level by parallelograms and a three-arm delta
robot, with their pick-and-place cycles (SI units, z up, gravity -z).

Each machine adds its ACTUATED joints first, so the default independent coordinates of a loop
model (the first independent joint coordinates in model order) are the actuated ones, and
``model.joint_names[:n]`` lists them (``PALLETIZER_ACTUATED``, ``DELTA_ACTUATED``). Joint
coordinates are 0 at the assembly pose documented per machine. ``palletizer_ik`` and
``delta_ik`` are the machines' closed-form inverse kinematics (no armdyn call), which the
cycles and the tests use. ``pick_and_place(machine)`` gives a cycle of
the actuated coordinates as an :class:`armdyn.motion.Trajectory`; ``drives=`` of each machine
takes it (or a dict of profiles per actuated joint) to build the fully driven model that
``armdyn.driven_inverse_dynamics`` and ``armdyn.simulate`` take."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core

if TYPE_CHECKING:
    from armdyn.motion import Trajectory


PALLETIZER_ACTUATED = ("yaw", "shoulder", "elbow", "wrist")
DELTA_ACTUATED = ("arm1", "arm2", "arm3")


def _rod_inertia(mass: float, length: float, radius: float, axis) -> np.ndarray:
    """Inertia (3, 3) about the centre of a solid cylinder along unit `axis` (world axes)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    ia = 0.5 * mass * radius**2
    it = mass * (3 * radius**2 + length**2) / 12.0
    return it * (np.eye(3) - np.outer(a, a)) + ia * np.outer(a, a)


def _box_inertia(mass: float, size) -> np.ndarray:
    x, y, z = size
    return np.diag([y * y + z * z, x * x + z * z, x * x + y * y]) * mass / 12.0


def _lump(parts) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia (3,3) about it) of parts (mass, position, inertia about
    the part's own centre; None: a point mass), all in world axes."""
    m = sum(p[0] for p in parts)
    c = sum(p[0] * np.asarray(p[1], float) for p in parts) / m
    inertia = np.zeros((3, 3))
    for mi, pi, ii in parts:
        r = np.asarray(pi, float) - c
        inertia += (np.zeros((3, 3)) if ii is None else ii) + mi * (
            r @ r * np.eye(3) - np.outer(r, r)
        )
    return m, c, inertia


def _add(b: _core.ModelBuilder, name: str, parts) -> None:
    m, c, inertia = _lump(parts)
    b.add_body(name, m, inertia, position=c)


def _check_fields(who: str, name: str, obj: Any, signed: tuple[str, ...] = ()) -> None:
    """Every number of a geometry / masses dataclass finite, and positive unless in `signed`."""
    from dataclasses import fields

    for f in fields(obj):
        values = getattr(obj, f.name)
        for k, v in enumerate(values if isinstance(values, tuple) else (values,)):
            label = f"{name}.{f.name}" + (f"[{k}]" if isinstance(values, tuple) else "")
            if f.name in signed:
                _checks.number(who, label, v)
            else:
                _checks.number(who, label, v, lo=0.0, lo_open=True)


def _points(who: str, name: str, value: Any) -> np.ndarray:
    """(n, 3) finite points from (3,) or (n, 3)."""
    x = np.asarray(_checks.array(who, name, value, finite=True), float)
    if x.shape[-1:] != (3,) or x.ndim not in (1, 2):
        raise _core.ModelError(f"{who}: {name} must have shape (3,) or (n, 3), got {x.shape}")
    return np.atleast_2d(x)


def _add_torques(b: _core.ModelBuilder, torques: Any, actuated: tuple[str, ...]) -> None:
    if torques is None:
        return
    if not isinstance(torques, Mapping):
        raise _core.ModelError("torques must be None or a dict {actuated joint: profile}")
    for joint, profile in torques.items():
        if joint not in actuated:
            raise _core.ModelError(f"torques: {joint!r} is not an actuated joint {list(actuated)}")
        b.add_joint_torque(joint, profile)


def _add_drives(b: _core.ModelBuilder, drives: Any, actuated: tuple[str, ...]) -> None:
    if drives is None:
        return
    from armdyn.motion import Trajectory, drive_profile

    if isinstance(drives, Trajectory):
        if drives.q.shape[1] != len(actuated):
            raise _core.ModelError(
                f"drives: a trajectory of {drives.q.shape[1]} columns; the machine has "
                f"{len(actuated)} actuated joints {list(actuated)}"
            )
        fast = drives.info.get("profiles")
        if isinstance(fast, Mapping) and tuple(fast) == tuple(actuated):
            drives = fast  # a pick_and_place cycle: its exact splines
        else:
            drives = {j: drive_profile(drives, i) for i, j in enumerate(actuated)}
    if not isinstance(drives, Mapping):
        raise _core.ModelError("drives must be None, an armdyn.motion.Trajectory or a dict")
    for joint, profile in drives.items():
        if joint not in actuated:
            raise _core.ModelError(f"drives: {joint!r} is not an actuated joint {list(actuated)}")
        b.add_drive(joint, profile)


# ---------------------------------------------------------------------------------------------
# Palletizer


@dataclass(frozen=True)
class PalletizerGeometry:
    """The palletizer's dimensions [m] (assembly pose: lower arm vertical, upper arm
    horizontal, pointing along +x; every planar joint's axis is the turret's y axis).

    shoulder: the shoulder (and elbow actuator) axis point S in the turret, (x, z).
    lower: lower arm length |SE| (E the elbow pin); upper: upper arm length |EW| (W the wrist
    pin); rear: the upper arm's rear lever |ER| behind E, driven by the elbow parallelogram;
    level_back: the wrist-level parallelogram's turret lever (along -x from S and from E);
    level_up: the bell crank's upper lever (along +z from E and from W); flange_drop: the flange
    (wrist yaw joint) below W; tool_drop: the tool point below the flange. Every number
    positive and finite (else a ModelError naming the field)."""

    shoulder: tuple[float, float] = (0.25, 0.65)
    lower: float = 1.0
    upper: float = 1.2
    rear: float = 0.3
    level_back: float = 0.25
    level_up: float = 0.25
    flange_drop: float = 0.25
    tool_drop: float = 0.15

    def points(self) -> dict[str, np.ndarray]:
        """Every joint point of the assembly pose (world, y = 0 plane of the turret)."""
        s = np.array([self.shoulder[0], 0.0, self.shoulder[1]])
        e = s + np.array([0.0, 0.0, self.lower])
        w = e + np.array([self.upper, 0.0, 0.0])
        r = e - np.array([self.rear, 0.0, 0.0])
        back = np.array([-self.level_back, 0.0, 0.0])
        up = np.array([0.0, 0.0, self.level_up])
        f = w - [0.0, 0.0, self.flange_drop]
        return dict(
            S=s, E=e, W=w, R=r, C=s + (r - e), T=s + back, B1=e + back, B2=e + up,
            W2=w + up, F=f, tool=f - [0.0, 0.0, self.tool_drop],
        )  # fmt: skip


@dataclass(frozen=True)
class PalletizerMasses:
    """Masses [kg] of the palletizer's bodies (the links as solid cylinders of `radius` [m]),
    each positive and finite."""

    turret: float = 80.0
    lower: float = 30.0
    upper: float = 25.0
    crank: float = 6.0
    elbow_rod: float = 4.0
    level_rod: float = 2.0
    bell: float = 3.0
    wrist: float = 6.0
    flange: float = 10.0
    radius: float = 0.06


def palletizer(
    *,
    payload: float = 20.0,
    closure: str = "inline",
    drives: Trajectory | Mapping[str, Any] | None = None,
    torques: Mapping[str, Any] | None = None,
    geometry: PalletizerGeometry | None = None,
    masses: PalletizerMasses | None = None,
    gravity: float = 9.81,
) -> _core.Model:
    """A four-axis palletizing arm (yaw, shoulder, elbow, wrist) whose upper arm is driven
    through a parallelogram and whose wrist a second pair of parallelograms holds level.

    Actuated joints, added first (``PALLETIZER_ACTUATED``): ``yaw`` (ground → turret about z at
    the origin), ``shoulder`` (turret → lower arm about the turret's y axis at S; positive leans
    the lower arm forward), ``elbow`` (turret → crank, coaxial with the shoulder; the crank, the
    elbow rod and the upper arm's rear lever form a parallelogram with the lower arm, so the
    elbow coordinate is the upper arm's pitch below the horizontal, positive down, whatever
    the shoulder does) and ``wrist`` (wrist → flange about the vertical at F). The wrist-level
    linkage: a level rod from the turret (T) to a bell crank pivoting about the elbow axis on
    the lower arm, parallel to the lower arm, and a second rod from the bell crank to the wrist,
    parallel to the upper arm: the bell crank keeps the turret's orientation and the wrist the
    bell crank's, so the flange axis stays vertical. Passive joints: ``elbow_pin`` (lower →
    upper arm at E), ``crank_pin`` (crank → elbow rod at C), ``bell_pin`` (lower arm → bell crank
    at E), ``level_pin`` (turret → level rod 1 at T), ``bell_rod`` (bell crank → level rod 2 at
    B2), ``wrist_pin`` (upper arm → wrist at W) and three loop closures, ``rear_pin`` (elbow
    rod → upper arm at R), ``bell_link`` (level rod 1 → bell crank at B1), ``wrist_link`` (level
    rod 2 → wrist at W2). ``closure="inline"`` (the default) closes them with inline joints (2
    rows each: no redundant row, the sparse KKT path), ``"revolute"`` with revolutes (5 rows, 3 of
    them redundant, as real pins; dense minimum-norm multipliers); the motion and the actuator
    torques are the same. Mobility 4. Points: :meth:`PalletizerGeometry.points`; frame
    ``tool`` on the flange, ``payload`` [kg] a point mass at it. Rods are offset along the pin
    axes (elbow rod at y = -0.15, level rods at y = +0.15). ``drives``: a trajectory of the four
    actuated coordinates (``pick_and_place("palletizer")``) or ``{joint: profile}``; ``torques``:
    ``{actuated joint: profile}`` applied as ``add_joint_torque`` (a forward run)."""
    closure = _checks.choice("palletizer", "closure", closure, ("inline", "revolute"))
    who = "palletizer"
    g = geometry or PalletizerGeometry()
    m = masses or PalletizerMasses()
    _check_fields(who, "geometry", g)
    _check_fields(who, "masses", m)
    payload = _checks.number(who, "payload", payload, lo=0.0)
    gravity = _checks.number(who, "gravity", gravity)
    p = g.points()
    rad = m.radius
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -gravity))
    ey, ez = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    ex = np.array([1.0, 0.0, 0.0])
    side_e, side_l = -0.15 * ey, 0.15 * ey

    def rod(a, c):
        return (np.asarray(a) + np.asarray(c)) / 2, _rod_inertia(
            1.0, np.linalg.norm(c - a), rad, c - a
        )

    def part(mass, a, c):
        centre, unit = rod(a, c)
        return (mass, centre, mass * unit)

    turret_centre = np.array([0.0, 0.0, 0.5 * p["S"][2]])
    _add(b, "turret", [(m.turret, turret_centre, _box_inertia(m.turret, (0.6, 0.5, p["S"][2])))])
    _add(b, "lower_arm", [part(m.lower, p["S"], p["E"])])
    _add(b, "crank", [part(m.crank, p["S"] + side_e, p["C"] + side_e)])
    flange_parts = [part(m.flange, p["F"], p["tool"])]
    if payload > 0:
        flange_parts.append((payload, p["tool"], None))
    _add(b, "flange", flange_parts)
    _add(b, "wrist", [part(m.wrist, p["W2"], p["F"])])
    _add(b, "upper_arm", [part(m.upper, p["R"], p["W"])])
    _add(b, "elbow_rod", [part(m.elbow_rod, p["C"] + side_e, p["R"] + side_e)])
    _add(b, "level_rod1", [part(m.level_rod, p["T"] + side_l, p["B1"] + side_l)])
    bell = _rod_inertia(m.bell, g.level_back + g.level_up, rad, ex - ez)
    _add(b, "bell", [(m.bell, (p["E"] + p["B1"] + p["B2"]) / 3 + side_l, bell)])
    _add(b, "level_rod2", [part(m.level_rod, p["B2"] + side_l, p["W2"] + side_l)])
    # actuated joints first
    b.add_revolute("yaw", "ground", "turret", point=(0, 0, 0), axis=ez)
    b.add_revolute("shoulder", "turret", "lower_arm", point=p["S"], axis=ey)
    b.add_revolute("elbow", "turret", "crank", point=p["S"] + side_e, axis=ey)
    b.add_revolute("wrist", "wrist", "flange", point=p["F"], axis=ez)
    # the tree of passive joints
    b.add_revolute("elbow_pin", "lower_arm", "upper_arm", point=p["E"], axis=ey)
    b.add_revolute("crank_pin", "crank", "elbow_rod", point=p["C"] + side_e, axis=ey)
    b.add_revolute("bell_pin", "lower_arm", "bell", point=p["E"] + side_l, axis=ey)
    b.add_revolute("level_pin", "turret", "level_rod1", point=p["T"] + side_l, axis=ey)
    b.add_revolute("bell_rod", "bell", "level_rod2", point=p["B2"] + side_l, axis=ey)
    b.add_revolute("wrist_pin", "upper_arm", "wrist", point=p["W"], axis=ey)
    # loop closures
    close = b.add_revolute if closure == "revolute" else b.add_inline
    close("rear_pin", "elbow_rod", "upper_arm", point=p["R"] + side_e, axis=ey)
    close("bell_link", "level_rod1", "bell", point=p["B1"] + side_l, axis=ey)
    close("wrist_link", "level_rod2", "wrist", point=p["W2"] + side_l, axis=ey)
    b.add_frame("tool", "flange", position=p["tool"])
    _add_drives(b, drives, PALLETIZER_ACTUATED)
    _add_torques(b, torques, PALLETIZER_ACTUATED)
    return b.finalize()


def palletizer_ik(
    tool: npt.ArrayLike, tool_yaw: float = 0.0, geometry: PalletizerGeometry | None = None
) -> np.ndarray:
    """The actuated coordinates (yaw, shoulder, elbow, wrist) that put the tool point at `tool`
    (world, (3,) or (n, 3)) with the flange turned by `tool_yaw` [rad] about the vertical from
    its assembly heading (closed form: the wrist is level, so the wrist pin is `flange_drop +
    tool_drop` above the tool; the elbow on the upper branch, as assembled). SolverError naming
    the first row out of reach; ModelError for a point that is not finite."""
    who = "palletizer_ik"
    g = geometry or PalletizerGeometry()
    _check_fields(who, "geometry", g)
    tool_yaw = _checks.number(who, "tool_yaw", tool_yaw)
    p = g.points()
    x = _points(who, "tool", tool)
    yaw = np.arctan2(x[:, 1], x[:, 0])
    r = np.hypot(x[:, 0], x[:, 1])
    wr = r - p["S"][0]
    wz = x[:, 2] + g.flange_drop + g.tool_drop - p["S"][2]
    d = np.hypot(wr, wz)
    out = (d > g.lower + g.upper) | (d < abs(g.lower - g.upper)) | (d <= 0.0)
    if np.any(out):
        row = int(np.argmax(out))
        raise _core.SolverError(f"{who}: tool point {row} {x[row].tolist()} is out of reach")
    along = (g.lower**2 - g.upper**2 + d**2) / (2 * d)
    h = np.sqrt(g.lower**2 - along**2)
    er = along * wr / d - h * wz / d  # the elbow, left of S -> W (the upper branch)
    ez = along * wz / d + h * wr / d
    shoulder = np.arctan2(er, ez)
    elbow = np.arctan2(-(wz - ez), wr - er)
    q = np.column_stack([yaw, shoulder, elbow, tool_yaw - yaw])
    return q[0] if np.ndim(tool) == 1 else q


# ---------------------------------------------------------------------------------------------
# Delta robot


@dataclass(frozen=True)
class DeltaGeometry:
    """The delta robot's dimensions [m] and masses [kg].

    base: radius of the arms' pivots; plate: radius of the forearms' attachments on the
    travelling plate; arm: upper arm length (pivot to elbow); rod: forearm rod length; spacing:
    half the distance between a forearm's two parallel rods (along the pivot axis); theta0:
    the upper arms' assembly angle below the horizontal [rad]. arm_mass (a solid cylinder of
    `radius`), elbow_mass (a point mass at the elbow: the lumped share of the forearm), plate_mass
    (a disc of radius `plate`, with the forearms' other share). Every number finite, all but
    theta0 positive, and the rods longer than the elbows' horizontal reach beyond the plate."""

    base: float = 0.2
    plate: float = 0.05
    arm: float = 0.35
    rod: float = 0.8
    spacing: float = 0.04
    theta0: float = 0.5
    arm_mass: float = 1.2
    elbow_mass: float = 0.15
    plate_mass: float = 0.6
    radius: float = 0.02

    def directions(self) -> tuple[np.ndarray, np.ndarray]:
        """(radial, axis): (3, 3) rows per arm: the arm's outward direction and pivot axis."""
        phi = np.deg2rad([0.0, 120.0, 240.0])
        radial = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(3)])
        axis = np.column_stack([-np.sin(phi), np.cos(phi), np.zeros(3)])
        return radial, axis

    def plate_z(self) -> float:
        """The plate's centre height at the assembly pose (below the base: negative)."""
        reach = self.base + self.arm * np.cos(self.theta0) - self.plate
        return -self.arm * np.sin(self.theta0) - np.sqrt(self.rod**2 - reach**2)

    def arm_inertia(self) -> float:
        """Moment of inertia [kg m²] of an upper arm (with its elbow mass) about its pivot."""
        rod = self.arm_mass * (self.radius**2 / 4 + self.arm**2 / 3)
        return rod + self.elbow_mass * self.arm**2

    def arm_moment(self) -> float:
        """First moment [kg m] of an upper arm with its elbow mass about its pivot."""
        return self.arm_mass * self.arm / 2 + self.elbow_mass * self.arm


def _check_geometry(who: str, g: DeltaGeometry) -> None:
    _check_fields(who, "geometry", g, signed=("theta0",))
    if g.base + g.arm * np.cos(g.theta0) - g.plate >= g.rod:
        raise _core.ModelError(
            f"{who}: geometry.rod ({g.rod:g} m) must exceed the horizontal reach of the elbow "
            f"beyond the plate, base + arm cos(theta0) - plate = "
            f"{g.base + g.arm * np.cos(g.theta0) - g.plate:g} m"
        )


def delta_robot(
    *,
    drives: Trajectory | Mapping[str, Any] | None = None,
    torques: Mapping[str, Any] | None = None,
    geometry: DeltaGeometry | None = None,
    gravity: float = 9.81,
) -> _core.Model:
    """A three-arm delta robot (Clavel): three upper arms on revolutes ``arm1``..``arm3`` (the
    actuated joints, added first: ground → upper arm ``arm<i>`` at the base pivot
    ``base (cos φ, sin φ, 0)``, φ = 0°, 120°, 240°, about the tangent (-sin φ, cos φ, 0);
    positive swings the arm down), each joined to the travelling plate by a forearm of two
    parallel rods of length ``rod`` (``add_distance``: massless rods with ball ends, ``rod<i>a``
    and ``rod<i>b``, ``spacing`` either side of the arm's plane). The three parallelograms keep
    the plate from turning: it translates (mobility 3). The forearms' mass is lumped (the usual
    simplified delta model): ``elbow_mass`` at each elbow, the rest in ``plate_mass``. The plate
    body ``plate`` is held by the rods alone; frame ``tool`` at its centre. Assembly: upper arms
    ``theta0`` below the horizontal, the plate centred under the base at ``plate_z()``.
    ``drives``: a trajectory of the three arm angles (``pick_and_place("delta")``) or
    ``{joint: profile}``; ``torques``: ``{arm joint: profile}`` applied as ``add_joint_torque``."""
    who = "delta_robot"
    g = geometry or DeltaGeometry()
    _check_geometry(who, g)
    gravity = _checks.number(who, "gravity", gravity)
    radial, axis = g.directions()
    down = np.array([0.0, 0.0, -1.0])
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -gravity))
    plate = np.array([0.0, 0.0, g.plate_z()])
    elbows = []
    for i in range(3):
        pivot = g.base * radial[i]
        along = np.cos(g.theta0) * radial[i] + np.sin(g.theta0) * down
        elbow = pivot + g.arm * along
        elbows.append(elbow)
        rod = (
            g.arm_mass,
            pivot + g.arm * along / 2,
            _rod_inertia(g.arm_mass, g.arm, g.radius, along),
        )
        _add(b, f"upper_arm{i + 1}", [rod, (g.elbow_mass, elbow, None)])
    disc = g.plate_mass * g.plate**2 / 4 * np.diag([1.0, 1.0, 2.0])
    b.add_body("plate", g.plate_mass, disc, position=plate)
    for i in range(3):
        pivot = g.base * radial[i]
        b.add_revolute(f"arm{i + 1}", "ground", f"upper_arm{i + 1}", point=pivot, axis=axis[i])
    for i in range(3):
        for tag, sign in (("a", 1.0), ("b", -1.0)):
            off = sign * g.spacing * axis[i]
            b.add_distance(
                f"rod{i + 1}{tag}", f"upper_arm{i + 1}", elbows[i] + off, "plate",
                plate + g.plate * radial[i] + off,
            )  # fmt: skip
    b.add_frame("tool", "plate", position=plate)
    _add_drives(b, drives, DELTA_ACTUATED)
    _add_torques(b, torques, DELTA_ACTUATED)
    return b.finalize()


def _delta_branch(g: DeltaGeometry, k, rho, z) -> np.ndarray:
    r = np.hypot(rho, z)
    phi = np.arctan2(z, rho)
    return -phi - np.arccos(np.clip(k / r, -1.0, 1.0))


def delta_ik(plate: npt.ArrayLike, geometry: DeltaGeometry | None = None) -> np.ndarray:
    """The arm coordinates (arm1, arm2, arm3) [rad] (0 at the assembly pose) that put the plate's
    centre at `plate` ((3,) or (n, 3), world), on the assembly's branch (elbows outward); closed
    form. SolverError naming the first row out of reach; ModelError for a point that is not
    finite."""
    who = "delta_ik"
    g = geometry or DeltaGeometry()
    _check_geometry(who, g)
    radial, _ = g.directions()
    x = _points(who, "plate", plate)
    q = np.empty((x.shape[0], 3))
    for i in range(3):
        d = x + g.plate * radial[i] - g.base * radial[i]
        rho, z = d @ radial[i], d[:, 2]
        k = (g.arm**2 + np.sum(d * d, axis=1) - g.rod**2) / (2 * g.arm)
        out = np.abs(k) > np.hypot(rho, z)
        if np.any(out):
            row = int(np.argmax(out))
            raise _core.SolverError(
                f"{who}: plate position {row} {x[row].tolist()} is out of reach of arm{i + 1}"
            )
        # rho cos(t) - z sin(t) = k, t the angle below the horizontal
        q[:, i] = _delta_branch(g, k, rho, z) - g.theta0
    return q[0] if np.ndim(plate) == 1 else q


# ---------------------------------------------------------------------------------------------
# Pick-and-place cycles

_CYCLES = {
    # tool points (world) above the pick, at the pick, above the place, at the place; flange
    # yaw at the pick and at the place; limits (velocity, acceleration, jerk) per joint; the
    # dwell [s] at the pick and at the place
    "palletizer": dict(
        above_pick=(1.3, -0.6, 0.9), pick=(1.3, -0.6, 0.6), above_place=(0.8, 1.2, 0.9),
        place=(0.8, 1.2, 0.5), yaw=(0.0, np.pi / 2), limits=(2.0, 6.0, 40.0), dwell=0.3,
    ),
    "delta": dict(
        above_pick=(-0.1525, 0.0, -0.825), pick=(-0.1525, 0.0, -0.85),
        above_place=(0.1525, 0.0, -0.825), place=(0.1525, 0.0, -0.85),
        limits=(10.0, 150.0, 4000.0), dwell=0.05,
    ),
}  # fmt: skip

# the peaks of s_curve's velocity, acceleration and jerk (per unit move and duration)
_S_PEAKS = (2.0, 8.0, 32.0)


def s_curve(tau: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cycles' rest-to-rest shape s(tau), s'(tau), s''(tau) for tau in [0, 1] (clipped): a
    piecewise cubic with constant jerk +32, -32, +32 on [0, 1/4], [1/4, 3/4], [3/4, 1], from
    s = 0 to 1 with zero velocity and acceleration at both ends (peaks |s'| = 2, |s''| = 8).
    s'' is continuous, so the natural cubic spline through its values at the quarter points
    reproduces it exactly."""
    tau = np.clip(np.asarray(tau, float), 0.0, 1.0)
    h = tau - 0.25
    r = 1.0 - tau
    first, last = tau <= 0.25, tau >= 0.75
    middle = 1 / 12 + h + 4 * h**2 - 16 / 3 * h**3
    pos = np.where(first, 16 / 3 * tau**3, np.where(last, 1 - 16 / 3 * r**3, middle))
    vel = np.where(first, 16 * tau**2, np.where(last, 16 * r**2, 1 + 8 * h - 16 * h**2))
    acc = np.where(first, 32 * tau, np.where(last, -32 * r, 8 - 32 * h))
    return pos, vel, acc


@dataclass(frozen=True)
class _Moves:
    """Rest-to-rest straight moves in joint space between waypoints (m, n), each of its own
    duration (a dwell: a move of zero length), shaped by :func:`s_curve`."""

    points: np.ndarray
    durations: np.ndarray

    @property
    def starts(self) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(self.durations)])

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.atleast_1d(np.asarray(t, float))
        starts = self.starts
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.durations) - 1)
        span = self.durations[k][:, None]
        step = self.points[k + 1] - self.points[k]
        pos, vel, acc = s_curve((t - starts[k]) / self.durations[k])
        q = self.points[k] + pos[:, None] * step
        return q, vel[:, None] * step / span, acc[:, None] * step / span**2

    def knots(self) -> np.ndarray:
        """Every time where the jerk may change (the moves' ends and quarter points)."""
        starts = self.starts
        inner = starts[:-1, None] + self.durations[:, None] * np.array([0.25, 0.5, 0.75])
        return np.union1d(starts, inner.ravel())


def _timed(points: np.ndarray, limits, dwell_after: dict) -> _Moves:
    """The moves through `points`, each as short as the per-joint limits (velocity,
    acceleration, jerk) allow for the shape, with a dwell after the waypoints in `dwell_after`
    (index -> seconds)."""
    v, a, j = limits
    peak_v, peak_a, peak_j = _S_PEAKS
    pts, durations = [points[0]], []
    for k in range(len(points) - 1):
        d = np.abs(points[k + 1] - points[k]).max()
        durations.append(max(peak_v * d / v, np.sqrt(peak_a * d / a), np.cbrt(peak_j * d / j)))
        pts.append(points[k + 1])
        if k + 1 in dwell_after:
            durations.append(dwell_after[k + 1])
            pts.append(points[k + 1])
    return _Moves(np.array(pts), np.array(durations))


def _waypoints(machine: str):
    """(names, joint waypoints (8, n) from home to home, tool waypoints (8, 3))."""
    c = _CYCLES[machine]
    order = ["above_pick", "pick", "above_pick", "above_place", "place", "above_place"]
    tool = np.array([c[k] for k in order], float)
    if machine == "palletizer":
        yaw = np.array([c["yaw"][0 if "pick" in k else 1] for k in order])
        inner = np.vstack([palletizer_ik(x, y) for x, y in zip(tool, yaw, strict=True)])
        home = PalletizerGeometry().points()["tool"]
        names = PALLETIZER_ACTUATED
    else:
        inner = delta_ik(tool)
        home = np.array([0.0, 0.0, DeltaGeometry().plate_z()])
        names = DELTA_ACTUATED
    zero = np.zeros((1, len(names)))
    return names, np.vstack([zero, inner, zero]), np.vstack([home, tool, home])


def pick_and_place(
    machine: str,
    *,
    max_velocity: float | None = None,
    max_acceleration: float | None = None,
    max_jerk: float | None = None,
    dwell: float | None = None,
    dt: float = 1e-3,
) -> Trajectory:
    """One pick-and-place cycle of `machine` (``"palletizer"`` or ``"delta"``) in its actuated
    coordinates: from rest at the assembly pose (all coordinates 0: the home), to above the
    pick, down to the pick, a `dwell` (the gripper), up, across to above the place, down to the
    place, a dwell, up, and back home, stopping at each waypoint. Each move is a straight line in
    joint space shaped by :func:`s_curve` (jerk-limited, constant jerk per quarter), as short as
    the per-joint limits allow (rad/s, rad/s², rad/s³; default: palletizer 2, 6, 40 with a 0.3 s
    dwell; delta 10, 150, 4000 with 0.05 s). The waypoints come from the closed-form inverse
    kinematics of the default geometry (``palletizer_ik``: the tool from above (1.3, -0.6, 0.6)
    m to above (0.8, 1.2, 0.5) m, 0.3 m / 0.4 m lifts, the flange turned by 90°; ``delta_ik``:
    the plate through the Adept-style cycle, 25 mm up, 305 mm across at z = -0.825 m, 25 mm
    down).

    Returns an :class:`armdyn.motion.Trajectory` on a `dt` grid with the exact ``evaluate``,
    ``names`` the actuated joints (``PALLETIZER_ACTUATED`` / ``DELTA_ACTUATED``) and in ``info``:
    ``tool`` (8, 3) the tool (plate) waypoints, ``waypoint_times`` (8,) when the cycle arrives
    at them (the dwells follow), ``knots`` and ``profiles``: per actuated joint an
    ``armdyn.profiles.spline`` through the knots, which is the motion exactly (a C2 piecewise
    cubic with zero end accelerations is the natural spline through its knots) and runs in
    C++; ``palletizer(drives=traj)`` / ``delta_robot(drives=traj)`` drive them."""
    from armdyn.motion import Trajectory

    who = "pick_and_place"
    machine = _checks.choice(who, "machine", machine, sorted(_CYCLES))
    given = [
        _checks.number(who, name, value, lo=0.0, lo_open=True, none=True)
        for name, value in (
            ("max_velocity", max_velocity), ("max_acceleration", max_acceleration),
            ("max_jerk", max_jerk),
        )
    ]  # fmt: skip
    rest = _checks.number(who, "dwell", dwell, lo=0.0, none=True)
    dt = float(_checks.number(who, "dt", dt, lo=0.0, lo_open=True))  # type: ignore[arg-type]
    names, points, tool = _waypoints(machine)
    limits = tuple(
        d if x is None else x for x, d in zip(given, _CYCLES[machine]["limits"], strict=True)
    )
    rest = _CYCLES[machine]["dwell"] if rest is None else rest
    moves = _timed(points, limits, {2: rest, 5: rest} if rest > 0 else {})
    starts = moves.starts
    moving = np.any(moves.points[1:] != moves.points[:-1], axis=1)
    arrive = np.concatenate([[0.0], starts[1:][moving]])
    if starts[-1] / dt > 1e7:
        raise _core.ModelError(f"{who}: dt = {dt:g} s gives more than 1e7 samples of the cycle")
    grid = np.append(np.arange(0.0, starts[-1], dt), starts[-1])
    q, qd, qdd = moves.evaluate(grid)
    knots = moves.knots()
    at_knots = moves.evaluate(knots)[0]
    profiles = {n: _core.profiles.spline(knots, at_knots[:, i]) for i, n in enumerate(names)}
    info = dict(
        method="pick_and_place", machine=machine, tool=tool, waypoint_times=arrive,
        knots=knots, profiles=profiles, limits=limits, dwell=rest,
    )  # fmt: skip
    return Trajectory(grid, q, qd, qdd, names=names, info=info, evaluate=moves.evaluate)
