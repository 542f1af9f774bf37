"""Scenes of the extreme-case studies (docs/extreme_cases.md): an overconstrained Bricard
linkage and a fast heavy top. SI units, z up."""

from __future__ import annotations

import numpy as np

from armdyn import _core


def bricard(side=0.3, mass=1.0):
    """Orthogonal Bricard 6R linkage on the edges of a cube of edge ``side``: six equal links,
    consecutive joint axes perpendicular, one link is ground. 6 revolutes = 30 rows on 5 bodies
    (nv = 30), so Grübler's count gives 0 DOF; the linkage moves with 1, and its joint angles keep
    the threefold symmetry J0 = J2 = J4, J1 = J3 = J5."""
    p = np.array([(1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1), (1, 0, 1)], float) * side
    d = [p[(i + 1) % 6] - p[i] for i in range(6)]
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    links = [f"link{i}" for i in range(5)]
    for i in range(5):
        b.add_body(links[i], mass, [2e-3, 2e-3, 1e-3], position=(p[i] + p[i + 1]) / 2)
    for i in range(6):
        axis = np.cross(d[i - 1], d[i])
        parent = "ground" if i == 0 else links[i - 1]
        child = links[i] if i < 5 else "ground"
        b.add_revolute(f"J{i}", parent, child, point=p[i], axis=axis / np.linalg.norm(axis))
    return b.finalize()


def heavy_top(spin=1000.0, tilt=np.pi / 6, mass=1.0, length=0.05, i1=1.5e-3, i3=2e-3):
    """Symmetric top on a spherical joint at the origin, centre of mass ``length`` up its axis,
    tilted by ``tilt`` about x. Returns (model, u0, v0, omega_p): the initial state spins at
    ``spin`` about the symmetry axis and precesses at the gyroscopic rate
    omega_p = m g l / (I3 spin) (steady precession of the fast top)."""
    g = 9.81
    omega_p = mass * g * length / (i3 * spin)
    e = np.array([np.cos(tilt / 2), np.sin(tilt / 2), 0.0, 0.0])
    c, s = np.cos(tilt), np.sin(tilt)
    rot = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    r = rot @ np.array([0.0, 0.0, length])
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -g))
    b.add_body("top", mass, [i1, i1, i3], position=r, orientation=e)
    b.add_spherical("tip", "ground", "top", point=(0, 0, 0))
    model = b.finalize()
    w_world = rot @ np.array([0.0, 0.0, spin]) + np.array([0.0, 0.0, omega_p])
    u0 = np.concatenate([r, e])
    v0 = np.concatenate([np.cross(w_world, r), rot.T @ w_world])
    return model, u0, v0, omega_p
