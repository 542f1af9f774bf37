"""``armdyn identify ROBOT.urdf --log FILE.csv --out DIR [--validate FILE.csv] [--cutoff HZ]
[--trim SECONDS] [--filter-tau] [--no-physical] [--method ols|wls] [--torque-constants K]
[--gear-ratios N] [--efficiency E]``: identify a robot's parameters from a measured log, from
the command line.

The steps: load the URDF (:func:`armdyn.load_urdf`; a fixed-base robot), read the log
(:func:`armdyn.identification.load_log`: a CSV with ``t``, one position column per joint named
as the joint, and ``<joint>.tau`` torques or ``<joint>.current`` currents; ``--cutoff`` low-pass
filters q before differentiating, and tau too with ``--filter-tau`` — by default tau is left as
logged, which :mod:`armdyn.identification.log` measures to bias a fit less, a filtered Coulomb
step being smeared; ``--trim`` drops that many seconds at each end),
identify (:func:`armdyn.identification.identify`, ``--method`` wls by default, physically
consistent unless ``--no-physical``), validate on data the fit did not use (the ``--validate``
log, read like the fit log; without it the log is split in time: the first
:data:`FIT_FRACTION` (70 %) fits, the rest validates) and write into DIR (created if missing):

- ``identified.urdf``: the URDF with the identified ``<inertial>`` and the identified friction
  as ``<dynamics damping friction>`` (:func:`armdyn.identification.write_urdf`);
- ``report.html``, ``torques.png``, ``parameters.csv``, ``base_parameters.csv``
  (:func:`armdyn.identification.write_report`).

It prints the per-joint verdict (validation RMSE of the identified and the nominal model) and the
files written. Exit code 0 when it ran (the verdict is in the report); 1 when, with
``--no-physical``, the unconstrained estimate cannot be a URDF (a negative mass, friction or
rotor inertia: the report is written, ``identified.urdf`` is not); 2 for bad input: a
missing, unreadable or special file (directory, FIFO, device), a malformed or empty log, unknown
or missing joints, non-finite values, an unwritable DIR, a log that does not excite every base
parameter — one line on stderr naming the command and the culprit.

``--torque-constants`` and ``--gear-ratios`` (for logs with ``<joint>.current`` columns; torque =
gear ratio x torque constant x current [x efficiency]) take one number for every joint, one per
joint in the model's order (``0.07,0.07,...``), or ``JOINT=VALUE`` pairs
(``elbow_joint=0.07,wrist_1_joint=0.05``); a list starting with a minus sign needs the ``=`` form
(``--gear-ratios=-50,100``). They apply to both logs (the ``--validate`` log then has current
columns too).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from armdyn import _core

#: without --validate: the share of the log (by time) the fit uses; the rest validates
FIT_FRACTION = 0.7


def per_joint(option: str, text: str | None):
    """The value of ``--torque-constants`` / ``--gear-ratios`` / ``--efficiency``: None, a
    float (every joint), a list of floats (one per joint) or a dict ``{joint: float}``."""
    if text is None:
        return None
    parts = [p.strip() for p in text.split(",")]
    if any(not p for p in parts):
        raise _core.ModelError(
            f"{option} {text!r}: an empty entry (expected VALUE[,VALUE...] or "
            "JOINT=VALUE[,JOINT=VALUE...])"
        )
    named = ["=" in p for p in parts]
    if any(named) and not all(named):
        raise _core.ModelError(f"{option} {text!r}: either every entry is JOINT=VALUE or none is")
    if all(named):
        out = {}
        for p in parts:
            joint, value = (s.strip() for s in p.split("=", 1))
            if joint in out:
                raise _core.ModelError(f"{option} {text!r}: joint {joint!r} given twice")
            out[joint] = _finite(option, text, value)
        return out
    values = [_finite(option, text, p) for p in parts]
    return values[0] if len(values) == 1 else values


def _finite(option: str, whole: str, text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        x = float("nan")
    if not np.isfinite(x):
        raise _core.ModelError(f"{option} {whole!r}: {text!r} is not a finite number")
    return x


def _expand(value, model):
    """A single number becomes one per coordinate (what load_log takes)."""
    if isinstance(value, float):
        return [value] * model.n_coords
    return value


def _not_a_file(out: str) -> None:
    if Path(out).exists() and not Path(out).is_dir():
        raise _core.ModelError(f"--out {out!r} exists and is not a folder")


def _out_dir(out: str) -> Path:
    """DIR, created if missing and checked writable (before the fit)."""
    _not_a_file(out)
    path = Path(out)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _core.ModelError(f"--out {out!r}: cannot create the folder: {exc}") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise _core.ModelError(f"--out {out!r}: the folder is not writable")
    return path


def _cutoff(text: str | None) -> float | None:
    if text is None:
        return None
    x = _finite("--cutoff", text, text)
    if x <= 0:
        raise _core.ModelError(f"--cutoff {text!r}: the cutoff must be > 0 Hz")
    return x


def _trim(text: str | None) -> float:
    if text is None:
        return 0.0
    x = _finite("--trim", text, text)
    if x < 0:
        raise _core.ModelError(f"--trim {text!r}: must be >= 0 s")
    return x


def run(args, echo=print) -> int:
    """The ``armdyn identify`` command (see the module notes); returns the exit code."""
    from armdyn.identification.report import joint_status
    from armdyn.identification.validate import validate
    from armdyn.urdf import load_urdf

    if args.method not in ("ols", "wls"):
        raise _core.ModelError(f"--method {args.method!r}: expected ols or wls")
    options = {
        "cutoff": _cutoff(args.cutoff),
        "trim": _trim(args.trim),
        "torque_constants": per_joint("--torque-constants", args.torque_constants),
        "gear_ratios": per_joint("--gear-ratios", args.gear_ratios),
        "efficiency": per_joint("--efficiency", args.efficiency),
        "filter_tau": bool(args.filter_tau),
    }
    _not_a_file(args.out)
    model = load_urdf(args.urdf)
    if model.n_free:
        raise _core.ModelError(
            f"{args.urdf}: a floating base; identification takes fixed-base arms"
        )
    for key in ("torque_constants", "gear_ratios", "efficiency"):
        options[key] = _expand(options[key], model)
    fit_log, val_log = _logs(args, model, options)
    out = _out_dir(args.out)
    ident = _identify(model, fit_log, args)
    validation = validate(ident, val_log)
    nominal = validate(model, val_log)
    least_squares = None
    if ident.physical:  # what the consistency costs: the unconstrained estimate's validation
        pi_ls = ident.base.complete(ident.beta_ls, _core.dynamic_parameters(model))
        least_squares = validate(model, val_log, pi=pi_ls)
    logs = (fit_log, val_log)
    validations = (validation, nominal, least_squares)
    files, no_urdf = _write(args, out, model, ident, logs, validations)
    statuses = joint_status(validation, ident.sigma)
    _summary(echo, ident, validations, statuses, fit_log, val_log, args)
    for f in files:
        echo(f"wrote {f}")
    if no_urdf:
        print(
            f"armdyn identify: identified.urdf not written: {no_urdf} (the unconstrained "
            "estimate is not a physical model: drop --no-physical)",
            file=sys.stderr,
        )
        return 1
    return 0


def _logs(args, model, options):
    log = _read("--log", args.log, model, options)
    if args.validate is not None:
        return log, _read("--validate", args.validate, model, options)
    try:
        return log.split(FIT_FRACTION)
    except _core.ModelError as exc:
        raise _core.ModelError(
            f"--log {args.log!r}: {len(log.t)} samples cannot be split into a fit part (the first "
            f"{FIT_FRACTION:.0%}) and a validation part ({exc}); give a longer log or --validate"
        ) from None


def _read(option: str, path: str, model, options):
    """load_log of ``path``; a failure names the option."""
    from armdyn.identification.log import load_log

    try:
        return load_log(path, model, **options)
    except (_core.ModelError, OSError) as exc:
        text = str(exc)
        for name in ("torque_constants", "gear_ratios"):  # load_log's keywords: the options
            text = text.replace(name, "--" + name.replace("_", "-"))
        raise _core.ModelError(f"{option}: {text}") from None


def _identify(model, log, args):
    from armdyn.identification.estimate import identify

    return identify(model, log, method=args.method, physical=not args.no_physical)


def _log_notes(args, fit_log, val_log) -> dict[str, str]:
    """The report's description of the two logs."""
    if args.validate is not None:
        return {"fit (--log)": fit_log.processing, "validation (--validate)": val_log.processing}
    share = f"{FIT_FRACTION:.0%}"
    return {
        f"fit (--log, the first {share} in time)": fit_log.processing,
        "validation (--log, the rest)": val_log.processing,
    }


def _write(args, out: Path, model, ident, logs, validations) -> tuple[list[Path], str]:
    """The report's files, then identified.urdf: ``(written, why the URDF is not)``."""
    validation, nominal, least_squares = validations
    from armdyn.identification.export import write_urdf
    from armdyn.identification.report import write_report

    page = write_report(
        ident,
        out,
        validation=validation,
        nominal_validation=nominal,
        urdf=args.urdf,
        logs=_log_notes(args, *logs),
        ls_validation=least_squares,
    )
    names = ["torques.png", "parameters.csv", "base_parameters.csv"]
    written = [page, *(out / n for n in names if (out / n).exists())]
    urdf_out = out / "identified.urdf"
    try:
        write_urdf(args.urdf, model, ident.pi, path=urdf_out)
    except _core.ModelError as exc:  # the unconstrained estimate: a negative mass, friction...
        if ident.physical:
            raise
        return written, str(exc)
    return [urdf_out, *written], ""


def _summary(echo, ident, validations, statuses, fit_log, val_log, args) -> None:
    import pandas as pd

    validation, nominal, least_squares = validations
    how = (
        "--validate log" if args.validate is not None else f"last {1 - FIT_FRACTION:.0%} of the log"
    )
    echo(
        f"identified {len(ident.base.names)} base parameters from {len(fit_log.t)} samples "
        f"({ident.method}, {'physically consistent' if ident.physical else 'unconstrained'}); "
        f"validated on {len(val_log.t)} samples ({how})"
    )
    table = pd.DataFrame(
        {
            "verdict": statuses,
            "rmse": validation.rmse,
            "rel_rmse": validation.rel_rmse,
            **({"ls_rmse": least_squares.rmse} if least_squares is not None else {}),
            "nominal_rmse": nominal.rmse,
            "nominal_rel_rmse": nominal.rel_rmse,
        },
        index=pd.Index(validation.joint_names, name="joint"),
    )
    with pd.option_context("display.max_columns", None, "display.width", 200):
        echo(table.to_string(float_format=lambda v: f"{v:.4g}"))


def main(args) -> int:
    """``run(args)``'s exit code; bad input one line on stderr, exit code 2."""
    import pandas as pd

    try:
        return run(args)
    except (
        _core.ModelError,
        _core.UrdfError,
        _core.SolverError,
        OSError,
        pd.errors.ParserError,
        pd.errors.EmptyDataError,
        UnicodeDecodeError,
    ) as exc:
        print(f"armdyn identify: {exc}", file=sys.stderr)
        return 2
