"""The multibody community's standard test problems, built as armdyn models.

- IFToMM A01 simple pendulum, A02 N-four-bar and A03 Andrews' mechanism: the Library of
  Computational Benchmark Problems of the IFToMM Technical Committee for Multibody Dynamics
  (González, Dopico, Lugrís, Cuadrado, Multibody Syst. Dyn. 16 (2006) 189–199; specifications at
  lim.ii.udc.es/mbsbenchmark/dist/A0x/A0x_specification.xml).
- Andrews' squeezing mechanism in the form of Hairer & Wanner, *Solving ODEs II* (1996)
  §VII.7 and the Bari Test Set for IVP solvers (Mazzia & Magherini 2008, problem "andrews"):
  seven bodies, no gravity, spring c0 = 4530 N/m, motor torque 0.033 N m, t in [0, 0.03] s. IFToMM
  A03 is the same mechanism.

The planar mechanisms are modelled in 3-D with joint axes along world z. Loops are closed with
inline joints (2 rows) rather than revolutes, so that the rows stay independent.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from armdyn import _core

G = 9.81


def iftomm_a01_pendulum() -> _core.Model:
    """IFToMM A01: a 1 kg point mass on a massless 1 m rod, gravity 9.81 along −y, released at
    rest from the horizontal (P1 at x = +1 m), 2000 s.

    The rod is a distance joint (a massless rod with ball ends) from the pivot to the mass's
    centre, so the mass's own rotation is free and never excited: its inertia (any positive
    value; here a 1 cm ball) does not enter the motion, and the model is the specified
    point-mass pendulum exactly.
    """
    b = _core.ModelBuilder(gravity=(0.0, -G, 0.0))
    b.add_body("P1", 1.0, [4e-5] * 3, position=(1.0, 0.0, 0.0))
    b.add_distance("rod", "ground", (0, 0, 0), "P1", (1.0, 0.0, 0.0))
    return b.finalize()


def _bar_inertia(mass: float, length: float) -> list[float]:
    """Slender bar along body x: mL²/12 about y and z; about its own axis a small positive value
    (a revolute about z fixes that rotation, so it does not enter the motion)."""
    i = mass * length**2 / 12.0
    return [1e-4 * i, i, i]


def iftomm_a02_four_bar(n: int = 40) -> _core.Model:
    """IFToMM A02: ``n`` four-bar windows of 2n+1 uniform bars (1 m, 1 kg), gravity along −y.

    Ground pivots A_i = (i, 0), i = 0…n; vertical cranks A_i–B_i start upright (B_i = (i, 1)),
    horizontal couplers B_{i-1}–B_i. Point B0 starts with ẋ = 1 m/s. In the horizontal position the
    mechanism is singular: the mobility jumps from 1 to n+1. Duration 20 s.

    Crank i is a revolute to ground, coupler i a revolute to crank i-1; coupler i closes its
    window on crank i with an inline joint. Bodies: ``crank0…crank{n}``, ``coupler1…coupler{n}``.
    """
    if n < 1:
        raise _core.ModelError(f"iftomm_a02_four_bar: n must be >= 1, got {n}")
    b = _core.ModelBuilder(gravity=(0.0, -G, 0.0))
    up = (np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4))  # body x along world y
    z = (0, 0, 1)
    for i in range(n + 1):
        b.add_body(f"crank{i}", 1.0, _bar_inertia(1.0, 1.0), position=(i, 0.5, 0), orientation=up)
        b.add_revolute(f"A{i}", "ground", f"crank{i}", point=(i, 0, 0), axis=z)
    for i in range(1, n + 1):
        b.add_body(f"coupler{i}", 1.0, _bar_inertia(1.0, 1.0), position=(i - 0.5, 1.0, 0))
        b.add_revolute(f"B{i - 1}", f"crank{i - 1}", f"coupler{i}", point=(i - 1, 1, 0), axis=z)
        b.add_inline(f"B{i}_close", f"crank{i}", f"coupler{i}", point=(i, 1, 0), axis=z)
    return b.finalize()


def a02_initial_velocity(model: _core.Model, n: int = 40, speed: float = 1.0) -> np.ndarray:
    """Cartesian velocities of A02's start: every crank turning at −speed rad/s (B0 moving +x at
    ``speed`` m/s), every coupler translating at (speed, 0)."""
    v = np.zeros(model.nv)
    names = model.body_names
    for i, name in enumerate(names):
        if name.startswith("crank"):
            # CoM at (x, 0.5) turning at w = -speed about z: v = w × r = (speed * 0.5, 0)
            v[6 * i : 6 * i + 3] = (0.5 * speed, 0.0, 0.0)
            # body x along world y, body z along world z: omega_body = (0, 0, w)
            v[6 * i + 3 : 6 * i + 6] = (0.0, 0.0, -speed)
        else:
            v[6 * i : 6 * i + 3] = (speed, 0.0, 0.0)
    return v


# Andrews' squeezing mechanism: Hairer & Wanner (1996) §VII.7, Test Set "andrews" constants
SQUEEZER = {
    "m": (0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498),
    "I": (2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5),
    "xa": -0.06934,
    "ya": -0.00227,
    "xb": -0.03635,
    "yb": 0.03273,
    "xc": 0.014,
    "yc": 0.072,
    "c0": 4530.0,
    "d": 28e-3,
    "da": 115e-4,
    "e": 2e-2,
    "ea": 1421e-5,
    "rr": 7e-3,
    "ra": 92e-5,
    "l0": 7785e-5,
    "ss": 35e-3,
    "sa": 1874e-5,
    "sb": 1043e-5,
    "sc": 18e-3,
    "sd": 2e-2,
    "ta": 2308e-5,
    "tb": 916e-5,
    "u": 4e-2,
    "ua": 1228e-5,
    "ub": 449e-5,
    "zf": 2e-2,
    "zt": 4e-2,
    "fa": 1421e-5,
    "mom": 33e-3,
    # consistent initial angles (beta, Theta, gamma, Phi, delta, Omega, epsilon)
    "q0": (
        -0.0617138900142764496358948458001,
        0.0,
        0.455279819163070380255912382449,
        0.222668390165885884674473185609,
        0.487364979543842550225598953530,
        -0.222668390165885884674473185609,
        1.23054744454982119249735015568,
    ),
}


def _rot(a: float) -> np.ndarray:
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def squeezer_points(q: npt.ArrayLike) -> dict:
    """Joint points and centres of mass of Andrews' mechanism at angles ``q`` (2-D, metres)."""
    p = SQUEEZER
    be, th, ga, ph, de, om, ep = q
    e2 = lambda a: np.array([np.cos(a), np.sin(a)])  # noqa: E731
    A = np.array([p["xa"], p["ya"]])
    B = np.array([p["xb"], p["yb"]])
    C = np.array([p["xc"], p["yc"]])
    F = p["rr"] * e2(be)
    E = F - p["d"] * e2(be + th)
    Gp = A + p["zt"] * e2(de)
    H = A + _rot(ep) @ np.array([0.0, -p["u"]])
    D = B + _rot(ga) @ np.array([p["sd"], -p["sc"]])
    perp = lambda a: np.array([np.sin(a), -np.cos(a)])  # noqa: E731
    com = [
        p["ra"] * e2(be),
        F - p["da"] * e2(be + th),
        B + _rot(ga) @ np.array([p["sb"], -p["sa"]]),
        Gp + (p["e"] - p["ea"]) * perp(ph + de),
        A + _rot(de) @ np.array([p["ta"], p["tb"]]),
        H + (p["zf"] - p["fa"]) * e2(om + ep),
        A + _rot(ep) @ np.array([-p["ub"], -p["ua"]]),
    ]
    return {
        "O": np.zeros(2),
        "A": A,
        "B": B,
        "C": C,
        "D": D,
        "E": E,
        "F": F,
        "G": Gp,
        "H": H,
        "com": com,
    }


def andrews_squeezer() -> _core.Model:
    """Andrews' squeezing mechanism (Hairer & Wanner 1996 §VII.7; Test Set "andrews"; IFToMM A03):
    seven bodies in the plane, motor torque 0.033 N m on body 1 about O, spring 4530 N/m
    (rest 0.07785 m) from the fixed point C to point D of body 3, no gravity; released at rest in
    the consistent configuration of the Test Set.

    Bodies ``K1…K7`` in the order of the angles (β, Θ, γ, Φ, δ, Ω, ε): K1 = OF, K2 = FE, K3 = BDE
    (triangle), K4 = EG, K5 = GA, K6 = EH, K7 = HA. Tree revolutes O, F, B, A5, G, A7, H; the
    three loops close at E with inline joints. Out-of-plane inertias equal the in-plane ones
    (they do not enter the planar motion).
    """
    p = SQUEEZER
    pts = squeezer_points(p["q0"])
    b = _core.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    for k in range(7):
        c = pts["com"][k]
        b.add_body(f"K{k + 1}", p["m"][k], [p["I"][k]] * 3, position=(c[0], c[1], 0.0))

    def at(name):
        return (*pts[name], 0.0)

    z = (0, 0, 1)
    b.add_revolute("O", "ground", "K1", point=at("O"), axis=z)
    b.add_revolute("F", "K1", "K2", point=at("F"), axis=z)
    b.add_revolute("B", "ground", "K3", point=at("B"), axis=z)
    b.add_revolute("A5", "ground", "K5", point=at("A"), axis=z)
    b.add_revolute("G", "K5", "K4", point=at("G"), axis=z)
    b.add_revolute("A7", "ground", "K7", point=at("A"), axis=z)
    b.add_revolute("H", "K7", "K6", point=at("H"), axis=z)
    for k in (3, 4, 6):
        b.add_inline(f"E{k}", "K2", f"K{k}", point=at("E"), axis=z)
    b.add_spring_damper(
        "spring", "ground", at("C"), "K3", at("D"), stiffness=p["c0"], rest_length=p["l0"]
    )
    b.add_joint_torque("O", _core.profiles.constant(p["mom"]))
    return b.finalize()
