"""The cost of armdyn's analytical derivatives of the dynamics (issue 34), in one run, as ratios.

    python -m benchmarks.derivatives [--number 500] [--rows 1000] [--repeat 15]

Per robot (example-robot-data: the UR5 and the Panda on a fixed base, solo12 on a free flyer):

* From Python, one state per call: ``armdyn.inverse_dynamics_derivatives`` against
  ``pin.computeRNEADerivatives`` and ``armdyn.forward_dynamics_derivatives`` against
  ``pin.computeABADerivatives``, timed in interleaved rounds on the process's CPU clock
  (:func:`interleaved_cpu_times`), the ratio taken round by round (target: ≤ 1.0).
* "From C++": the per-row time of the 2-D batch call of each derivative function (``--rows``
  states in one call, the loop in C++) over the per-row time of the 2-D batch
  ``armdyn.inverse_dynamics`` call on the same states (the issue's target: ≤ 4; read here for
  both functions, ``meets_targets``); ``forward_dynamics_derivatives`` is also given against the
  batch ``forward_dynamics``.
* The answers against Pinocchio's in the same run (worst relative error over the batch's first
  states; the tests assert them: ``tests/algorithm/test_derivatives_pinocchio.py``).

Written to ``benchmarks/results/derivatives.json`` with the command and the machine.

:class:`DerivativePair` holds the map between the two libraries' conventions, which the tests
use too. armdyn's q is (x, y, z, e0, e1, e2, e3, joints) on a floating base (scalar-first
quaternion), Pinocchio's free flyer (x, y, z, e1, e2, e3, e0, joints); both take the base
velocity (v, ω) of the base frame in its own axes; joints are matched by name. The derivatives
with respect to q are taken in the tangent space, column k along the k-th velocity coordinate
(Pinocchio's ``integrate``), so that every matrix maps by the velocity permutation alone. The
URDF's ``<dynamics damping friction>``, which armdyn imports as joint friction and Pinocchio's
algorithms leave out, is added to Pinocchio's answers (:meth:`DerivativePair.friction`).
"""

from __future__ import annotations

import argparse
import sys
import time

import armdyn as ad
import numpy as np

from benchmarks import common

# name -> (example-robot-data path, fixed base)
ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", True),
    "panda": ("panda_description/urdf/panda.urdf", True),
    "solo12": ("solo_description/robots/solo12.urdf", False),
}
TARGET_PYTHON = 1.0  # armdyn / Pinocchio derivative call, one state per call from Python
TARGET_CPP = 4.0  # batch inverse_dynamics_derivatives per row / batch inverse_dynamics per row


def robot_path(name: str) -> str:
    """Path of one of :data:`ROBOTS`' URDFs (FileNotFoundError without example-robot-data)."""
    base = common.robots_dir()
    path = None if base is None else base / ROBOTS[name][0]
    if path is None or not path.is_file():
        raise FileNotFoundError(f"example-robot-data does not provide {ROBOTS[name][0]}")
    return str(path)


def symmetric(upper: np.ndarray) -> np.ndarray:
    """The symmetric matrix whose upper triangle is ``upper``'s (Pinocchio's ``Minv`` and
    ``crba`` fill only that triangle)."""
    return np.triu(upper) + np.triu(upper, 1).T


class DerivativePair:
    """One URDF in armdyn (``am``) and Pinocchio (``pm``, ``pd``), on a fixed base or a free
    flyer (``fixed_base=False``; Pinocchio's ``JointModelFreeFlyer``), each mimicking joint its
    own coordinate. ``iv[k]``: the Pinocchio velocity index of armdyn's velocity coordinate
    ``k``, so that ``v_pin[iv] = qd`` and an armdyn matrix is ``A_pin[np.ix_(iv, iv)]``."""

    def __init__(self, path: str, fixed_base: bool = True):
        import pinocchio as pin

        self.pin, self.fixed_base = pin, fixed_base
        self.am = ad.load_urdf(path, fixed_base=fixed_base, mimic=False)
        if fixed_base:
            self.pm = pin.buildModelFromUrdf(path)
        else:
            self.pm = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
        self.pd = self.pm.createData()
        base = 0 if fixed_base else 7
        names = self.am.coord_names[base:]
        ids = [self.pm.getJointId(n) for n in names]
        if any(self.pm.joints[i].nq != 1 or self.pm.joints[i].nv != 1 for i in ids):
            raise ValueError("only revolute/prismatic joints (one coordinate each) are mapped")
        self.iq = np.array([self.pm.idx_qs[i] for i in ids], dtype=int)
        head = [] if fixed_base else list(range(6))
        self.iv = np.array(head + [self.pm.idx_vs[i] for i in ids], dtype=int)
        if self.pm.nv != self.am.n_dofs or sorted(self.iv) != list(range(self.pm.nv)):
            raise ValueError("the two models' coordinates do not match one to one")

    # ---- states
    def q_pin(self, q: np.ndarray) -> np.ndarray:
        """armdyn's q in Pinocchio's configuration vector (the quaternion scalar last)."""
        qp = np.zeros(self.pm.nq)
        if not self.fixed_base:
            qp[:3], qp[3:6], qp[6] = q[:3], q[4:7], q[3]
        qp[self.iq] = q[0 if self.fixed_base else 7 :]
        return qp

    def q_armdyn(self, qp: np.ndarray) -> np.ndarray:
        """Pinocchio's configuration vector in armdyn's q (the quaternion scalar first)."""
        q = np.zeros(self.am.n_coords)
        if not self.fixed_base:
            q[:3], q[3], q[4:7] = qp[:3], qp[6], qp[3:6]
        q[0 if self.fixed_base else 7 :] = qp[self.iq]
        return q

    def v_pin(self, v: np.ndarray) -> np.ndarray:
        """An armdyn velocity-space vector (qd, qdd, tau) in Pinocchio's order."""
        vp = np.zeros(self.pm.nv)
        vp[self.iv] = v
        return vp

    def matrix(self, a_pin: np.ndarray) -> np.ndarray:
        """A Pinocchio velocity-space matrix (rows and columns) in armdyn's order."""
        return np.asarray(a_pin)[np.ix_(self.iv, self.iv)]

    def integrate(self, q: np.ndarray, dv: np.ndarray) -> np.ndarray:
        """armdyn's q moved along the velocity ``dv`` (armdyn order) for unit time, by
        Pinocchio's ``integrate`` (the free flyer's SE(3) exponential in the base frame): the
        tangent-space step the q-derivatives are taken along."""
        return self.q_armdyn(self.pin.integrate(self.pm, self.q_pin(q), self.v_pin(dv)))

    def random_state(self, rng: np.random.Generator, rows: int | None = None):
        """``(q, qd, x)`` in armdyn's order: joint angles in [-π, π], a random unit quaternion
        and a normal base position on a free flyer, rates and ``x`` (qdd or tau) normal; one
        state or ``rows`` of them."""
        shape = () if rows is None else (rows,)
        nj = self.am.n_coords - (0 if self.fixed_base else 7)
        q = rng.uniform(-np.pi, np.pi, size=(*shape, nj))
        if not self.fixed_base:
            e = rng.normal(size=(*shape, 4))
            e /= np.linalg.norm(e, axis=-1, keepdims=True)
            q = np.concatenate([rng.normal(size=(*shape, 3)), e, q], axis=-1)
        return (
            q,
            rng.normal(size=(*shape, self.am.n_dofs)),
            rng.normal(size=(*shape, self.am.n_dofs)),
        )

    # ---- Pinocchio's derivatives with armdyn's joint friction, in armdyn's order
    def friction(self, vp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(tau_f, dtau_f/dv)`` in Pinocchio's order: the URDF's ``<dynamics>`` torques at
        rates ``vp`` (armdyn's joint friction -damping v - friction tanh(v / v_s), v_s
        ``armdyn._core.URDF_COULOMB_SMOOTHING``) and their derivative, a diagonal matrix."""
        vs = ad._core.URDF_COULOMB_SMOOTHING
        th = np.tanh(vp / vs)
        tau = -self.pm.damping * vp - self.pm.friction * th
        return tau, np.diag(-self.pm.damping - self.pm.friction / vs * (1.0 - th * th))

    def rnea_derivatives(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
        """``(dtau/dq, dtau/dqd)`` of armdyn's inverse dynamics (joint friction included) from
        ``pin.computeRNEADerivatives``, in armdyn's order."""
        vp = self.v_pin(qd)
        dq, dv, _ = self.pin.computeRNEADerivatives(
            self.pm, self.pd, self.q_pin(q), vp, self.v_pin(qdd)
        )
        # armdyn's tau = rnea - tau_f: the friction's derivative enters with a minus sign
        return self.matrix(dq), self.matrix(dv - self.friction(vp)[1])

    def aba_derivatives(self, q, qd, tau) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(dqdd/dq, dqdd/dqd, dqdd/dtau)`` of armdyn's forward dynamics (joint friction
        acting) from ``pin.computeABADerivatives``, in armdyn's order."""
        vp = self.v_pin(qd)
        tau_f, dtau_f = self.friction(vp)
        dq, dv, minv = (
            np.array(m)
            for m in self.pin.computeABADerivatives(
                self.pm, self.pd, self.q_pin(q), vp, self.v_pin(tau) + tau_f
            )
        )
        minv = symmetric(minv)
        return self.matrix(dq), self.matrix(dv + minv @ dtau_f), self.matrix(minv)


def interleaved_cpu_times(fns: dict, number: int, repeat: int) -> dict:
    """``common.interleaved_times`` on the process's CPU clock: on the shared 2-core machine
    (load averages of 10 are common) the wall clock counts the time other processes hold the
    core, the CPU clock does not. The batch calls run on one thread, so their CPU time is their
    running time."""
    for fn in fns.values():
        fn()
    rounds = {name: [] for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            t0 = time.process_time()
            for _ in range(number):
                fn()
            rounds[name].append((time.process_time() - t0) / number)
    out = {name: float(np.median(t)) for name, t in rounds.items()}
    out["rounds"] = rounds
    return out


def rel_error(obs, ref) -> float:
    """Largest deviation relative to the reference's largest entry."""
    obs, ref = np.asarray(obs), np.asarray(ref)
    return float(np.abs(obs - ref).max() / np.abs(ref).max())


def python_timings(pair: DerivativePair, number: int, repeat: int) -> dict:
    """Microseconds per call from Python, one state per call, and the armdyn / Pinocchio ratios
    (median over interleaved rounds of the round's ratio)."""
    pin, pm, pd, am = pair.pin, pair.pm, pair.pd, pair.am
    q, qd, x = pair.random_state(np.random.default_rng(1))
    qp, vp, xp = pair.q_pin(q), pair.v_pin(qd), pair.v_pin(x)
    t = interleaved_cpu_times(
        {
            "pin_rnea_derivatives": lambda: pin.computeRNEADerivatives(pm, pd, qp, vp, xp),
            "armdyn_inverse_dynamics_derivatives": lambda: ad.inverse_dynamics_derivatives(
                am, q, qd, x
            ),
            "pin_aba_derivatives": lambda: pin.computeABADerivatives(pm, pd, qp, vp, xp),
            "armdyn_forward_dynamics_derivatives": lambda: ad.forward_dynamics_derivatives(
                am, q, qd, x
            ),
            "pin_rnea": lambda: pin.rnea(pm, pd, qp, vp, xp),
            "armdyn_inverse_dynamics": lambda: ad.inverse_dynamics(am, q, qd, x),
        },
        number,
        repeat,
    )
    r = {f"{name}_us": 1e6 * t[name] for name in t if name != "rounds"}
    r["ratio_inverse_dynamics_derivatives"] = common.paired_ratio(
        t, "armdyn_inverse_dynamics_derivatives", "pin_rnea_derivatives"
    )
    r["ratio_forward_dynamics_derivatives"] = common.paired_ratio(
        t, "armdyn_forward_dynamics_derivatives", "pin_aba_derivatives"
    )
    # context: each library's derivative call over its own inverse dynamics call, from Python
    r["armdyn_id_derivatives_over_id"] = common.paired_ratio(
        t, "armdyn_inverse_dynamics_derivatives", "armdyn_inverse_dynamics"
    )
    r["pin_rnea_derivatives_over_rnea"] = common.paired_ratio(t, "pin_rnea_derivatives", "pin_rnea")
    # the reference implementation against the 4x-inverse-dynamics bar (each call's
    # Python overhead included on both sides)
    r["armdyn_fd_derivatives_over_id"] = common.paired_ratio(
        t, "armdyn_forward_dynamics_derivatives", "armdyn_inverse_dynamics"
    )
    r["pin_aba_derivatives_over_rnea"] = common.paired_ratio(t, "pin_aba_derivatives", "pin_rnea")
    return r


def batch_timings(pair: DerivativePair, rows: int, number: int, repeat: int) -> dict:
    """Per-row microseconds of the 2-D batch calls (one call on ``rows`` states, the loop in
    C++), the derivative calls over the batch ``inverse_dynamics`` (and ``forward_dynamics``),
    and the batch answers' worst relative error against Pinocchio on the first states."""
    am = pair.am
    q, qd, x = pair.random_state(np.random.default_rng(2), rows)
    t = interleaved_cpu_times(
        {
            "inverse_dynamics": lambda: ad.inverse_dynamics(am, q, qd, x),
            "inverse_dynamics_derivatives": lambda: ad.inverse_dynamics_derivatives(am, q, qd, x),
            "forward_dynamics": lambda: ad.forward_dynamics(am, q, qd, x),
            "forward_dynamics_derivatives": lambda: ad.forward_dynamics_derivatives(am, q, qd, x),
        },
        number,
        repeat,
    )
    r = {"rows": rows}
    r.update({f"{name}_us_per_row": 1e6 * t[name] / rows for name in t if name != "rounds"})
    r["ratio_inverse_dynamics_derivatives_to_inverse_dynamics"] = common.paired_ratio(
        t, "inverse_dynamics_derivatives", "inverse_dynamics"
    )
    r["ratio_forward_dynamics_derivatives_to_inverse_dynamics"] = common.paired_ratio(
        t, "forward_dynamics_derivatives", "inverse_dynamics"
    )
    r["ratio_forward_dynamics_derivatives_to_forward_dynamics"] = common.paired_ratio(
        t, "forward_dynamics_derivatives", "forward_dynamics"
    )
    r.update(batch_errors(pair, q, qd, x))
    return r


def batch_errors(pair: DerivativePair, q, qd, x, states: int = 20) -> dict:
    """Worst relative error of the batch answers against Pinocchio's over the first states."""
    am = pair.am
    ours_id = ad.inverse_dynamics_derivatives(am, q, qd, x)
    ours_fd = ad.forward_dynamics_derivatives(am, q, qd, x)
    worst_id = worst_fd = 0.0
    for i in range(min(states, len(q))):
        ref = pair.rnea_derivatives(q[i], qd[i], x[i])
        worst_id = max(worst_id, *(rel_error(o[i], r) for o, r in zip(ours_id, ref, strict=True)))
        ref = pair.aba_derivatives(q[i], qd[i], x[i])
        worst_fd = max(worst_fd, *(rel_error(o[i], r) for o, r in zip(ours_fd, ref, strict=True)))
    return {"id_derivatives_rel_error": worst_id, "fd_derivatives_rel_error": worst_fd}


def run(number: int = 500, rows: int = 1000, repeat: int = 15, echo: bool = True) -> dict:
    """Every robot's timings and errors (:func:`python_timings`, :func:`batch_timings`)."""
    out = {}
    for name, (_, fixed) in ROBOTS.items():
        pair = DerivativePair(robot_path(name), fixed_base=fixed)
        rec = {
            "fixed_base": fixed,
            "n_dofs": pair.am.n_dofs,
            "python": python_timings(pair, number, repeat),
            "cpp": batch_timings(pair, rows, 3, repeat),
        }
        p, c = rec["python"], rec["cpp"]
        rec["meets_targets"] = {
            "python_inverse": p["ratio_inverse_dynamics_derivatives"] <= TARGET_PYTHON,
            "python_forward": p["ratio_forward_dynamics_derivatives"] <= TARGET_PYTHON,
            "cpp_inverse": c["ratio_inverse_dynamics_derivatives_to_inverse_dynamics"]
            <= TARGET_CPP,
            "cpp_forward": c["ratio_forward_dynamics_derivatives_to_inverse_dynamics"]
            <= TARGET_CPP,
        }
        out[name] = rec
        if echo:
            print(summary_line(name, rec), flush=True)
    return out


def summary_line(name: str, rec: dict) -> str:
    p, c = rec["python"], rec["cpp"]
    return (
        f"{name:7s} n={rec['n_dofs']:2d}  Python: ID-deriv "
        f"{p['armdyn_inverse_dynamics_derivatives_us']:.2f} us / pin "
        f"{p['pin_rnea_derivatives_us']:.2f} us = {p['ratio_inverse_dynamics_derivatives']:.2f}x, "
        f"FD-deriv {p['armdyn_forward_dynamics_derivatives_us']:.2f} us / pin "
        f"{p['pin_aba_derivatives_us']:.2f} us = {p['ratio_forward_dynamics_derivatives']:.2f}x"
        f" (pin ABA-deriv / pin rnea {p['pin_aba_derivatives_over_rnea']:.2f}x)"
        f"  |  C++ batch per row: ID {c['inverse_dynamics_us_per_row']:.2f} us, ID-deriv "
        f"{c['inverse_dynamics_derivatives_us_per_row']:.2f} us = "
        f"{c['ratio_inverse_dynamics_derivatives_to_inverse_dynamics']:.2f}x, FD-deriv "
        f"{c['forward_dynamics_derivatives_us_per_row']:.2f} us = "
        f"{c['ratio_forward_dynamics_derivatives_to_inverse_dynamics']:.2f}x ID"
        f"  |  errors vs pin {c['id_derivatives_rel_error']:.1e}, "
        f"{c['fd_derivatives_rel_error']:.1e}"
    )


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--number", type=int, default=500, help="calls per round (Python side)")
    p.add_argument("--rows", type=int, default=1000, help="states in the batch calls")
    p.add_argument("--repeat", type=int, default=15, help="interleaved rounds")
    args = p.parse_args(argv)
    robots = run(args.number, args.rows, args.repeat)
    common.write_json(
        common.RESULTS / "derivatives.json",
        {
            "command": " ".join(["python -m benchmarks.derivatives", *sys.argv[1:]]),
            "machine": common.machine(),
            "targets": {
                "python_ratio_to_pinocchio": TARGET_PYTHON,
                "cpp_batch_ratio_to_inverse_dynamics": TARGET_CPP,
            },
            "robots": robots,
        },
    )


if __name__ == "__main__":
    main()
