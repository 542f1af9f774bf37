"""The arms of the five-DOF validation paper (``five-dof-light-lifting-arm-validation.txt``),
rebuilt as armdyn models. Every number the paper does not publish is reconstructed here, in one
place, with the reason.

Conventions: SI units, world z up, gravity 9.81 m/s² along −z. The arms start stretched out
along +x. Pitch joints turn about −y, so a positive angle raises the arm: a rotation about −y
takes +x towards +z, the paper's "angle from the x-axis" in its x–y plane with y up. The paper's
end-effector axes (X, Y, Z), with Y up, are our (x, z, y).

Three-DOF arm (paper, Stage 1, after Ramish et al. 2016). The paper gives no dimensions, only
"three links, 1 s trajectories".
  * Links: solid aluminium bars (ρ = 2700 kg/m³) with a 40 × 20 mm section. Lengths 0.30, 0.25
    and 0.20 m, so masses 0.648, 0.540 and 0.432 kg. Each bar spans its joint to the next joint.
  * Trajectories: cubic rest-to-rest in 1 s for the relative joint angles, 0 → (60°, −45°, 30°).
  * The paper model (equations (9)–(11)) takes these link masses as point masses at the link
    ends, as its equations (3)–(5) place them.

Five-DOF light-lifting arm (paper, Figure 1 and Stage 2). The paper publishes the joint kinds:
one twist, three rotary and one prismatic joint. Its Table 4 at position 1 (all joints at zero)
gives the end effector at [0.66, 0.16, 0]; with equations (22)–(25) that fixes h = 0.16 m and
λ = L1 + L2 + L3 + L4 = 0.66 m. We choose the split L1 = 0.25, L2 = 0.20, L3 = 0.12 and
L4 = 0.09 m: each link shorter than the one before, as in Figure 1.
  * turret: twist joint about z at the origin. Cylinder r = 0.06 m, height 0.16 m, 0.80 kg.
  * link1: shoulder at (0, 0, 0.16). Bar 0.25 × 0.05 × 0.03 m, 0.55 kg.
  * link2: elbow at (0.25, 0, 0.16). Bar 0.20 × 0.04 × 0.03 m, 0.40 kg.
  * link3: wrist at (0.45, 0, 0.16). Housing of the linear motor, 0.12 × 0.04 × 0.04 m, 0.30 kg.
  * rod: prismatic joint along link3's axis. Rod of length 0.09 m and radius 8 mm, 0.12 kg,
    gripper included. Its tip is the end effector, at 0.66 m when retracted (s = 0).
  * Stroke: 0.10 m. "Fully extended within 5 s": cubic 0 → 0.10 m in 5 s.
  * Rotary joints: cubic 0° → 50° in 5 s (equations (28)–(30)). Outputs every 0.01 s.
The simplified model "of the paper's kind" keeps the same joints but lumps each link's mass at
the link's far end, as equations (3)–(4) do, with no rotational inertia. The turret's mass sits
on the twist axis.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import numpy.typing as npt

from armdyn import _core

G = 9.81
DEG = np.pi / 180.0

# ---------------------------------------------------------------------------------------------
# published figures (the paper's tables), for the reproduction report
# ---------------------------------------------------------------------------------------------
PAPER = SimpleNamespace(
    table1_percent=np.array([32.16, 15.14, 9.22]),  # "percentage of error", three-DOF
    table2_rmse=np.array([24.0, 3.0, 4.0, 6.0, 1.0]),  # RMS percentage error, five-DOF
    table2_average=7.6,
    # Table 3: joint angles [deg] of joints 1..4 at positions 1..3 (prismatic not listed: 0)
    table3_deg=np.array([[0, 0, 0, 0], [0, 45, 45, 45], [45, 45, 45, 45]], dtype=float),
    # Table 4: end effector [X, Y, Z] in metres, paper axes (Y up)
    table4_simscape=np.array([[0.67, 0.16, 0.03], [0.30, 0.71, 0.03], [0.19, 0.71, 0.25]]),
    table4_geometric=np.array([[0.66, 0.16, 0.0], [0.35, 0.73, 0.0], [0.18, 0.73, 0.30]]),
)

# ---------------------------------------------------------------------------------------------
# reconstructed parameters
# ---------------------------------------------------------------------------------------------
ARM3 = SimpleNamespace(
    lengths=np.array([0.30, 0.25, 0.20]),
    width=0.04,
    thickness=0.02,
    density=2700.0,
    duration=1.0,
    targets=np.array([60.0, -45.0, 30.0]) * DEG,
)
ARM3.masses = ARM3.density * ARM3.lengths * ARM3.width * ARM3.thickness

ARM5 = SimpleNamespace(
    h=0.16,
    L1=0.25,
    L2=0.20,
    L3=0.12,
    L4=0.09,
    stroke=0.10,
    duration=5.0,
    target_deg=50.0,
    turret=dict(mass=0.80, radius=0.06, height=0.16),
    link1=dict(mass=0.55, size=(0.25, 0.05, 0.03)),
    link2=dict(mass=0.40, size=(0.20, 0.04, 0.03)),
    link3=dict(mass=0.30, size=(0.12, 0.04, 0.04)),
    rod=dict(mass=0.12, length=0.09, radius=0.008),
    joints=["twist", "shoulder", "elbow", "wrist", "extend"],
)
ARM5.reach = ARM5.L1 + ARM5.L2 + ARM5.L3 + ARM5.L4  # λ at position 1 = 0.66 m


def _box(mass, a, b, c):
    """Principal inertias of a box with edges a (x), b (y), c (z)."""
    return [mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12]


def _cyl_z(mass, r, h):
    return [mass * (3 * r * r + h * h) / 12, mass * (3 * r * r + h * h) / 12, 0.5 * mass * r * r]


def _cyl_x(mass, r, length):
    it = mass * (3 * r * r + length * length) / 12
    return [0.5 * mass * r * r, it, it]


_POINT = 1e-9  # principal inertia of a "point mass" body [kg m²]; the validator ignores it
PITCH = (0.0, -1.0, 0.0)  # positive pitch raises the arm


# ---------------------------------------------------------------------------------------------
# three-DOF planar arm
# ---------------------------------------------------------------------------------------------
def three_dof_arm(point_masses: bool = False, drives: bool = True) -> _core.Model:
    """The paper's Stage 1 planar 3-DOF arm (see the module docstring for every number).

    Joints ``j1, j2, j3`` (relative angles), driven by cubic rest-to-rest profiles over 1 s.
    With ``point_masses`` each link's mass sits at its far end (the paper model's assumption).
    """
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -G))
    x = 0.0
    for i, (length, mass) in enumerate(zip(ARM3.lengths, ARM3.masses, strict=True)):
        if point_masses:
            b.add_body(f"link{i + 1}", mass, [_POINT] * 3, position=(x + length, 0, 0))
        else:
            inertia = _box(mass, length, ARM3.thickness, ARM3.width)
            b.add_body(f"link{i + 1}", mass, inertia, position=(x + 0.5 * length, 0, 0))
        parent = "ground" if i == 0 else f"link{i}"
        b.add_revolute(f"j{i + 1}", parent, f"link{i + 1}", point=(x, 0, 0), axis=PITCH)
        x += length
    if drives:
        for i, target in enumerate(ARM3.targets):
            b.add_drive(f"j{i + 1}", _core.profiles.cubic(0.0, float(target), 0.0, ARM3.duration))
    return b.finalize()


def three_dof_absolute(
    q: npt.ArrayLike, qd: npt.ArrayLike
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Absolute link angles and rates (from the horizontal) from relative joint angles."""
    return np.cumsum(q, axis=-1), np.cumsum(qd, axis=-1)


def absolute_to_joint_torques(T: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Generalised forces conjugate to absolute angles → joint torques: τ_i = Σ_{k≥i} T_k
    (θ_abs = B q with B lower-triangular ones, so τ = Bᵀ T)."""
    T = np.asarray(T, dtype=float)
    return np.flip(np.cumsum(np.flip(T, axis=-1), axis=-1), axis=-1)


# ---------------------------------------------------------------------------------------------
# five-DOF light-lifting arm
# ---------------------------------------------------------------------------------------------
def five_dof_arm(
    point_masses: bool = False, hold: npt.ArrayLike | None = None, drives: bool = True
) -> _core.Model:
    """The paper's five-DOF light-lifting arm (see the module docstring for every number).

    Joints in order: ``twist`` (about z), ``shoulder``, ``elbow``, ``wrist`` (pitch, positive
    raises), ``extend`` (prismatic along the last link). By default every joint is driven by the
    paper's cubic trajectories (0° → 50° and 0 → full stroke in 5 s). ``hold`` = (θ1, θ2, θ3, θ4
    [rad], s [m]) instead holds the joints at those values (constant drives; the assembly solves
    the constraints for that pose). ``point_masses`` builds the simplified model.
    """
    a = ARM5
    h = a.h
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -G))
    x1, x2, x3, x4 = a.L1, a.L1 + a.L2, a.L1 + a.L2 + a.L3, a.reach
    if point_masses:
        b.add_body("turret", a.turret["mass"], [_POINT] * 3, position=(0, 0, h))
        b.add_body("link1", a.link1["mass"], [_POINT] * 3, position=(x1, 0, h))
        b.add_body("link2", a.link2["mass"], [_POINT] * 3, position=(x2, 0, h))
        b.add_body("link3", a.link3["mass"], [_POINT] * 3, position=(x3, 0, h))
        b.add_body("rod", a.rod["mass"], [_POINT] * 3, position=(x4, 0, h))
    else:
        t = a.turret
        b.add_body("turret", t["mass"], _cyl_z(t["mass"], t["radius"], t["height"]), (0, 0, h / 2))
        for name, x0 in (("link1", 0.0), ("link2", x1), ("link3", x2)):
            p = getattr(a, name)
            b.add_body(name, p["mass"], _box(p["mass"], *p["size"]), (x0 + p["size"][0] / 2, 0, h))
        r = a.rod
        b.add_body(
            "rod", r["mass"], _cyl_x(r["mass"], r["radius"], r["length"]), (x3 + a.L4 / 2, 0, h)
        )
    b.add_revolute("twist", "ground", "turret", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("shoulder", "turret", "link1", point=(0, 0, h), axis=PITCH)
    b.add_revolute("elbow", "link1", "link2", point=(x1, 0, h), axis=PITCH)
    b.add_revolute("wrist", "link2", "link3", point=(x2, 0, h), axis=PITCH)
    b.add_prismatic("extend", "link3", "rod", point=(x3, 0, h), axis=(1, 0, 0))
    # the end effector: the rod tip (five_dof_tip's point), world axes at the assembly pose
    b.add_frame("tip", "rod", position=(a.reach, 0, h))
    if hold is not None:
        hold = np.asarray(hold, dtype=float)
        if hold.shape != (5,):
            raise _core.ModelError(f"five_dof_arm: hold needs 5 values, got shape {hold.shape}")
        for name, value in zip(a.joints, hold, strict=True):
            b.add_drive(name, float(value))
    elif drives:
        end = a.target_deg * DEG
        for name in a.joints[:4]:
            b.add_drive(name, _core.profiles.cubic(0.0, end, 0.0, a.duration))
        b.add_drive("extend", _core.profiles.cubic(0.0, a.stroke, 0.0, a.duration))
    return b.finalize()


def five_dof_tip(model_is_point_mass: bool = False) -> tuple[str, npt.NDArray[np.float64]]:
    """(body, point) of the end effector: the rod tip, in the rod's body frame (also the model's
    frame ``tip``)."""
    offset = 0.0 if model_is_point_mass else ARM5.L4 / 2
    return "rod", np.array([offset, 0.0, 0.0])


def to_paper_axes(p: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """World (x, y, z) → the paper's (X, Y, Z) with Y up: (x, z, y)."""
    p = np.asarray(p, dtype=float)
    return p[..., [0, 2, 1]]
