"""Every URDF shipped in example-robot-data against Pinocchio (issue 21), with a fixed and with a
floating base: which load in armdyn, which match.

``python -m benchmarks.urdf_sweep [--json OUT]`` takes every ``*.urdf`` under the package's
``robots`` folder (69 files in 6.0.0) and, for each base:

- **Pinocchio** ``pin.buildModelFromUrdf(path)`` (fixed base) or with
  ``pin.JointModelFreeFlyer()`` (floating base), with ``mimic=True`` when the file has a
  ``<mimic>`` element; its mass matrix ``pin.crba`` (symmetrised) is checked for positive
  definiteness (smallest eigenvalue above ``PD_RTOL`` times the largest) at the random states.
- **armdyn** ``armdyn.load_urdf(path, fixed_base=...)``; when the refusal names a non-physical
  inertia (:data:`NONPHYSICAL`), again with ``physical_inertia=False`` (recorded as the option
  needed).
- where both load, at ``N_STATES`` seeded random states (Pinocchio configurations
  ``pin.integrate(neutral, u)``, u uniform in [-pi, pi]; velocities, torques and accelerations
  uniform in [-pi, pi]): ``armdyn.mass_matrix`` against ``pin.crba``,
  ``armdyn.forward_dynamics`` against ``pin.aba`` (on a mimic model, which ``pin.aba`` refuses,
  against ``M^-1 (tau - pin.rnea(q, v, 0))``) and ``armdyn.inverse_dynamics`` against
  ``pin.rnea``; each error is ``max|a - b| / max|b|`` over the entries, the worst over the
  states.

Coordinates are matched by joint name (:class:`CoordinateMap`): armdyn's joint coordinates are
the last ``n_coords - base`` entries of ``model.coord_names`` (or, when it lists more names, those
of the reference's independent joints, in armdyn's order). The floating base follows the
issue: armdyn's ``q = (x, y, z, e0, e1, e2, e3, joints...)`` with a scalar-first quaternion
(Pinocchio's is ``(x, y, z, qx, qy, qz, qw)``), and ``qd = (v, w, joint rates...)`` the root
frame's velocity in the root frame, Pinocchio's free-flyer convention; ``qdd`` and ``tau`` in the
same sense; ``model.n_dofs`` is the length of ``qd`` (``n_coords`` where the model has no such
attribute). A continuous joint is an angle in armdyn and ``(cos, sin)`` in Pinocchio.

The target of the issue (:func:`meets_target`, asserted per file and base by
``tests/peers/test_example_robot_data.py``): every URDF that Pinocchio loads with a positive
definite mass matrix loads in armdyn (by default, or with ``physical_inertia=False`` when the
default refusal names a non-physical inertia) and M, forward and inverse dynamics match to
``TOL``. Prints one row per file and the failures grouped by cause; ``--json`` writes every
record.
"""

from __future__ import annotations

import argparse
import functools
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import armdyn as ad
import numpy as np

from .common import machine, robots_dir, write_json
from .peers.pinocchio import mass_matrix

N_STATES = 5
SEED = 21
TOL = 1e-10  # the target, relative
PD_RTOL = 1e-12  # Pinocchio's M counts as positive definite above this eigenvalue ratio
BASES = ("fixed", "floating")
OPTION = "physical_inertia=False"
# an armdyn refusal that names a non-physical inertia (today's builder messages, and the option
# the issue asks the refusal to name)
NONPHYSICAL = re.compile(r"triangle inequality|not positive semi-?definite|physical_inertia")


def robot_files() -> list[Path]:
    """Every ``*.urdf`` of example-robot-data, sorted by path; empty when it is not installed."""
    base = robots_dir()
    return [] if base is None else sorted(base.rglob("*.urdf"))


def label(path: Path) -> str:
    """``<package folder>/<file>``: short and unique (two files are called ``anymal.urdf``)."""
    path = Path(path)
    base = robots_dir()
    top = path.relative_to(base).parts[0] if base and path.is_relative_to(base) else ""
    return f"{top}/{path.name}" if top else path.name


def mimics(path: Path) -> dict[str, tuple[str, float, float]]:
    """The URDF's ``<mimic>`` couplings: joint -> (the joint it follows, multiplier, offset), for
    the joints of the robot (``<joint>`` children of ``<robot>``; comments do not count)."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        return {}
    out = {}
    for j in root.findall("joint"):
        m = j.find("mimic")
        if m is not None:
            out[j.get("name")] = (
                m.get("joint"),
                float(m.get("multiplier", "1")),
                float(m.get("offset", "0")),
            )
    return out


def urdf_joints(path: Path) -> set[str]:
    """The names of the URDF's joints."""
    try:
        return {j.get("name") for j in ET.parse(path).getroot().findall("joint")}
    except ET.ParseError:
        return set()


def has_mimic(path: Path) -> bool:
    return bool(mimics(path))


def _why(e: BaseException) -> str:
    return f"{type(e).__name__}: {e}"


class Reference:
    """Pinocchio's model of one file and its joint-space functions, in the coordinates armdyn's
    joint space should have: a free flyer first for a floating base, then one coordinate per
    independent joint.

    With ``<mimic>`` couplings this is ``pin.buildModelFromUrdf(..., mimic=True)``; where that
    refuses (Pinocchio 4.1 does on ``romeo.urdf`` and ``talos_full_v2*.urdf``: "The parent joint
    of the mimic joint is not in the kinematic tree"), or with ``project``, the model without
    couplings projected on the independent coordinates as Pinocchio's mimic model does:
    ``q_j = m q_k + o``, ``v = G u``, ``M = G^T M_full G``, ``tau = G^T rnea(q, G u, G du)``
    (``how`` says which). Forward dynamics is ``pin.aba`` where the model has no mimic joint,
    else ``M^-1 (tau - bias)`` (``pin.aba`` refuses mimic joints). A ``<mimic>`` that follows a
    joint the file does not have leaves no reference (``model`` None, ``error`` says why)."""

    def __init__(self, path: Path, floating: bool, project: bool = False, friction: bool = True):
        import pinocchio as pin

        self.pin = pin
        self.floating = floating
        self.couplings = mimics(path)
        self.model = self.data = self.G = None
        self.how, self.error = "", None
        self.follow = []  # (q index of a mimic joint, of its leader, multiplier, offset)
        joints = urdf_joints(path)
        unknown = {j: c[0] for j, c in self.couplings.items() if c[0] not in joints}
        if unknown:  # the file's error
            self.error = "BadMimic: " + ", ".join(
                f"joint '{j}' mimics '{k}', which the URDF does not have"
                for j, k in unknown.items()
            )
            return
        root = [pin.JointModelFreeFlyer()] if floating else []
        try:
            if self.couplings and not project:
                try:
                    self.model = pin.buildModelFromUrdf(str(path), *root, mimic=True)
                    self.how = "mimic=True"
                except Exception as e:  # a Pinocchio limitation, recorded
                    self.how = f"mimic=True refused ({_why(e)}); projected"
            if self.model is None:
                self.model = pin.buildModelFromUrdf(str(path), *root)
                self.how = self.how or ("projected" if self.couplings else "")
        except Exception as e:  # every failure is a result here
            self.model, self.error = None, _why(e)
            return
        pm = self.model
        self.data = pm.createData()
        # the URDF's <dynamics damping friction>, which armdyn imports as joint friction
        # (-damping v - friction tanh(v / v_s)) and Pinocchio's algorithms leave out; a mimic=True
        # model drops the followers' entries, so a file with friction on a follower takes the
        # projected reference (the follower's joint turns, its friction acts)
        self.with_friction = friction
        if (
            friction
            and self.how == "mimic=True"
            and any(pm_plain_has_friction(path, name) for name in self.couplings)
        ):
            self.model = pin.buildModelFromUrdf(str(path), *root)
            self.how = "mimic=True drops the followers' friction; projected"
            pm = self.model
            self.data = pm.createData()
        # independent joints with coordinates: name -> (index in q, index in v, kind)
        self.joints: dict[str, tuple[int, int, str]] = {}
        projected = self.how.endswith("projected")
        self._aba = not projected and all(
            pm.joints[j].shortname() != "JointModelMimic" for j in range(1, pm.njoints)
        )
        first = 2 if floating else 1
        for j in range(first, pm.njoints):
            jm = pm.joints[j]
            if jm.nq == 0 or (projected and pm.names[j] in self.couplings):
                continue  # a mimic joint
            kind = {(1, 1): "scalar", (2, 1): "unbounded"}.get((jm.nq, jm.nv))
            if kind is None:
                raise CoordinateMismatch(f"Pinocchio's joint '{pm.names[j]}' is {jm.shortname()}")
            self.joints[pm.names[j]] = (jm.idx_q, jm.idx_v, kind)
        self.nv = ((6 if floating else 0) + len(self.joints)) if projected else pm.nv
        if projected:
            self._project()

    def _project(self):
        pm = self.model
        idx = {pm.names[j]: j for j in range(1, pm.njoints)}
        g = np.zeros((pm.nv, self.nv))
        if self.floating:
            g[:6, :6] = np.eye(6)
        reduced = {}
        for k, (name, (iq, iv, kind)) in enumerate(self.joints.items()):
            reduced[name] = (6 if self.floating else 0) + k
            g[iv, reduced[name]] = 1.0
            self.joints[name] = (iq, reduced[name], kind)
        for name, (leader, mult, off) in self.couplings.items():
            if name not in idx or pm.joints[idx[name]].nq == 0:
                continue  # a fixed joint in the URDF
            if leader not in reduced:
                raise CoordinateMismatch(
                    f"mimic joint '{name}' follows '{leader}', not independent"
                )
            jm = pm.joints[idx[name]]
            if (jm.nq, jm.nv) != (1, 1) or self.joints[leader][2] != "scalar":
                raise CoordinateMismatch(f"mimic joint '{name}' is {jm.shortname()}")
            g[jm.idx_v, reduced[leader]] = mult
            self.follow.append((jm.idx_q, self.joints[leader][0], mult, off))
        self.G = g

    def states(self, n: int, seed: int):
        """``n`` seeded random states ``(q, v, tau, a)``: ``q`` Pinocchio's configuration
        (``pin.integrate`` from the neutral one by a uniform step in [-pi, pi]), the others in the
        reference's velocity space, uniform in [-pi, pi]."""
        pin, pm = self.pin, self.model
        rng = np.random.default_rng(seed)
        out = []
        for _ in range(n):
            q = pin.integrate(pm, pin.neutral(pm), rng.uniform(-np.pi, np.pi, pm.nv))
            for iq, il, mult, off in self.follow:
                q[iq] = mult * q[il] + off
            v, tau, a = rng.uniform(-np.pi, np.pi, size=(3, self.nv))
            out.append((q, v, tau, a))
        return out

    def friction(self, v_full):
        """The joint friction torques at the model's velocity v_full (Pinocchio order)."""
        if not self.with_friction:
            return np.zeros_like(v_full)
        vs = ad._core.URDF_COULOMB_SMOOTHING
        return -self.model.damping * v_full - self.model.friction * np.tanh(v_full / vs)

    def _lift(self, u):
        return u if self.G is None else self.G @ u

    def _reduce(self, f):
        return f if self.G is None else self.G.T @ f

    def mass_matrix(self, q) -> np.ndarray:
        m = mass_matrix(self.pin, self.model, self.data, q)
        return m if self.G is None else self.G.T @ m @ self.G

    def rnea(self, q, v, a) -> np.ndarray:
        vf = self._lift(v)
        tau = self.pin.rnea(self.model, self.data, q, vf, self._lift(a)) - self.friction(vf)
        return self._reduce(tau)

    def forward_dynamics(self, q, v, tau, m=None) -> np.ndarray:
        if self._aba:
            return self.pin.aba(self.model, self.data, q, v, tau + self.friction(v))
        m = self.mass_matrix(q) if m is None else m
        return np.linalg.solve(m, tau - self.rnea(q, v, np.zeros(self.nv)))


@functools.cache
def pm_plain_has_friction(path: Path, joint: str) -> bool:
    """Whether the URDF gives joint ``joint`` a nonzero <dynamics damping/friction>."""
    import xml.etree.ElementTree as ET

    for e in ET.parse(path).getroot().findall("joint"):
        if e.get("name") == joint:
            d = e.find("dynamics")
            return d is not None and any(
                float(d.get(k, "0") or 0) != 0.0 for k in ("damping", "friction")
            )
    return False


def reference(path: Path, floating: bool) -> Reference:
    return Reference(path, floating)


@dataclass(frozen=True)
class ArmdynLoad:
    model: ad.Model | None
    option: str  # "" or OPTION: what the load needed (or what was tried last)
    error: str | None


@functools.cache
def armdyn_model(path: Path, floating: bool) -> ArmdynLoad:
    """armdyn's model of the file, the option it needed and, when it does not load, why (the
    exception's type and message; a second attempt with ``physical_inertia=False`` when the first
    refusal names a non-physical inertia)."""
    kw = {"fixed_base": not floating}
    try:
        return ArmdynLoad(ad.load_urdf(str(path), **kw), "", None)
    except Exception as e:
        first = _why(e)
    if not NONPHYSICAL.search(first):
        return ArmdynLoad(None, "", first)
    try:
        return ArmdynLoad(ad.load_urdf(str(path), physical_inertia=False, **kw), OPTION, None)
    except Exception as e:
        return ArmdynLoad(None, OPTION, f"{first}; then with {OPTION}: {_why(e)}")


class CoordinateMismatch(Exception):
    """armdyn's and Pinocchio's joint spaces cannot be matched name by name."""


class CoordinateMap:
    """The reference's ``(q, v)`` <-> armdyn's ``(q, qd)`` for one model pair, by joint name."""

    def __init__(self, ref: Reference, am: ad.Model):
        self.nq = int(am.n_coords)
        self.nv = int(getattr(am, "n_dofs", am.n_coords))
        self.floating = ref.floating
        bq, bv = (7, 6) if ref.floating else (0, 0)
        names = list(am.coord_names)
        nj = self.nq - bq
        if nj < 0 or self.nv - bv != nj or len(names) < nj:
            raise CoordinateMismatch(
                f"armdyn's model has n_coords {self.nq}, n_dofs {self.nv} and "
                f"{len(names)} coordinate names; a {'floating' if ref.floating else 'fixed'} "
                f"base needs {bq} + {bv} base coordinates before the joints'"
            )
        if len(names) in (nj, self.nq):  # joint names, after the base's if it has any
            joints = names[len(names) - nj :]
        else:  # names of dependent (coupled) joints too: the reference's independent ones
            joints = [n for n in names if n in ref.joints]
            if len(joints) != nj:
                raise CoordinateMismatch(
                    f"armdyn's model has n_coords {self.nq} and {len(names)} coordinate names, "
                    f"{len(joints)} of them independent joints of Pinocchio's model"
                )
        if len(set(joints)) != nj:
            raise CoordinateMismatch(f"armdyn's coordinate names repeat: {joints}")
        extra = [n for n in joints if n not in ref.joints]
        missing = [n for n in ref.joints if n not in joints]
        if extra or missing:
            what = "Pinocchio's " + (f"{ref.how} model" if ref.how else "model")
            raise CoordinateMismatch(
                f"armdyn's coordinates not in {what}: {extra}; {what}'s not in armdyn's: {missing}"
            )
        self.q_pairs = [(ref.joints[n][0], bq + i, ref.joints[n][2]) for i, n in enumerate(joints)]
        # v_reference = qd_armdyn[self.v_index]
        self.v_index = np.empty(ref.nv, dtype=int)
        self.v_index[:bv] = np.arange(bv)
        for i, n in enumerate(joints):
            self.v_index[ref.joints[n][1]] = bv + i

    def q_to_armdyn(self, qp: np.ndarray) -> np.ndarray:
        qa = np.zeros(self.nq)
        if self.floating:  # (x, y, z, qx, qy, qz, qw) -> (x, y, z, e0, e1, e2, e3)
            qa[0:3], qa[3], qa[4:7] = qp[0:3], qp[6], qp[3:6]
        for p, a, kind in self.q_pairs:
            qa[a] = qp[p] if kind == "scalar" else np.arctan2(qp[p + 1], qp[p])
        return qa

    def v_to_armdyn(self, vp: np.ndarray) -> np.ndarray:
        va = np.empty(self.nv)
        va[self.v_index] = vp
        return va

    def v_to_pin(self, va: np.ndarray) -> np.ndarray:
        return np.asarray(va)[self.v_index]

    def m_to_pin(self, ma: np.ndarray) -> np.ndarray:
        return np.asarray(ma)[np.ix_(self.v_index, self.v_index)]


def rel_error(a, b) -> float:
    """``max|a - b| / max|b|``; 0 for two empty arrays, inf for arrays of different shapes."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        return float("inf")
    if b.size == 0:
        return 0.0
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


@functools.cache
def compare(path: Path, floating: bool, n_states: int = N_STATES, seed: int = SEED) -> dict:
    """One file with one base: what loads, Pinocchio's definiteness, the worst relative errors of
    ``M`` (mass matrix), ``fd`` (forward dynamics) and ``id`` (inverse dynamics), and where armdyn
    fails, at which ``stage`` and why (``failure``: the exception's type and message). Where
    Pinocchio's M is singular, armdyn's forward dynamics is still called: it must refuse."""
    path = Path(path)
    rec = {
        "robot": label(path),
        "path": str(path),
        "base": BASES[floating],
        "mimic": has_mimic(path),
        # <mimic> elements that follow a joint the file does not have: the file's error
        "bad_mimic": sorted(j for j, c in mimics(path).items() if c[0] not in urdf_joints(path)),
        "pin_loads": False,
        "pin_how": "",
        "pin_error": None,
        "pin_nq": None,
        "pin_nv": None,
        "pin_pd": None,
        "pin_min_eig_ratio": None,
        "armdyn_loads": False,
        "armdyn_option": "",
        "n_coords": None,
        "n_dofs": None,
        "compared": False,
        "M": None,
        "fd": None,
        "id": None,
        "stage": None,
        "failure": None,
    }
    try:
        ref = reference(path, floating)
    except CoordinateMismatch as e:
        ref = None
        rec["pin_error"] = f"CoordinateMismatch: {e}"
    if ref is not None and ref.model is None:
        rec["pin_error"] = ref.error
    elif ref is not None:
        rec.update(pin_loads=True, pin_how=ref.how, pin_nq=ref.model.nq, pin_nv=ref.nv)
        states = [(*s, ref.mass_matrix(s[0])) for s in ref.states(n_states, seed)]
        if ref.nv:
            ratio = min(float(np.linalg.eigvalsh(s[4])[0] / np.abs(s[4]).max()) for s in states)
            rec.update(pin_min_eig_ratio=ratio, pin_pd=ratio > PD_RTOL)

    al = armdyn_model(path, floating)
    rec["armdyn_option"] = al.option
    if al.model is None:
        rec.update(stage="load", failure=al.error)
        return rec
    am = al.model
    rec.update(
        armdyn_loads=True,
        n_coords=int(am.n_coords),
        n_dofs=int(getattr(am, "n_dofs", am.n_coords)),
    )
    if not rec["pin_loads"]:
        return rec
    rec.update(compare_models(ref, am, states, singular=rec["pin_pd"] is False))
    rec["compared"] = rec["failure"] is None
    return rec


def compare_models(ref: Reference, am: ad.Model, states, singular: bool = False) -> dict:
    """The worst relative errors (``M``, ``fd``, ``id``; None where not reached) of armdyn's model
    ``am`` against the reference at ``states`` (``(q, v, tau, a, M)`` in the reference's
    coordinates), and where armdyn failed: ``stage`` (coordinates, mass_matrix,
    forward_dynamics, inverse_dynamics) and ``failure`` (type and message). ``singular``: the
    reference's M is singular, so armdyn's forward dynamics must refuse rather than answer."""
    out = {"M": None, "fd": None, "id": None, "stage": None, "failure": None}
    try:
        cmap = CoordinateMap(ref, am)
    except CoordinateMismatch as e:
        # armdyn's own refusal of joint-space calls, when it has one, says more
        n, nd = int(am.n_coords), int(getattr(am, "n_dofs", am.n_coords))
        try:
            ad.forward_dynamics(am, np.zeros(n), np.zeros(nd), np.zeros(nd))
            why = f"CoordinateMismatch: {e}"
        except Exception as refusal:
            why = f"{_why(refusal)} ({e})"
        return {**out, "stage": "coordinates", "failure": why}

    worst = {}  # the comparisons made at least once
    stage = "mass_matrix"

    def update(key, got, want):
        worst[key] = max(worst.get(key, 0.0), rel_error(got, want))

    try:
        for qp, vp, tp, ap, mp in states:
            qa = cmap.q_to_armdyn(qp)
            va, ta, aa = (cmap.v_to_armdyn(x) for x in (vp, tp, ap))
            stage = "mass_matrix"
            update("M", cmap.m_to_pin(ad.mass_matrix(am, qa)), mp)
            stage = "forward_dynamics"
            fd = cmap.v_to_pin(ad.forward_dynamics(am, qa, va, ta))
            if singular:
                raise RuntimeError("the reference's M is singular but armdyn's answers")
            update("fd", fd, ref.forward_dynamics(qp, vp, tp, mp))
            stage = "inverse_dynamics"
            update("id", cmap.v_to_pin(ad.inverse_dynamics(am, qa, va, aa)), ref.rnea(qp, vp, ap))
    except Exception as e:
        out.update(stage=stage, failure=_why(e))
    return {**out, **worst}


REFUSALS = ("UrdfError:", "ModelError:", "SolverError:")  # armdyn's own, clear refusals


def is_target(rec: dict) -> bool:
    """Whether the issue's target covers the record: Pinocchio loads the file with a positive
    definite mass matrix (or, with a fixed base, with no degree of freedom at all)."""
    return rec["pin_loads"] and (rec["pin_nv"] == 0 or bool(rec["pin_pd"]))


def meets_target(rec: dict) -> str | None:
    """None when the record meets the issue's target, else why not.

    - Pinocchio's M positive definite: armdyn loads (by default, or with ``physical_inertia=False``
      after a refusal naming a non-physical inertia), and M, fd and id are within ``TOL``.
    - A fixed base with no moving joint (Pinocchio: zero degrees of freedom): armdyn loads it with
      no coordinate, or refuses with a message that suggests ``fixed_base=False``.
    - Pinocchio's M singular: armdyn refuses (its own error type, at load or at a joint-space
      call), never answers.
    - A ``<mimic>`` that follows a joint the file does not have: armdyn refuses the file, naming
      the mimic joint (Pinocchio's ``mimic=True`` refuses it too).
    - Pinocchio does not load the file (``ur3.urdf`` of 6.0.0 has no ``<link>``): armdyn refuses
      it too.
    """
    if rec["bad_mimic"]:
        failure = rec["failure"] or ""
        if rec["stage"] == "load" and failure.startswith(REFUSALS):
            if any(j in failure for j in rec["bad_mimic"]):
                return None
        return (
            f"<mimic> of {rec['bad_mimic']} follows a joint the URDF does not have, and armdyn "
            f"does not refuse the file naming it ({failure or 'loads'})"
        )
    if rec["pin_loads"] and rec["pin_pd"] is False:
        if (rec["failure"] or "").startswith(REFUSALS):
            return None
        return f"Pinocchio's M is singular and armdyn does not refuse: {rec['failure']}"
    if not rec["pin_loads"]:
        if rec["stage"] == "load" and (rec["failure"] or "").startswith(REFUSALS):
            return None
        return (
            f"Pinocchio refuses the file ({rec['pin_error']}) and armdyn does not refuse it "
            f"with its own error ({rec['failure'] or 'it loads'})"
        )
    if rec["pin_nv"] == 0 and not rec["armdyn_loads"]:
        if "fixed_base=False" in (rec["failure"] or ""):
            return None
        return f"zero-DOF model refused without suggesting fixed_base=False: {rec['failure']}"
    if rec["failure"] is not None:
        return f"{rec['stage']}: {rec['failure']}"
    bad = {k: rec[k] for k in ("M", "fd", "id") if rec[k] is None or not rec[k] <= TOL}
    if bad:
        return f"differs from Pinocchio beyond {TOL:g}: " + ", ".join(
            f"{k} {'not compared' if v is None else f'{v:.1e}'}" for k, v in bad.items()
        )
    return None


# causes of failures, for the summary: (label, test on the record and its failure text); the
# first that applies
CAUSES = (
    ("<mimic> of an unknown joint accepted", lambda r, t: bool(r["bad_mimic"])),
    ("singular M not refused", lambda r, t: r["pin_pd"] is False),
    ("loads what Pinocchio refuses", lambda r, t: not r["pin_loads"]),
    ("floating base refused", lambda r, t: "root_free" in t or "free joint" in t),
    ("zero-DOF model refused", lambda r, t: r["pin_nv"] == 0 or "no bodies" in t),
    ("massless link refused", lambda r, t: "has no mass" in t or "mass must be positive" in t),
    (
        f"non-physical inertia, no {OPTION}",
        lambda r, t: r["armdyn_option"] == OPTION and "physical_inertia" in t,
    ),
    ("non-physical inertia refused", lambda r, t: bool(NONPHYSICAL.search(t))),
    ("<mimic> dropped", lambda r, t: r["mimic"] and r["stage"] == "coordinates"),
    ("coordinates differ", lambda r, t: r["stage"] == "coordinates"),
    ("values differ", lambda r, t: t.startswith("differs")),
)


def cause(rec: dict, why: str) -> str:
    for name, test in CAUSES:
        if test(rec, why):
            return name
    return f"other ({rec['stage']})"


def short(text: str | None, n: int) -> str:
    text = " ".join((text or "").split())
    return text if len(text) <= n else text[: n - 1] + "…"


def sweep(files=None, n_states: int = N_STATES, seed: int = SEED) -> list[dict]:
    """Every record (:func:`compare`, with ``target``, ``meets_target``, ``why`` and ``cause``):
    each file with a fixed, then a floating base."""
    out = []
    for path in robot_files() if files is None else files:
        for floating in (False, True):
            rec = compare(Path(path), floating, n_states, seed)
            why = meets_target(rec)
            rec = {**rec, "target": is_target(rec), "meets_target": why is None, "why": why}
            rec["cause"] = cause(rec, why) if why else None
            out.append(rec)
    return out


def table(records: list[dict]):
    """One row per file (pandas DataFrame): Pinocchio's nq/nv (FAIL: not loaded) and
    definiteness, whether armdyn loads with each base and the option it needed, its n_coords
    (fixed base), the worst errors per base, and the cause per base where the target is missed."""
    import pandas as pd

    rows = {}
    for r in records:
        row = rows.setdefault(r["robot"], {"robot": r["robot"], "option": "", "misses": []})
        b = "fix" if r["base"] == "fixed" else "flo"
        if b == "fix":
            row["pin"] = f"{r['pin_nq']}/{r['pin_nv']}" if r["pin_loads"] else "FAIL"
            row["mimic"] = "mimic" if r["mimic"] else ""
            row["PD"] = {True: "yes", False: "NO", None: "-"}[r["pin_pd"]]
            row["n"] = "" if r["n_coords"] is None else r["n_coords"]
        row[f"ad {b}"] = "ok" if r["armdyn_loads"] else "FAIL"
        row["option"] = row["option"] or r["armdyn_option"]
        for k in ("M", "fd", "id"):
            row[f"{k} {b}"] = "" if r[k] is None else f"{r[k]:.0e}"
        if r["cause"]:
            row["misses"].append(f"{b}: {r['cause']}")
    df = pd.DataFrame(list(rows.values()))
    df["misses"] = df["misses"].map("; ".join)
    df["option"] = df["option"].map(lambda o: "no-phys" if o else "")
    cols = ["robot", "pin", "mimic", "PD", "ad fix", "ad flo", "option", "n"]
    cols += [f"{k} {b}" for b in ("fix", "flo") for k in ("M", "fd", "id")] + ["misses"]
    return df[cols]


def summary(records: list[dict]) -> dict:
    out = {}
    for base in BASES:
        rs = [r for r in records if r["base"] == base]
        fails = [r for r in rs if not r["meets_target"]]
        causes: dict[str, list[str]] = {}
        for r in fails:
            causes.setdefault(r["cause"], []).append(r["robot"])
        out[base] = {
            "files": len(rs),
            "pinocchio_loads": sum(r["pin_loads"] for r in rs),
            "pinocchio_pd": sum(bool(r["pin_pd"]) for r in rs),
            "target": sum(r["target"] for r in rs),
            "armdyn_loads": sum(r["armdyn_loads"] for r in rs),
            "needs_option": sum(r["armdyn_loads"] and r["armdyn_option"] == OPTION for r in rs),
            "compared": sum(r["compared"] for r in rs),
            "meet_target": sum(r["target"] and r["meets_target"] for r in rs),
            "worst": {
                k: max((r[k] for r in rs if r["compared"] and r[k] is not None), default=None)
                for k in ("M", "fd", "id")
            },
            "causes": causes,
        }
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", metavar="OUT", help="write every record and the summary here")
    args = ap.parse_args()
    import pandas as pd

    files = robot_files()
    if not files:
        raise SystemExit("example-robot-data is not installed")
    records = sweep(files)
    with pd.option_context("display.max_rows", None, "display.width", 250):
        print(table(records).to_string(index=False))
    s = summary(records)
    for base, c in s.items():
        w = c["worst"]
        print(
            f"\n{base} base: {c['files']} files; a Pinocchio reference for {c['pinocchio_loads']}, "
            f"positive definite {c['pinocchio_pd']} (target {c['target']}); armdyn loads "
            f"{c['armdyn_loads']} ({c['needs_option']} with {OPTION}), compared "
            f"{c['compared']}, meet the target {c['meet_target']}/{c['target']}; worst "
            + ", ".join(f"{k} {'-' if v is None else f'{v:.1e}'}" for k, v in w.items())
        )
        for name, robots in sorted(c["causes"].items(), key=lambda kv: -len(kv[1])):
            shown = ", ".join(robots[:4]) + (", …" if len(robots) > 4 else "")
            print(f"  {len(robots):3d}  {name}: {shown}")
            example = next(r for r in records if r["base"] == base and r["cause"] == name)
            print(f"       e.g. {short(example['why'], 160)}")
    if args.json:
        out = {
            "command": "python -m benchmarks.urdf_sweep --json " + args.json,
            "machine": machine(),
            "n_states": N_STATES,
            "seed": SEED,
            "tol": TOL,
            "summary": s,
            "records": records,
        }
        print("wrote", write_json(args.json, out))


if __name__ == "__main__":
    main()
