"""The run options of :func:`armdyn.simulate` and :func:`armdyn.rollout`, declared once: name,
default, check, the form the C++ run takes it in, and the docstring entry.

Everything else follows from :data:`RUN_OPTIONS`: the checks of both functions
(:func:`core_options`), rollout's list of the options it forwards and their defaults, and the
options' entries in both docstrings (:func:`document`). ``simulate``'s signature spells the
options out as keyword arguments (so that IDEs and type checkers show them);
``tests/simulate/test_run_options.py`` checks that it names them with these defaults, in this
order."""

from __future__ import annotations

import textwrap
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from armdyn import _checks

#: the integrators simulate takes (None: the default choice)
INTEGRATORS = ("dopri5", "dop853", "rk4", "trbdf2", "kinematic", "auto")


@dataclass(frozen=True)
class RunOption:
    """One run option.

    Attributes:
        name: the keyword argument.
        default: its default in ``simulate``'s signature (and rollout's when not given).
        check: ``check(who, name, value)``: the value checked (a ModelError naming ``who`` and
            the option, saying what it allows), as :mod:`armdyn._checks` does it.
        core: the checked value as ``_core._simulate`` / ``_core._rollout`` take it.
        doc: its entry in the docstrings' ``Args`` (continuation lines unindented).
    """

    name: str
    default: Any
    check: Callable[[str, str, Any], Any]
    core: Callable[[Any], Any]
    doc: str


def _positive(none: bool = False):
    return lambda who, name, v: _checks.number(who, name, v, lo=0.0, lo_open=True, none=none)


def _choice(allowed: tuple[str, ...], none: bool = False):
    return lambda who, name, v: _checks.choice(who, name, v, allowed, none=none)


def _as_is(value: Any) -> Any:
    return value


def _zero_if_none(value: float | None) -> float:
    return value or 0.0


RUN_OPTIONS: tuple[RunOption, ...] = (
    RunOption(
        "integrator",
        None,
        _choice(INTEGRATORS, none=True),
        lambda v: "default" if v is None else v,
        """``"dopri5"`` (Dormand–Prince 5(4), error control, dense output),
``"dop853"`` (Dormand–Prince 8(5,3), error control, 7th-order dense output: for
tight tolerances), ``"rk4"`` (classical fixed step ``dt``), ``"trbdf2"``
(L-stable implicit TR-BDF2 with error control, for stiff scenes), ``"kinematic"``
(a fully driven model: each output state is solved from the constraints, nothing is
integrated), or ``"auto"``: kinematic when the drives leave no degree of freedom
(and outputs are on an ``output_dt`` grid), else TR-BDF2 when the stiffness
estimate of the force elements says an explicit method would need more than 5000
steps for stability alone, else DOP853 for ``rtol <= 1e-7`` and DOPRI5 above.
Default (``None``): kinematic for a fully driven model with ``output_dt``, else
DOPRI5. A fully driven model has nothing to integrate: its DOPRI5 run only supplies
starting guesses to the same position, velocity and acceleration problems, so both
give the same outputs. ``stats["integrator"]`` and ``stats["integrator_reason"]``
say which was used and why.""",
    ),
    RunOption(
        "rtol",
        1e-6,
        _positive(),
        _as_is,
        "relative error-control tolerance on every component of (u, v).",
    ),
    RunOption(
        "atol",
        1e-8,
        _positive(),
        _as_is,
        "absolute error-control tolerance on every component of (u, v).",
    ),
    RunOption(
        "dt",
        None,
        _positive(none=True),
        _zero_if_none,
        """RK4 step (required for rk4); DOPRI5/DOP853/TR-BDF2 initial step (optional). It
must advance time: at least ``64 eps t_end`` (about 1.4e-14 t_end), else a
ModelError naming ``dt``.""",
    ),
    RunOption(
        "output_dt",
        None,
        _positive(none=True),
        _zero_if_none,
        """spacing of output times (default: every accepted step). Output states are
interpolated (the integrator's dense output) and projected onto the constraints.""",
    ),
    RunOption(
        "projection",
        "mass",
        _choice(("mass", "unweighted")),
        _as_is,
        """metric of the minimum-norm projection: ``"mass"`` (kinetic-energy metric,
reuses the KKT factorisation) or ``"unweighted"`` (the paper's form).""",
    ),
    RunOption(
        "max_steps",
        10_000_000,
        lambda who, name, v: _checks.integer(who, name, v, lo=1),
        _as_is,
        "limit on steps.",
    ),
    RunOption(
        "max_step",
        None,
        _positive(none=True),
        _zero_if_none,
        "largest step of DOPRI5/DOP853/TR-BDF2 (default: no limit).",
    ),
    RunOption(
        "merge_welded",
        True,
        _checks.flag,
        _as_is,
        """integrate bodies joined by fixed joints as one composite body (fewer
bodies and rows: the same motion at lower cost); the outputs still cover every body
and joint, the fixed joints' reactions from their bodies' Newton–Euler balances.
``stats["solver_bodies"]`` / ``stats["solver_rows"]`` give the size integrated.""",
    ),
    RunOption(
        "coordinates",
        "auto",
        _choice(("cartesian", "joint", "auto")),
        _as_is,
        """``"auto"`` (default): the cheaper exact formulation for the scene: joint
space where it applies (a tree without drives, no light bodies on a geared model;
enforced joint limit stops too) and the measured cost model
(:func:`armdyn.dynamics_cost`) predicts its right-hand side cheaper, else
Cartesian. ``"cartesian"``: the bodies' Cartesian state with the
constrained Newton–Euler equations and the topological projection (the paper's
method; any mechanism). ``"joint"``: the joint coordinates and rates of a tree
without drives, ideal gears allowed: the mass matrix by the composite-rigid-body
algorithm, the bias and applied forces by recursive Newton–Euler, the gears
eliminated by their null space (far fewer states and a cheaper right-hand side;
the error control then acts on (q, qd)). Outputs are the same tables either way
(joint space builds them from (q, qd): reactions from the bodies' Newton–Euler
balances, the constraint residuals of the Cartesian state it reports).
``stats["formulation"]`` names the path taken (and for ``"auto"`` why).""",
    ),
    RunOption(
        "limits",
        "enforce",
        _choice(("enforce", "ignore")),
        lambda v: v == "enforce",
        """``"enforce"`` (default): every joint with one coordinate (revolute,
prismatic), a finite position limit (``set_joint_limits``, the URDF ``<limit>``;
``model.coord_lower``/``coord_upper``) and no drive is held within it by a
unilateral stop: the contact is located as an event, the impact is an impulse of the
whole mechanism (kinetic energy never rises), and the joint then rests on its stop,
held by a torque in ``limit_forces``, until the load pulls it off. While a joint is
held its state stands still, so the error control alone would let the steps grow
without bound and step over a load that reverses and comes back within one step:
the adaptive steps are then also bounded by the applied loads' profiles, at most
1/16 of each one's time scale (a sine's period, a cubic/quintic transition's
duration while in it, a spline's sample interval) and ending on their breakpoints
(a transition's start and end, a spline's samples), so that the holding force's
sign is sampled on the loads' own time scale; a callback profile has no known time
scale (``max_step`` bounds its steps). A run that starts outside a limit is
refused. ``"ignore"``: the limits play no part in the dynamics (they are still
checked by :func:`armdyn.limit_violations`).""",
    ),
    RunOption(
        "restitution",
        0.0,
        lambda who, name, v: _checks.number(who, name, v, lo=0.0, hi=1.0),
        _as_is,
        """the stops' coefficient of restitution in [0, 1]: 0 (default) a plastic
impact; e > 0 rebounds at e times the impact rate. A rebound too small to rise
1e-9·max(1, |limit|) off its stop against the acceleration back into it ends the
series of ever shorter bounces that would follow: the joint rests on the stop,
having lost the rebound's kinetic energy, as the whole series would.""",
    ),
)

NAMES: tuple[str, ...] = tuple(o.name for o in RUN_OPTIONS)
DEFAULTS: dict[str, Any] = {o.name: o.default for o in RUN_OPTIONS}


def core_options(who: str, values: Mapping[str, Any]) -> dict[str, Any]:
    """The run options in ``values`` (a mapping holding every one of :data:`NAMES`, e.g. the
    caller's ``locals()``) checked, in order, and as ``_core._simulate`` / ``_core._rollout``
    take them (keyword arguments); a ModelError naming ``who`` and the first bad option."""
    return {o.name: o.core(o.check(who, o.name, values[o.name])) for o in RUN_OPTIONS}


#: the lines of a docstring that :func:`document` fills in
ENTRIES_MARK = "{run options}"
NAMES_MARK = "{run option names}"


def document(doc: str) -> str:
    """``doc`` with the line holding :data:`ENTRIES_MARK` replaced by each option's ``Args``
    entry (at that line's indentation), and :data:`NAMES_MARK` by the options' names."""
    lines = []
    for line in doc.splitlines():
        if line.strip() == ENTRIES_MARK:
            indent = line[: len(line) - len(line.lstrip())]
            for o in RUN_OPTIONS:
                first, *rest = o.doc.splitlines()
                lines.append(f"{indent}{o.name}: {first}")
                lines.extend(f"{indent}    {r}" for r in rest)
        elif NAMES_MARK in line:
            indent = line[: len(line) - len(line.lstrip())]
            text = line.strip().replace(NAMES_MARK, ", ".join(NAMES))
            lines.extend(textwrap.wrap(text, 100, initial_indent=indent, subsequent_indent=indent))
        else:
            lines.append(line)
    return "\n".join(lines) + ("\n" if doc.endswith("\n") else "")
