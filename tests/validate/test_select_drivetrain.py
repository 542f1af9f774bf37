"""armdyn.select_drivetrain: the coupled selection equals an independent exhaustive search of
every combination of every joint's parts (the actuators' masses carried on models built here
with ModelBuilder, the checks evaluated candidate by candidate in a plain loop with the parts'
functions), infeasible cases explained, hostile inputs refused, the UR5 with 3 kg chosen from
the example catalog."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn.sizing import checks as checks_module
from armdyn.sizing.checks import CHECKS

# ---------------------------------------------------------------------------------------------
# the arm: a planar 3-link arm (x-z plane, joints about y) built with ModelBuilder; an actuator
# mass is a body welded at its joint's point on the parent link (what the selection places
# with model.with_payload)

LINKS = (("upper", 3.0, 0.5), ("fore", 2.0, 0.4), ("hand", 1.0, 0.2))  # name, mass, length
JOINTS = ("shoulder", "elbow", "wrist")


def planar_arm(payloads=()):
    """The arm with point masses ``[(body, mass, com in the body frame from its centre)]``."""
    b = ad.ModelBuilder(gravity=(0, 0, -9.81))
    x, centres, parent = 0.0, {}, "ground"
    for (name, mass, length), joint in zip(LINKS, JOINTS, strict=True):
        centres[name] = np.array([x + length / 2, 0.0, 0.0])
        inertia = mass * length**2 / 12
        b.add_body(name, mass, [1e-4, inertia, inertia], position=tuple(centres[name]))
        b.add_revolute(joint, parent, name, point=(x, 0, 0), axis=(0, 1, 0))
        x, parent = x + length, name
    for k, (body, mass, com) in enumerate(payloads):
        p = tuple(centres[body] + np.asarray(com, float))
        b.add_body(f"payload{k}", float(mass), [0.0, 0.0, 0.0], position=p)
        b.add_fixed(f"weld{k}", body, f"payload{k}", point=p)
    return b.finalize()


def motion(model, n=121):
    """A rest-to-rest move of every joint (quintic), sampled: (t, q, qd, qdd)."""
    t = np.linspace(0.0, 1.0, n)
    q0, q1 = np.array([-0.3, 0.4, -0.2]), np.array([0.6, -0.5, 0.5])
    cols = [ad.profiles.quintic(a, b, 0.0, 1.0).eval(t) for a, b in zip(q0, q1, strict=True)]
    q, qd, qdd = (np.stack([c[i] for c in cols], axis=1) for i in range(3))
    return t, q, qd, qdd


# ---------------------------------------------------------------------------------------------
# the parts' functions the exhaustive search calls candidate by candidate

_MODULES = (
    "armdyn.sizing.cycle",
    "armdyn.sizing.motor",
    "armdyn.sizing.gearbox",
    "armdyn.sizing.drive",
)


@pytest.fixture
def parts():
    """The modules of issue 33's parts 4 and 5 (duty cycle, motor side, gearbox, drive)."""
    import importlib

    return {name: importlib.import_module(name) for name in _MODULES}


# ---------------------------------------------------------------------------------------------
# the catalog (SI), written here

MOTORS = pd.DataFrame(
    {
        "torque_constant": [0.05, 0.08, 0.12, 0.2],
        "resistance": [1.2, 0.8, 0.5, 0.3],
        "rotor_inertia": [2e-6, 5e-6, 1.2e-5, 3e-5],
        "mass": [0.31, 0.52, 0.83, 1.37],
        "continuous_torque": [0.08, 0.16, 0.28, 0.62],
        "peak_torque": [0.25, 0.5, 0.9, 1.9],
        "max_speed": [900.0, 700.0, 600.0, 450.0],
        "cost": [100.0, 160.0, 230.0, 390.0],
    },
    index=pd.Index(["M1", "M2", "M3", "M4"], name="name"),
)
GEARBOXES = pd.DataFrame(
    {
        "ratio": [50.0, 100.0, 160.0],
        "efficiency": [0.8, 0.75, 0.7],
        "input_inertia": [1e-6, 2e-6, 3e-6],
        "mass": [0.41, 0.67, 1.12],
        "rated_torque": [12.0, 25.0, 50.0],
        "repeated_peak_torque": [30.0, 60.0, 120.0],
        "max_input_speed": [800.0, 700.0, 600.0],
        "cost": [300.0, 420.0, 610.0],
    },
    index=pd.Index(["G50", "G100", "G160"], name="name"),
)
DRIVES = pd.DataFrame(
    {
        "peak_current": [6.0, 15.0],
        "continuous_current": [2.0, 5.0],
        "bus_voltage": [48.0, 48.0],
        "cost": [80.0, 150.0],
    },
    index=pd.Index(["D6", "D15"], name="name"),
)


@dataclass
class _Catalog:
    motors: pd.DataFrame
    gearboxes: pd.DataFrame
    drives: pd.DataFrame | None = None


def catalog(drives=False, motors=MOTORS, gearboxes=GEARBOXES):
    """The test's catalog: an armdyn Catalog (checked by the catalog's rules)."""
    return ad.Catalog(motors.copy(), gearboxes.copy(), DRIVES.copy() if drives else None)


def raw_catalog(drives=False, motors=MOTORS, gearboxes=GEARBOXES):
    """The same tables unchecked (what a hand-made catalog object may hold)."""
    return _Catalog(motors.copy(), gearboxes.copy(), DRIVES.copy() if drives else None)


# ---------------------------------------------------------------------------------------------
# the independent exhaustive search


def _margins_of(out: dict) -> dict:
    found = {}
    for check in CHECKS:
        if check.margin_column in out:
            found[check.name] = float(np.asarray(out[check.margin_column]).reshape(-1)[0])
        elif check.name in out and check.name != check.value:
            found[check.name] = float(np.asarray(out[check.name]).reshape(-1)[0])
    return found


def _one(table: pd.DataFrame, name: str) -> dict:
    """One part's numeric columns as (1,) arrays."""
    row = table.loc[name]
    return {c: np.array([float(row[c])]) for c in table.columns if table[c].dtype.kind in "fiu"}


def candidate_margins(fns, load, motor, gearbox, drive, cat, options) -> dict:
    """Every check's margin of one candidate, calling the parts' functions for it alone."""
    m, g = _one(cat.motors, motor), _one(cat.gearboxes, gearbox)
    rotor = m["rotor_inertia"] + g["input_inertia"]
    gm = fns["armdyn.sizing.gearbox"]
    dm = fns["armdyn.sizing.drive"]
    mv = fns["armdyn.sizing.motor"].motor_cycle_values(
        load, g["ratio"], g["efficiency"], rotor, m, options
    )
    brake = m.get("brake_torque", np.array([np.nan]))
    stop = np.fmax(m["peak_torque"], brake)
    outs = [
        mv,
        gm.gearbox_cycle_values(load, g["ratio"], g, options),
        gm.bearing_cycle_values(load, g, options),
        gm.emergency_stop_values(load, g["ratio"], g["efficiency"], rotor, stop, g, options),
        dm.brake_values(load, g["ratio"], brake, options),
    ]
    if drive is not None:
        outs.append(dm.drive_values(mv, _one(cat.drives, drive)))
    found = {}
    for out in outs:
        found.update(_margins_of(out))
    return found


def _cycle_on(fns, payloads, run):
    model = planar_arm(payloads)
    return fns["armdyn.sizing.cycle"].duty_cycle(model, ad.trajectory_run(model, *run))


def _objective_of(cat, objective, part):
    motor, gearbox, drive = part
    column = "mass" if objective == "mass" else "cost"
    value = float(cat.motors.loc[motor, column] + cat.gearboxes.loc[gearbox, column])
    if objective == "cost" and drive is not None:
        value += float(cat.drives.loc[drive, "cost"])
    return value


def exhaustive(fns, run, joints, cat, options, objective="mass", mounts=None):
    """Every combination of every joint's (motor, gearbox[, drive]), in increasing total
    objective, each checked on the model carrying that combination's actuator masses (built
    here with ModelBuilder) until the first that passes every check of every joint: every
    lighter (cheaper) combination was checked and failed. ``(total, combination, margins per
    joint)``, None when no combination is feasible."""
    drives = [None] if cat.drives is None or len(cat.drives) == 0 else list(cat.drives.index)
    per_joint = list(itertools.product(cat.motors.index, cat.gearboxes.index, drives))
    places = {
        "shoulder": None,
        "elbow": ("upper", (0.25, 0.0, 0.0)),
        "wrist": ("fore", (0.2, 0, 0)),
    }
    places.update(mounts or {})
    combos = sorted(
        itertools.product(per_joint, repeat=len(joints)),
        key=lambda combo: sum(_objective_of(cat, objective, part) for part in combo),
    )
    cycles = {}
    for combo in combos:
        masses = [
            float(cat.motors.loc[mo, "mass"] + cat.gearboxes.loc[ge, "mass"]) for mo, ge, _ in combo
        ]
        payloads = tuple(
            (places[j][0], m, places[j][1])
            for j, m in zip(joints, masses, strict=True)
            if places[j] is not None
        )
        if payloads not in cycles:
            cycles[payloads] = _cycle_on(fns, payloads, run)
        margins = {}
        for j, (mo, ge, dr) in zip(joints, combo, strict=True):
            load = cycles[payloads].joint_load(j)
            margins[j] = candidate_margins(fns, load, mo, ge, dr, cat, options)
            if not all(np.isnan(v) or v >= 1.0 for v in margins[j].values()):
                break
        else:
            return sum(_objective_of(cat, objective, part) for part in combo), combo, margins
    return None


@pytest.fixture
def run():
    return motion(planar_arm())


def _options():
    from armdyn.sizing.options import SizingOptions

    return SizingOptions()


def _chosen(sel, joints):
    return tuple(
        (sel.table.loc[j, "motor"], sel.table.loc[j, "gearbox"], sel.table.loc[j, "drive"])
        for j in joints
    )


def _assert_margins(sel, ref_margins, joints):
    for j in joints:
        for name, value in ref_margins[j].items():
            got = sel.table.loc[j, checks_module.CHECKS_BY_NAME[name].margin_column]
            np.testing.assert_allclose(got, value, rtol=1e-12, err_msg=f"{j} {name}")


def test_equals_exhaustive_search_mass(parts, run):
    model = planar_arm()
    cat = catalog(gearboxes=GEARBOXES.iloc[:2])
    sel = ad.select_drivetrain(model, ad.trajectory_run(model, *run), cat, drives=False)
    total, combo, ref_margins = exhaustive(parts, run, JOINTS, cat, _options())
    assert _chosen(sel, JOINTS) == combo
    np.testing.assert_allclose(sel.table["mass"].sum(), total, rtol=1e-12)
    _assert_margins(sel, ref_margins, JOINTS)
    assert sel.converged and sel.ok and sel.passes == 2
    # the case needs the coupling: without the carried masses the choice would differ
    free = ad.select_drivetrain(
        model,
        ad.trajectory_run(model, *run),
        cat,
        drives=False,
        mounts={"elbow": None, "wrist": None},
    )
    assert _chosen(free, JOINTS) != combo
    assert list(sel.table.index) == list(JOINTS)
    assert sel.table["ok"].all() and len(sel.infeasible) == 0


def test_the_coupling_changes_the_shoulder(parts, run):
    """Without the carried masses (every mount None) the shoulder would take a lighter motor
    that the elbow's and wrist's actuators overload: the coupled search must not."""
    model = planar_arm()
    # a ladder of motors 20 % apart in torque: the carried masses raise the shoulder's torques
    # by more than that, so its lightest feasible motor must change
    c = 0.05 * 1.2 ** np.arange(16)
    ladder = pd.DataFrame(
        {
            "torque_constant": 0.05 + 0.2 * c,
            "resistance": 0.3 / c**0.5,
            "rotor_inertia": 2e-5 * c,
            "mass": 0.2 + 2.0 * c,
            "continuous_torque": c,
            "peak_torque": 3.0 * c,
            "max_speed": np.full(len(c), 900.0),
        },
        index=pd.Index([f"L{i:02d}" for i in range(len(c))], name="name"),
    )
    cat = catalog(motors=ladder, gearboxes=GEARBOXES.iloc[1:])
    traj = ad.trajectory_run(model, *run)
    free = ad.select_drivetrain(
        model, traj, cat, drives=False, mounts={"elbow": None, "wrist": None}
    )
    coupled = ad.select_drivetrain(model, traj, cat, drives=False)
    assert free.passes == 2 and coupled.passes == 2
    assert coupled.table.loc["shoulder", "mass"] > free.table.loc["shoulder", "mass"]
    # the free choice fails on the loaded arm: its margin there (from the candidates of the
    # coupled run) is below 1
    cand = coupled.candidates("shoulder")
    fm, fg = free.table.loc["shoulder", ["motor", "gearbox"]]
    row = cand[(cand["motor"] == fm) & (cand["gearbox"] == fg)].iloc[0]
    assert not row["ok"] and row["margin"] < 1.0
    # the wrist carries no actuator beyond it: the same values; the elbow carries the wrist's
    cols = ["motor", "gearbox", "margin", "motor_rms_torque"]
    assert free.table.loc["wrist", cols].tolist() == coupled.table.loc["wrist", cols].tolist()
    assert (
        coupled.table.loc["elbow", "motor_rms_torque"] > free.table.loc["elbow", "motor_rms_torque"]
    )


def test_equals_exhaustive_search_cost_with_drives(parts, run):
    model = planar_arm()
    cat = catalog(drives=True, gearboxes=GEARBOXES.iloc[:2])
    joints = ["shoulder", "elbow"]
    sel = ad.select_drivetrain(
        model, ad.trajectory_run(model, *run), cat, objective="cost", joints=joints
    )
    total, combo, ref_margins = exhaustive(parts, run, joints, cat, _options(), "cost")
    assert _chosen(sel, joints) == combo
    np.testing.assert_allclose(sel.table["cost"].sum(), total, rtol=1e-12)
    _assert_margins(sel, ref_margins, joints)
    assert sel.bus is not None
    free = ad.select_drivetrain(
        model,
        ad.trajectory_run(model, *run),
        cat,
        objective="cost",
        joints=joints,
        mounts={"elbow": None},
    )
    assert _chosen(free, joints) != combo  # the carried elbow actuator changes the choice


def _select(run, cat, **kw):
    model = planar_arm()
    return ad.select_drivetrain(model, ad.trajectory_run(model, *run), cat, **kw)


def test_margin_and_bus_power_objectives_rank_by_their_value(parts, run):
    cat = catalog()
    by_margin = _select(run, cat, drives=False, objective="margin")
    by_power = _select(run, cat, drives=False, objective="bus_power")
    for sel, column, best in ((by_margin, "margin", np.max), (by_power, "objective", np.min)):
        for joint in JOINTS:
            cand = sel.candidates(joint)
            feasible = cand[cand["ok"]]
            assert cand.iloc[0]["motor"] == sel.table.loc[joint, "motor"]
            assert cand.iloc[0]["gearbox"] == sel.table.loc[joint, "gearbox"]
            assert feasible.iloc[0][column] == best(feasible[column])
            # feasible first, then the infeasible ones closest first
            assert list(cand["ok"]) == sorted(cand["ok"], reverse=True)
            rest = cand[~cand["ok"]]["margin"].to_numpy()
            assert np.all(np.diff(rest) <= 0)
    np.testing.assert_array_equal(
        by_power.candidates("wrist")["objective"],
        by_power.candidates("wrist")["peak_electrical_power"],
    )


def test_candidates_are_every_combination_ranked(parts, run):
    cat = catalog(drives=True)
    sel = _select(run, cat, objective="cost")
    cand = sel.candidates("elbow")
    assert len(cand) == len(MOTORS) * len(GEARBOXES) * len(DRIVES)
    assert len(set(zip(cand["motor"], cand["gearbox"], cand["drive"], strict=True))) == len(cand)
    feasible = cand[cand["ok"]]
    assert np.all(np.diff(feasible["cost"].to_numpy()) >= 0)
    expected = (
        MOTORS.loc[cand["motor"], "cost"].to_numpy()
        + GEARBOXES.loc[cand["gearbox"], "cost"].to_numpy()
        + DRIVES.loc[cand["drive"], "cost"].to_numpy()
    )
    np.testing.assert_array_equal(cand["cost"].to_numpy(), expected)
    assert len(sel.candidates("elbow", n=3)) == 3
    assert sel.table.loc["elbow", "candidates"] == len(cand)
    assert sel.table.loc["elbow", "feasible"] == int(cand["ok"].sum())


def test_no_feasible_candidate_names_the_check_and_best_margin(parts, run):
    weak = MOTORS.copy()
    weak["continuous_torque"] = weak["continuous_torque"] * 0.2
    cat = catalog(motors=weak)
    sel = _select(run, cat, drives=False)
    assert not sel.ok
    failing = sel.table.index[~sel.table["ok"]].tolist()
    assert "shoulder" in failing
    why = sel.infeasible[sel.infeasible["joint"] == "shoulder"]
    assert "continuous_torque" in why["check"].tolist()
    row = why[why["check"] == "continuous_torque"].iloc[0]
    # the best margin any candidate reaches on it, and by which one: a plain loop over the
    # candidates on the model the table is of
    cand = sel.candidates("shoulder")
    k = int(np.argmax(cand["continuous_torque_margin"].to_numpy()))
    assert row["best_margin"] == cand["continuous_torque_margin"].iloc[k] < 1.0
    assert (row["motor"], row["gearbox"]) == (cand["motor"].iloc[k], cand["gearbox"].iloc[k])
    assert row["part"] == "motor"
    # the table shows the closest candidate
    assert sel.table.loc["shoulder", "margin"] == cand["margin"].max()
    assert "no candidate passes continuous_torque" in sel.explain()


def test_checks_in_conflict_are_explained(parts, run):
    """One motor and two gearboxes: the small ratio overloads the motor, the large one exceeds
    the gearbox's input speed; each check is passed by some candidate, none passes both."""
    motors = MOTORS.loc[["M2"]].copy()
    gearboxes = GEARBOXES.loc[["G50", "G160"]].copy()
    gearboxes["max_input_speed"] = [800.0, 100.0]
    sel = _select(run, catalog(motors=motors, gearboxes=gearboxes), drives=False, joints=["elbow"])
    assert not sel.table.loc["elbow", "ok"]
    why = sel.infeasible
    assert len(why) >= 1
    assert why["reason"].str.contains("none passes all").all()
    cand = sel.candidates("elbow")
    assert (why["motor"].iloc[0], why["gearbox"].iloc[0]) == (
        cand["motor"].iloc[0],
        cand["gearbox"].iloc[0],
    )


def test_not_converged_is_flagged(parts, run):
    with pytest.warns(UserWarning, match="not converged"):
        sel = _select(run, catalog(), drives=False, max_passes=1)
    assert sel.passes == 1 and not sel.converged and not sel.ok


def test_mount_on_a_frame_and_the_model_carries_the_actuators(parts, run):
    """mounts places the mass where told; the result's model carries every chosen actuator:
    the shoulder's static torque there equals the arm's plus the carried masses' m g x."""
    sel = _select(run, catalog(), drives=False, mounts={"wrist": ("upper", (0.25, 0.0, 0.0))})
    masses = sel.table["mass"]
    ref = planar_arm(
        [("upper", masses["elbow"], (0.25, 0, 0)), ("upper", masses["wrist"], (0.25, 0, 0))]
    )
    q = np.zeros(3)
    tau = ad.inverse_dynamics(sel.model, q, q, q)
    np.testing.assert_allclose(tau, ad.inverse_dynamics(ref, q, q, q), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"objective": "weight"}, "objective must be one of"),
        ({"joints": ["knee"]}, "'knee' is not a revolute or prismatic joint"),
        ({"joints": []}, "joints is empty"),
        ({"joints": 5}, "joints must be a list of joint names"),
        ({"objective": None}, "objective must be one of"),
        ({"joints": ["elbow", "elbow"]}, "listed twice"),
        ({"mounts": {"knee": "upper"}}, "'knee' is not a selected joint"),
        ({"mounts": {"elbow": "nowhere"}}, "'nowhere' is not a body or frame"),
        ({"mounts": {"elbow": ("upper", (0, 0))}}, "com must be 3 numbers"),
        ({"mounts": {"elbow": ("upper", (0, 0, np.nan))}}, "is not finite"),
        ({"mounts": ["elbow"]}, "mounts must be a dict"),
        ({"max_passes": 0}, "max_passes"),
        ({"max_passes": True}, "max_passes"),
        ({"drives": "yes"}, "drives must be True or False"),
        ({"drives": True}, "drives=True but the catalog has no drives"),
        ({"objective": "cost", "motors": MOTORS.drop(columns="cost")}, "no 'cost' column"),
        ({"motors": MOTORS.iloc[:0]}, "the catalog has no motors"),
        ({"gearboxes": GEARBOXES.iloc[:0]}, "the catalog has no gearboxes"),
        ({"motors": MOTORS.assign(mass=[0.3, np.nan, 0.8, 1.3])}, "motor 'M2' has mass = nan"),
        ({"gearboxes": GEARBOXES.assign(ratio=[50.0, 0.0, 160.0])}, "'G100' has ratio = 0.0"),
        ({"gearboxes": GEARBOXES.drop(columns="input_inertia")}, "no 'input_inertia'"),
        ({"required_lif": 1.0}, "unknown option"),
        (
            {"motors": pd.concat([MOTORS] * 200), "gearboxes": pd.concat([GEARBOXES] * 100)},
            "800 motors x 300 gearboxes = 240000 candidates per joint, more than",
        ),
    ],
)
def test_hostile_inputs(parts, run, kwargs, match):
    kwargs = dict(kwargs)
    cat = raw_catalog(
        motors=kwargs.pop("motors", MOTORS), gearboxes=kwargs.pop("gearboxes", GEARBOXES)
    )
    kwargs.setdefault("drives", False)
    with pytest.raises(ad.ModelError, match=match):
        _select(run, cat, **kwargs)


def test_hostile_model_catalog_and_candidates(parts, run):
    model = planar_arm()
    traj = ad.trajectory_run(model, *run)
    with pytest.raises(ad.ModelError, match=r"model must be an armdyn\.Model"):
        ad.select_drivetrain("arm.urdf", traj, catalog(), drives=False)
    with pytest.raises(ad.ModelError, match=r"catalog\.motors must be a pandas DataFrame"):
        ad.select_drivetrain(model, traj, _Catalog([1, 2], GEARBOXES), drives=False)
    with pytest.raises(ad.ModelError, match="the catalog has no motors"):
        ad.select_drivetrain(model, traj, object(), drives=False)
    with pytest.raises(ad.ModelError, match="motion must be a TrajectoryRun"):
        ad.select_drivetrain(model, None, catalog(), drives=False)
    held = planar_arm([("hand", 1.0, (0.1, 0.0, 0.0))])  # a fixed joint 'weld0'
    with pytest.raises(ad.ModelError, match="'weld0' is not a revolute or prismatic joint"):
        ad.select_drivetrain(
            held, ad.trajectory_run(held, *run), catalog(), drives=False, joints=["weld0"]
        )
    with pytest.raises(ad.ModelError, match="drives=True but the catalog has no drives"):
        ad.select_drivetrain(model, traj, catalog())  # a Catalog without drives.csv
    sel = ad.select_drivetrain(model, traj, catalog(), drives=False, joints=["wrist"])
    with pytest.raises(ad.ModelError, match="'elbow' was not selected"):
        sel.candidates("elbow")
    with pytest.raises(ad.ModelError, match="n must be"):
        sel.candidates("wrist", n=0)
    assert list(sel.table.index) == ["wrist"]


def test_an_actuator_on_its_own_link_takes_passes_and_equals_the_exhaustive_search(parts, run):
    """The wrist's actuator mounted at the hand's tip (on the link it drives) loads its own
    joint: the choice must hold with its own mass (a fixed point reached over passes)."""
    tip = {"wrist": ("hand", (0.1, 0.0, 0.0))}
    tiny = pd.DataFrame(
        {
            c: [v]
            for c, v in zip(MOTORS.columns, [0.03, 3.0, 1e-6, 0.2, 0.03, 0.1, 900, 60], strict=True)
        },
        index=pd.Index(["M0"], name="name"),
    )
    cat = catalog(motors=pd.concat([tiny, MOTORS]), gearboxes=GEARBOXES.iloc[:2])
    joints = ["elbow", "wrist"]
    sel = _select(run, cat, drives=False, mounts=tip, joints=joints)
    _, combo, ref_margins = exhaustive(parts, run, joints, cat, _options(), mounts=tip)
    assert _chosen(sel, joints) == combo
    _assert_margins(sel, ref_margins, joints)
    assert sel.converged and sel.passes >= 2
    # the wrist's first-pass choice (without its own mass) differs from the final one
    assert sel.history[0]["wrist"] != sel.history[-1]["wrist"]


def test_chunks_give_the_same_screening(parts, run, monkeypatch):
    from armdyn.sizing import drivetrain

    cat = catalog(drives=True)
    whole = _select(run, cat, objective="cost")
    monkeypatch.setattr(drivetrain, "CHUNK_ELEMENTS", 3 * len(run[0]))  # 3 pairs per chunk
    chunked = _select(run, cat, objective="cost")
    for joint in JOINTS:
        pd.testing.assert_frame_equal(whole.candidates(joint), chunked.candidates(joint))


def _ur5_pick_and_place():
    """The UR5 with a 3 kg payload 5 cm beyond its tool flange, moving every joint from a pick
    pose to a place pose (quintic, 1.5 s), holding there 0.5 s, repeated forever."""
    from benchmarks import common

    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    arm = ad.load_urdf(str(path))
    model = arm.with_payload("tool0", 3.0, com=(0.0, 0.0, 0.05))
    t = np.linspace(0.0, 1.5, 151)
    pick = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    place = np.array([1.4, -1.6, 1.2, -1.2, -0.9, 0.8])
    cols = [ad.profiles.quintic(a, b, 0.0, 1.5).eval(t) for a, b in zip(pick, place, strict=True)]
    q, qd, qdd = (np.stack([c[i] for c in cols], axis=1) for i in range(3))
    return model, ad.duty_cycle(model, ad.trajectory_run(model, t, q, qd, qdd), dwell=0.5)


def test_ur5_pick_and_place_from_the_example_catalog():
    model, cycle = _ur5_pick_and_place()
    catalog = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG)
    sel = ad.select_drivetrain(model, cycle, catalog)
    assert sel.converged and sel.passes >= 2
    assert sel.ok, sel.explain()
    assert list(sel.table.index) == list(model.dof_names)
    # a non-trivial choice: every joint has candidates that fail
    assert (sel.table["feasible"] < sel.table["candidates"]).all()
    # the model carries every actuator but the base joint's (its housing sits on the ground)
    carried = sel.table["mass"].drop(model.dof_names[0]).sum()
    np.testing.assert_allclose(np.sum(sel.model.masses), np.sum(model.masses) + carried, rtol=1e-12)
    # each housing at its joint's point on the parent link: the same dynamics as part 2's
    # joint mount (with_payload at a joint name)
    housings = [
        {"at": j, "mass": float(sel.table.loc[j, "mass"]), "name": f"h{k}"}
        for k, j in enumerate(model.dof_names[1:])
    ]
    ref = model.with_payloads(housings)
    rng = np.random.default_rng(3)
    x, xd, xdd = rng.uniform(-1.0, 1.0, (3, 6))
    np.testing.assert_allclose(
        ad.inverse_dynamics(sel.model, x, xd, xdd),
        ad.inverse_dynamics(ref, x, xd, xdd),
        rtol=1e-12,
        atol=1e-12,
    )
    # a fixed point: selecting again on the model that already carries the chosen actuators,
    # carrying nothing more, gives the same choice and the same margins
    again = ad.select_drivetrain(
        sel.model, cycle, catalog, mounts={j: None for j in model.dof_names}
    )
    cols = ["motor", "gearbox", "drive", "ok", "binding_check"]
    pd.testing.assert_frame_equal(again.table[cols], sel.table[cols])
    np.testing.assert_allclose(again.table["margin"], sel.table["margin"], rtol=1e-12)
    assert again.passes == 2


def test_a_thermal_runaway_fails_its_checks(parts, run):
    """A motor whose copper loss outruns its cooling (R(T) i² R_th grows without bound) has an
    infinite winding temperature and terminal voltage: it fails the winding and drive voltage
    checks and the selection goes on."""
    hot = (
        MOTORS.loc[["M2"]]
        .rename(index={"M2": "HOT"})
        .assign(
            thermal_resistance_winding=400.0,
            thermal_resistance_housing=400.0,
            thermal_time_constant_winding=5.0,
            thermal_time_constant_housing=50.0,
            max_winding_temperature=155.0,
        )
    )
    sel = _select(run, catalog(drives=True, motors=pd.concat([MOTORS, hot])), joints=["elbow"])
    cand = sel.candidates("elbow")
    hot_rows = cand[cand["motor"] == "HOT"]
    assert not hot_rows["ok"].any()
    if "winding_temperature_peak" in cand:  # the real motor side (part 4)
        runaway = hot_rows[np.isinf(hot_rows["winding_temperature_peak"])]
        assert len(runaway) > 0
        assert (runaway["winding_temperature_margin"] == 0.0).all()
        # the voltage R(T) i + k_t w with R at an infinite temperature
        assert np.isinf(runaway["peak_terminal_voltage"]).all()
        if "drive_voltage_margin" in cand:  # the real drive checks (part 5)
            assert (runaway["drive_voltage_margin"] == 0.0).all()
    assert sel.table.loc["elbow", "motor"] != "HOT"


def test_a_joint_whose_load_did_not_change_is_not_screened_again(parts, run, monkeypatch):
    """On a serial arm with the default mounts a joint's load depends on the actuators beyond
    it only: the second pass finds every load as it was and screens nothing again."""
    from armdyn.sizing import select as select_module

    screened = []
    evaluate = select_module.evaluate_joint

    def counted(joint, *args, **kwargs):
        screened.append(joint)
        return evaluate(joint, *args, **kwargs)

    monkeypatch.setattr(select_module, "evaluate_joint", counted)
    sel = _select(run, catalog(), drives=False)
    assert sel.passes == 2
    assert screened == ["wrist", "elbow", "shoulder"]  # distal to proximal, once each
