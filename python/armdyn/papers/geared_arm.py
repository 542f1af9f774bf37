"""A 6-DOF arm driven by motors through two-stage gear trains: the mechanism studied in the
first paper (``six-dof-arm-topological-projection.txt``: 44 bodies, 6 DOF, motions prescribed
through motors, driven-gear torque with gear clearance). The paper publishes no dimensions; every
number below is ours, chosen for a 1 m, 20 kg class arm. SI units, z up, build pose stretched
along +x.

Subsystems and bodies (``n_motors = 1``: 44 bodies):
  * base: 1 body welded to ground;
  * the arm: waist, lower_arm, fore_arm, wrist_1, wrist_2, hand (6 links), each with a fixed
    actuator housing (6 bodies), and a tool fixed to the hand (1 body);
  * one gear train per joint (6 trains × 5 bodies), all mounted on the joint's parent link:
      rotor (motor rotor, revolute) + pinion_1 (fixed to the rotor)  — stage 1, ideal gear,
      wheel_1 (revolute) + pinion_2 (fixed to wheel_1)               — stage 2,
      driven gear (fixed to the child link, coaxial with the joint).
    The stage-2 mesh between pinion_2 and the driven gear has the backlash (a gear pair with
    dead zone and Hunt–Crossley contact) when ``backlash > 0``, otherwise it is an ideal gear.
  * ``n_motors > 1`` adds trains (rotor, pinion_1, wheel_1, pinion_2: 4 bodies each) on the
    driven gear of ``shared_joint`` (default the waist, whose gear load reverses with the
    acceleration), spaced around it: the motors share that gear's load.

Joints (axes at the build pose): waist z at (0, 0, 0.1); shoulder −y at (0, 0, 0.3); elbow −y at
(0.4, 0, 0.3); wrist roll x at (0.75, 0, 0.3); wrist pitch −y at (0.8, 0, 0.3); hand roll x at
(0.85, 0, 0.3); tool tip at (0.95, 0, 0.3). Positive pitch raises the arm.

Gears (pitch radii [m]: driven R2, pinion r2, wheel R1, pinion r1; ratio N = (R1/r1)(R2/r2)):
  waist (0.10, 0.02, 0.06, 0.015) N = 20; shoulder (0.10, 0.02, 0.06, 0.012) N = 25;
  elbow (0.08, 0.016, 0.05, 0.01) N = 25; wrist roll, wrist pitch (0.04, 0.01, 0.03, 0.01)
  N = 12; hand roll (0.03, 0.01, 0.02, 0.01) N = 6. Gears are steel discs (7850 kg/m³) 8 mm
  wide; rotors are 0.3 kg cylinders of radius 20 mm. Mesh stiffness 2e9 N/m^1.5 (Hertzian
  exponent 1.5), Hunt–Crossley damping 0.3 s/m.

Motors: PD control of the rotor angle towards N × the joint's reference (a quintic rest-to-rest
profile between ``t_start`` and ``t_end``), gains kp = 25 N m/rad and kd = 0.5 N m s/rad per
rotor, torque limit 10 N m. Motors sharing a gear split the gains, and may be biased against
each other (``preload``, anti-backlash).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from armdyn import _core

G = 9.81
STEEL, FACE = 7850.0, 0.008

# name, parent, axis, point, R2, r2, R1, r1, train offset direction e (perpendicular to axis)
JOINTS = [
    ("waist", "base", (0, 0, 1), (0.0, 0, 0.10), 0.10, 0.02, 0.06, 0.015, (1, 0, 0)),
    ("shoulder", "waist", (0, -1, 0), (0.0, 0, 0.30), 0.10, 0.02, 0.06, 0.012, (0, 0, 1)),
    ("elbow", "lower_arm", (0, -1, 0), (0.40, 0, 0.30), 0.08, 0.016, 0.05, 0.01, (0, 0, 1)),
    ("wrist_roll", "fore_arm", (1, 0, 0), (0.75, 0, 0.30), 0.04, 0.01, 0.03, 0.01, (0, 0, 1)),
    ("wrist_pitch", "wrist_1", (0, -1, 0), (0.80, 0, 0.30), 0.04, 0.01, 0.03, 0.01, (0, 0, 1)),
    ("hand_roll", "wrist_2", (1, 0, 0), (0.85, 0, 0.30), 0.03, 0.01, 0.02, 0.01, (0, 0, 1)),
]
# link (child of the joint of the same index): mass, CoM, box size (x, y, z)
LINKS = [
    ("waist", 6.0, (0.0, 0, 0.2), (0.18, 0.18, 0.2)),
    ("lower_arm", 4.0, (0.2, 0, 0.3), (0.4, 0.08, 0.08)),
    ("fore_arm", 2.5, (0.575, 0, 0.3), (0.35, 0.06, 0.06)),
    ("wrist_1", 0.8, (0.775, 0, 0.3), (0.05, 0.06, 0.06)),
    ("wrist_2", 0.6, (0.825, 0, 0.3), (0.05, 0.05, 0.05)),
    ("hand", 0.5, (0.88, 0, 0.3), (0.06, 0.05, 0.05)),
]
HOUSING_MASS = [1.0, 0.8, 0.6, 0.3, 0.25, 0.2]
RATIOS = {j[0]: (j[6] / j[7]) * (j[4] / j[5]) for j in JOINTS}


def _box(mass, size):
    a, b, c = size
    return [mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12]


def _disc(mass, radius, axis, width=FACE):
    k = int(np.argmax(np.abs(axis)))
    t = mass * (radius**2 / 4 + width**2 / 12)
    d = [t, t, t]
    d[k] = 0.5 * mass * radius**2
    return d


def _gear_mass(radius, scale):
    return scale * STEEL * np.pi * radius**2 * FACE


def geared_arm_6dof(
    n_motors: int = 1,
    shared_joint: str = "waist",
    backlash: float = 0.0,
    control: str = "motor",
    targets: npt.ArrayLike = (0.8, 0.6, -0.9, 0.5, 0.7, 1.0),
    t_start: float = 0.5,
    t_end: float = 4.5,
    gear_mass_scale: float = 1.0,
    trains: bool = True,
    mesh_stiffness: float = 2e9,
    hc_damping: float = 0.3,
    kp: float = 25.0,
    kd: float = 0.5,
    torque_limit: float = 10.0,
    preload: float = 0.0,
    ideal_gears: bool = True,
) -> _core.Model:
    """Build the geared arm (see the module docstring for every dimension).

    Args:
        n_motors: motors (gear trains) on the driven gear of ``shared_joint``, 1…6.
        shared_joint: the joint whose driven gear the motors share.
        backlash: stage-2 clearance [m] (0: ideal stage-2 gears).
        control: ``"motor"`` (PD motors on the rotors, forward dynamics) or ``"drive"`` (rotor
            angles prescribed as drives: the drive efforts are the motor torques).
        targets: joint angles [rad] reached by the quintic references.
        gear_mass_scale: multiplies every gear and rotor mass (tiny: trains without inertia).
        trains: False builds the arm alone (links, housings, driven gears, tool) with drives on
            the arm joints (for inverse-dynamics comparisons).
        preload: anti-backlash bias torque [N m] at the rotors of the trains sharing
            ``shared_joint``'s gear: trains 1, 3, … add +preload and trains 2, 4, … −preload
            (with an odd count the last train gets none), so the biases cancel on the gear
            but hold the teeth of the two groups against opposite flanks. Ramped in by a
            quintic over [0, t_start/2] so the teeth close before the motion starts.
        ideal_gears: False leaves out the ideal gear constraints (stage 1 and stage 2): rotors
            and shafts then turn freely, an open tree in the joint coordinates. Only with
            backlash=0 and n_motors=1 (otherwise a ModelError). Not a mechanism of its own:
            ``benchmarks.references`` eliminates the gear ratios from its Euler–Lagrange equations
            to obtain an independent reference.
    """
    if not 1 <= int(n_motors) <= 6:
        raise _core.ModelError(f"geared_arm_6dof: n_motors must be 1..6, got {n_motors}")
    if shared_joint not in RATIOS:
        raise _core.ModelError(
            f"geared_arm_6dof: unknown shared_joint {shared_joint!r} (one of {sorted(RATIOS)})"
        )
    if not ideal_gears and (backlash > 0 or n_motors > 1):
        raise _core.ModelError(
            "geared_arm_6dof: ideal_gears=False (the open tree) needs backlash=0 and n_motors=1; "
            "the stage-2 contacts of a backlash or multi-motor arm would couple it"
        )
    if control not in ("motor", "drive"):
        raise _core.ModelError(
            f"geared_arm_6dof: control must be 'motor' or 'drive', got {control!r}"
        )
    if not preload >= 0:
        raise _core.ModelError(f"geared_arm_6dof: preload must be >= 0, got {preload}")
    if not backlash >= 0:
        raise _core.ModelError(f"geared_arm_6dof: backlash must be >= 0, got {backlash}")
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body("base", 10.0, _box(10.0, (0.3, 0.3, 0.1)), position=(0, 0, 0.05))
    b.add_fixed("base_mount", "ground", "base", point=(0, 0, 0))
    for (name, mass, com, size), hmass in zip(LINKS, HOUSING_MASS, strict=True):
        b.add_body(name, mass, _box(mass, size), position=com)
        hc = np.array(com) + np.array([0.0, 0.06, 0.0])
        b.add_body(f"{name}_housing", hmass, _box(hmass, (0.06, 0.04, 0.06)), position=hc)
    b.add_body("tool", 0.3, _box(0.3, (0.1, 0.03, 0.03)), position=(0.92, 0, 0.3))
    references = {}
    for (name, parent, axis, point, R2, r2, R1, r1, e), (child, *_), target in zip(
        JOINTS, LINKS, targets, strict=True
    ):
        axis, point, e = np.array(axis, float), np.array(point, float), np.array(e, float)
        b.add_revolute(name, parent, child, point=point, axis=axis)
        b.add_fixed(f"{child}_housing_mount", child, f"{child}_housing", point=point)
        # driven gear, coaxial with the joint, fixed to the child link
        mg = _gear_mass(R2, gear_mass_scale)
        b.add_body(f"{name}_driven", mg, _disc(mg, R2, axis), position=point)
        b.add_fixed(f"{name}_driven_mount", child, f"{name}_driven", point=point)
        references[name] = (0.0, float(target))
        if not trains:
            continue
        n_trains = int(n_motors) if name == shared_joint else 1
        for k in range(n_trains):
            # trains spaced around the driven gear: rotate e about the axis
            ang = 2 * np.pi * k / n_trains
            ek = e * np.cos(ang) + np.cross(axis, e) * np.sin(ang)
            w = np.cross(axis, ek)
            tag = name if n_trains == 1 else f"{name}_{k + 1}"
            c2 = point + (R2 + r2) * ek  # intermediate shaft
            c1 = c2 + (R1 + r1) * w  # motor shaft
            m_w1, m_p2 = _gear_mass(R1, gear_mass_scale), _gear_mass(r2, gear_mass_scale)
            m_p1, m_rot = _gear_mass(r1, gear_mass_scale), 0.3 * gear_mass_scale
            b.add_body(f"{tag}_wheel_1", m_w1, _disc(m_w1, R1, axis), position=c2)
            b.add_body(f"{tag}_pinion_2", m_p2, _disc(m_p2, r2, axis), position=c2 + 0.01 * axis)
            b.add_body(f"{tag}_rotor", m_rot, _disc(m_rot, 0.02, axis, 0.05), position=c1)
            b.add_body(f"{tag}_pinion_1", m_p1, _disc(m_p1, r1, axis), position=c1 + 0.03 * axis)
            b.add_revolute(f"{tag}_shaft", parent, f"{tag}_wheel_1", point=c2, axis=axis)
            b.add_fixed(f"{tag}_p2_key", f"{tag}_wheel_1", f"{tag}_pinion_2", point=c2)
            b.add_revolute(f"{tag}_motor", parent, f"{tag}_rotor", point=c1, axis=axis)
            b.add_fixed(f"{tag}_p1_key", f"{tag}_rotor", f"{tag}_pinion_1", point=c1)
            if ideal_gears:
                b.add_gear(f"{tag}_stage_1", f"{tag}_motor", f"{tag}_shaft", r1, R1)
            # without backlash, one ideal stage-2 mesh per joint: further trains on the same
            # gear would be redundant constraints, so they mesh through a stiff contact with
            # zero clearance
            if backlash > 0 or k > 0:
                b.add_gear_pair(
                    f"{tag}_stage_2",
                    f"{tag}_shaft",
                    name,
                    r2,
                    R2,
                    backlash=backlash,
                    stiffness=mesh_stiffness,
                    exponent=1.5,
                    hc_damping=hc_damping,
                )
            elif ideal_gears:
                b.add_gear(f"{tag}_stage_2", f"{tag}_shaft", name, r2, R2)
            n_ratio = RATIOS[name]
            ref = _core.profiles.quintic(0.0, n_ratio * float(target), t_start, t_end)
            if control == "motor":
                bias = 0.0
                if n_trains > 1 and preload > 0 and not (n_trains % 2 == 1 and k == n_trains - 1):
                    bias = preload if k % 2 == 0 else -preload
                b.add_motor(
                    f"{tag}_motor",
                    ref,
                    kp=kp / n_trains,
                    kd=kd / n_trains,
                    torque_limit=torque_limit,
                    feedforward=(
                        None if bias == 0.0 else _core.profiles.quintic(0.0, bias, 0.0, t_start / 2)
                    ),
                )
            elif k == 0:
                b.add_drive(f"{tag}_motor", ref)
    if not trains:
        for name, (_y0, target) in references.items():
            b.add_drive(name, _core.profiles.quintic(0.0, target, t_start, t_end))
    b.add_fixed("tool_mount", "hand", "tool", point=(0.85, 0, 0.3))
    return b.finalize()
