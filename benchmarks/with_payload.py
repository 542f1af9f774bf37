"""The cost of Model.with_payload / with_payloads (issue 33: the drivetrain selection places up
to six actuator housings on the arm per pass), on the UR5 with and without actuators.

    python -m benchmarks.with_payload

Median CPU time per call (common.cpu_time, 30 warm calls) of: finalize() of the URDF's builder
(the floor: a payload refinalizes the model), one with_payload, six payloads in turn, and six at
once (with_payloads); the last column divides by the finalize time.
"""

from __future__ import annotations

import armdyn as ad

from benchmarks import common

GEARS = [(100.0, 6e-5), (100.0, 6e-5), (80.0, 4e-5), (50.0, 1.5e-5), (50.0, 1.5e-5), (50.0, 1.5e-5)]


def _row(label, fn, floor):
    seconds, _runs, _ = common.cpu_time(fn, 30)
    ratio = "" if floor is None else f"{seconds / floor:8.2f}"
    print(f"  {label:<34s} {1e3 * seconds:8.3f} ms {ratio}")
    return seconds


def main() -> None:
    path = common.robot_urdf("ur5")
    if path is None:
        raise SystemExit("example-robot-data is not installed (pip install '.[test]')")
    for geared in (False, True):
        builder = ad.urdf_builder(str(path))
        if geared:
            for joint, (ratio, inertia) in zip(builder.finalize().coord_names, GEARS, strict=True):
                builder.add_actuator(joint, ratio, inertia)
        model = builder.finalize()
        housings = [
            {"at": body, "mass": 1.0, "com": (0.0, 0.0, 0.05), "name": f"housing_{k}"}
            for k, body in enumerate(model.body_names[:6])
        ]

        def in_turn(model=model, housings=housings):
            m = model
            for h in housings:
                m = m.with_payload(**h)
            return m

        print(
            f"UR5{' with 6 actuators' if geared else ''} ({model.nb} bodies): CPU time, / finalize"
        )
        floor = _row("finalize() of the builder", builder.finalize, None)
        _row("with_payload (1 payload)", lambda m=model: m.with_payload("tool0", 3.0), floor)
        _row("6 x with_payload in turn", in_turn, floor)
        _row("with_payloads (6 at once)", lambda m=model, h=housings: m.with_payloads(h), floor)


if __name__ == "__main__":
    main()
