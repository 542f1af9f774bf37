"""The committed stubs of armdyn._core (python/armdyn/_core/*.pyi) are what pybind11-stubgen
makes of the built module: regenerated into a temporary directory and compared. When this fails,
run ``python tools/gen_stubs.py`` (with the new module built and importable) and commit."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import armdyn
import pytest

pytest.importorskip("pybind11_stubgen")

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
from tools import gen_stubs  # noqa: E402


@pytest.fixture(scope="module")
def generated(tmp_path_factory) -> dict[str, str]:
    out = tmp_path_factory.mktemp("stubs")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(Path(armdyn.__file__).resolve().parents[1]), env.get("PYTHONPATH", "")]
    )
    p = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "gen_stubs.py"), "--out", str(out)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert p.returncode == 0, p.stdout + p.stderr
    return {f.name: f.read_text() for f in sorted((out / "armdyn" / "_core").glob("*.pyi"))}


def test_committed_stubs_are_up_to_date(generated):
    assert set(generated) == {"__init__.pyi", "profiles.pyi"}
    d = gen_stubs.diff(generated)
    assert not d, (
        f"python/armdyn/_core/*.pyi are out of date; regenerate with `{gen_stubs.COMMAND}`:\n{d}"
    )


def test_the_check_sees_a_change(generated, tmp_path):
    # the comparison is not vacuous: an edited signature shows up in the diff
    for name, text in generated.items():
        (tmp_path / name).write_text(text.replace("axis: numpy.typing.ArrayLike", "axis: str"))
    d = gen_stubs.diff(generated, old_dir=tmp_path)
    assert "-    def add_revolute(self, name: str, parent: str, child: str, point:" in d
    assert d.count("\n+    def add_") >= 1


def test_stubs_have_full_types(generated):
    stub = generated["__init__.pyi"]
    # inputs: ArrayLike, profiles and optionals; outputs: float64 arrays
    for line in (
        "def add_revolute(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike,"
        " axis: numpy.typing.ArrayLike) -> int:",
        "def frame_pose(model: Model, q: numpy.typing.ArrayLike, frame: str | int, data: Data |"
        " None = None) -> numpy.typing.NDArray[numpy.float64]:",
        "def add_joint_torque(self, joint: str, profile: Profile | float | collections.abc."
        "Callable[[float], tuple[float, float, float]], coord: typing.SupportsInt |"
        " typing.SupportsIndex = 0) -> None:",
    ):
        assert line in stub, line
    eval_line = "def eval(self, t: float | numpy.typing.ArrayLike) -> tuple[float, float, float] |"
    assert eval_line in stub
    # every public function and method is typed: no bare `object`/Any parameters left
    public = [
        ln
        for ln in stub.splitlines()
        if ln.lstrip().startswith("def ") and not ln.lstrip().startswith(("def _", "def __"))
    ]
    assert len(public) > 60
    untyped = [ln.strip() for ln in public if "typing.Any" in ln or ": object" in ln]
    assert not untyped, untyped
    # the docstrings travel with the stubs (editors show them)
    assert "Add a revolute (hinge) joint" in stub
