"""Classic small mechanisms, built with :class:`armdyn.ModelBuilder` (SI units, z up)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from armdyn import _core


def _sphere(mass: float, radius: float) -> list[float]:
    i = 0.4 * mass * radius**2
    return [i, i, i]


def _rod(mass: float, length: float, radius: float, axis: int) -> list[float]:
    """Principal inertias of a solid cylinder along body axis `axis`."""
    ia = 0.5 * mass * radius**2
    it = mass * (3 * radius**2 + length**2) / 12.0
    d = [it, it, it]
    d[axis] = ia
    return d


def simple_pendulum(
    length: float = 1.0,
    mass: float = 1.0,
    theta0: float = 0.0,
    radius: float = 1e-3,
    gravity: float = 9.81,
) -> _core.Model:
    """Bob (a small sphere) on a revolute joint about world y at the origin.

    The angle is measured from the downward vertical; the bob starts at `theta0` [rad].
    Returns the finalized model (one joint coordinate, 0 at the start pose).
    """
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -gravity))
    pos = (length * np.sin(theta0), 0.0, -length * np.cos(theta0))
    b.add_body("bob", mass, _sphere(mass, radius), position=pos)
    b.add_revolute("pivot", "ground", "bob", point=(0, 0, 0), axis=(0, 1, 0))
    return b.finalize()


def double_pendulum(
    l1: float = 1.0,
    l2: float = 0.8,
    m1: float = 1.0,
    m2: float = 0.7,
    theta1: float = np.pi / 2,
    theta2: float = np.pi / 2,
) -> _core.Model:
    """Planar double pendulum of slender rods in the x–z plane, both released horizontal."""
    b = _core.ModelBuilder()
    p1 = np.array([np.sin(theta1), 0, -np.cos(theta1)])
    p2 = np.array([np.sin(theta2), 0, -np.cos(theta2)])
    elbow = l1 * p1

    # rods along body x: orientation turning body x onto the rod direction (about -y)
    def orient(direction):
        ang = np.arctan2(-direction[2], direction[0])
        return (np.cos(ang / 2), 0.0, np.sin(ang / 2), 0.0)

    b.add_body("link1", m1, _rod(m1, l1, 0.01, 0), position=0.5 * l1 * p1, orientation=orient(p1))
    b.add_body(
        "link2", m2, _rod(m2, l2, 0.01, 0), position=elbow + 0.5 * l2 * p2, orientation=orient(p2)
    )
    b.add_revolute("shoulder", "ground", "link1", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_revolute("elbow", "link1", "link2", point=elbow, axis=(0, 1, 0))
    return b.finalize()


def free_body(inertia: npt.ArrayLike = (1.0, 2.0, 3.0), mass: float = 1.0) -> _core.Model:
    """A torque-free rigid body (no gravity) with principal inertias `inertia` in body axes."""
    b = _core.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("body", mass, list(inertia))
    b.add_free("float", "body")
    return b.finalize()


def slider_crank(
    crank: float = 0.1, rod: float = 0.35, speed: float = 2 * np.pi, drive: bool = True
) -> _core.Model:
    """Planar slider-crank in the x–y plane (axes along z): crank about the origin, connecting rod,
    slider on a prismatic joint along x. A closed loop: 3 bodies, 4 joints. With `drive` the
    crank angle follows `speed * t` (a linear spline, extrapolated)."""
    b = _core.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    a = np.array([crank, 0, 0])
    s = np.array([crank + rod, 0, 0])
    b.add_body("crank", 1.0, _rod(1.0, crank, 0.01, 0), position=a / 2)
    b.add_body("rod", 0.5, _rod(0.5, rod, 0.01, 0), position=(a + s) / 2)
    b.add_body("slider", 2.0, [1e-3, 1e-3, 1e-3], position=s)
    b.add_revolute("crank_pin", "ground", "crank", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("crank_rod", "crank", "rod", point=a, axis=(0, 0, 1))
    b.add_revolute("rod_slider", "rod", "slider", point=s, axis=(0, 0, 1))
    b.add_prismatic("guide", "ground", "slider", point=s, axis=(1, 0, 0))
    if drive:
        b.add_drive("crank_pin", _core.profiles.spline([0.0, 1.0], [0.0, speed]))
    return b.finalize()


def four_bar(
    a: float = 0.3,
    b_len: float = 0.6,
    c: float = 0.5,
    d: float = 0.7,
    five_revolutes: bool = False,
    crank_angle: float = np.pi / 3,
    crank_drive: _core.Profile | float | None = None,
    gravity: float = 9.81,
    closure: str = "revolute",
    crank_torque: _core.Profile | float | None = None,
) -> _core.Model:
    """Planar four-bar (crank a, coupler b, rocker c, ground d) modelled in 3-D with revolute
    joints, all axes along z, gravity along -y: 3 moving bodies, 4 revolutes = 20 rows of rank 17,
    mobility 1, so 3 rows are redundant. With `five_revolutes` the crank bearing is doubled (a
    second, coaxial revolute "A2" between ground and crank, as real bearings often are): 25 rows,
    still rank 17 and mobility 1. `crank_drive` (a profile of the crank joint "A", relative to the
    start angle) prescribes the crank. With a = c and b = d the linkage is a parallelogram whose
    links all become collinear at crank angles 0 and π (its change points). ``closure="inline"``
    closes the loop at D with an inline joint (2 rows) instead of a revolute: 17 independent
    rows, no redundancy, the same motion. `crank_torque` (a profile, number or callable, as
    ``add_joint_torque`` takes) applies a torque to the crank about z. The links are solid
    cylinders of radius 0.01 m whose axes are along z (so each turns about its own axis):
    crank 1 kg, coupler 2 kg, rocker 1.5 kg, centres of mass at the links' midpoints, moment of
    inertia about z 0.5 m r²."""
    bld = _core.ModelBuilder(gravity=(0.0, -gravity, 0.0))
    pa = np.array([a * np.cos(crank_angle), a * np.sin(crank_angle), 0.0])
    pd = np.array([d, 0.0, 0.0])
    # coupler/rocker joint: intersection of the circles |p - pa| = b and |p - pd| = c
    dist = np.linalg.norm(pd - pa)
    x = (b_len**2 - c**2 + dist**2) / (2 * dist)
    h = np.sqrt(b_len**2 - x**2)
    e = (pd - pa) / dist
    pb = pa + x * e + h * np.array([-e[1], e[0], 0.0])
    z = (0, 0, 1)
    bld.add_body("crank", 1.0, _rod(1.0, a, 0.01, 2), position=pa / 2)
    bld.add_body("coupler", 2.0, _rod(2.0, b_len, 0.01, 2), position=(pa + pb) / 2)
    bld.add_body("rocker", 1.5, _rod(1.5, c, 0.01, 2), position=(pb + pd) / 2)
    bld.add_revolute("A", "ground", "crank", point=(0, 0, 0), axis=z)
    if five_revolutes:
        bld.add_revolute("A2", "ground", "crank", point=(0, 0, 0.05), axis=z)
    bld.add_revolute("B", "crank", "coupler", point=pa, axis=z)
    bld.add_revolute("C", "coupler", "rocker", point=pb, axis=z)
    if closure == "inline":
        bld.add_inline("D", "rocker", "ground", point=pd, axis=z)
    else:
        bld.add_revolute("D", "rocker", "ground", point=pd, axis=z)
    if crank_drive is not None:
        bld.add_drive("A", crank_drive)
    if crank_torque is not None:
        bld.add_joint_torque("A", crank_torque)
    return bld.finalize()


def spring_mass_pendulum(
    stiffness: float = 1e6,
    damping_ratio: float = 0.2,
    mass: float = 1.0,
    length: float = 1.0,
    theta0: float = 0.5,
) -> _core.Model:
    """A stiff spring-mass pendulum: a light arm (0.5 kg rod) on a pivot about world y, and a bob
    of ``mass`` sliding along the arm on a prismatic joint held by a linear spring-damper of
    ``stiffness`` [N/m] (rest length: the arm's ``length``) with damping ``damping_ratio`` of the
    critical value 2 sqrt(k m). Released at rest at ``theta0`` [rad] from the downward vertical.
    The spring's frequency sqrt(k/m) sets the stiffness; the pendulum's ≈ sqrt(g/L) the motion.
    Coordinates: ``pivot`` (angle), ``slide`` (stretch)."""
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    s, c = np.sin(theta0), np.cos(theta0)
    rot = (np.cos(theta0 / 2), 0.0, np.sin(theta0 / 2), 0.0)
    b.add_body(
        "arm",
        0.5,
        _rod(0.5, length, 0.01, 2),
        position=(0.5 * length * s, 0, -0.5 * length * c),
        orientation=rot,
    )
    pos = (length * s, 0.0, -length * c)
    b.add_body("bob", mass, _sphere(mass, 0.03), position=pos, orientation=rot)
    b.add_revolute("pivot", "ground", "arm", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_prismatic("slide", "arm", "bob", point=pos, axis=(s, 0.0, -c))
    b.add_joint_spring_damper(
        "slide", stiffness=stiffness, damping=damping_ratio * 2.0 * np.sqrt(stiffness * mass)
    )
    return b.finalize()


def slider_driven_to_dead_centre(crank: float = 0.1, rod: float = 0.35) -> _core.Model:
    """Slider-crank (axes along z, no gravity) started with the crank at 90° and its *slider*
    driven by a cubic over 1 s to x = crank + rod, the dead centre, where the driven
    constraints lose rank: the standard singular case of driven inverse dynamics."""
    a = np.array([0.0, crank, 0.0])
    x0 = np.sqrt(rod**2 - crank**2)
    s = np.array([x0, 0.0, 0.0])
    b = _core.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("crank", 1.0, [1e-3, 1e-4, 1e-3], position=a / 2)
    b.add_body("rod", 0.5, [1e-4, 5e-3, 5e-3], position=(a + s) / 2)
    b.add_body("slider", 2.0, [1e-3] * 3, position=s)
    b.add_revolute("crank_pin", "ground", "crank", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("crank_rod", "crank", "rod", point=a, axis=(0, 0, 1))
    b.add_revolute("rod_slider", "rod", "slider", point=s, axis=(0, 0, 1))
    b.add_prismatic("guide", "ground", "slider", point=s, axis=(1, 0, 0))
    b.add_drive("guide", _core.profiles.cubic(0.0, crank + rod - x0, 0.0, 1.0))
    return b.finalize()
