"""``mypy --strict`` on a user's script: armdyn is typed (py.typed, the stubs of armdyn._core,
the annotated facade), so a correct script passes with its results typed as float64 arrays,
and the usual mistakes are flagged."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import armdyn
import pytest

pytest.importorskip("mypy")

HERE = Path(__file__).resolve().parent
GOOD = HERE / "user_script.py"
BAD = HERE / "bad_script.py"
# NDArray[np.float64] as mypy reveals it (the shape parameter differs between numpy versions)
FLOAT_ARRAY = re.compile(r"numpy\.ndarray\[.*, numpy\.dtype\[numpy\.float64\]\]")


def _env() -> dict[str, str]:
    # the armdyn these tests import (a worktree's python/, or site-packages), as an installed
    # package: mypy reads it only through its py.typed marker and stubs
    env = dict(os.environ)
    package_root = str(Path(armdyn.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([package_root, env.get("PYTHONPATH", "")])
    return env


@pytest.fixture(scope="module")
def mypy_output() -> tuple[int, str]:
    # one mypy run for both scripts; a cache shared between test runs keeps it to seconds
    cache = Path(tempfile.gettempdir()) / "armdyn-mypy-cache"
    cmd = [
        sys.executable, "-m", "mypy", "--strict", "--no-error-summary", "--hide-error-context",
        "--cache-dir", str(cache), "--python-executable", sys.executable, str(GOOD), str(BAD),
    ]  # fmt: skip
    p = subprocess.run(cmd, capture_output=True, text=True, env=_env(), cwd=HERE, timeout=300)
    assert p.returncode in (0, 1), p.stdout + p.stderr
    return p.returncode, p.stdout


def _messages(output: str, path: Path, kind: str) -> dict[int, str]:
    out: dict[int, str] = {}
    for line in output.splitlines():
        m = re.match(rf"(.*?):(\d+): {kind}: (.*)", line)
        if m and Path(m.group(1)).name == path.name:
            out[int(m.group(2))] = out.get(int(m.group(2)), "") + m.group(3)
    return out


def test_user_script_passes_mypy_strict(mypy_output):
    _, output = mypy_output
    assert _messages(output, GOOD, "error") == {}, output
    revealed = _messages(output, GOOD, "note")
    assert revealed, output
    # result.q, result.joint_torques and forward_dynamics' qdd: float64 arrays; names: list[str]
    types = [
        re.sub(r'^Revealed type is "(.*)"$', r"\1", v).replace("builtins.", "")
        for _, v in sorted(revealed.items())
    ]
    assert len(types) == 4, types
    assert all(FLOAT_ARRAY.fullmatch(t) for t in types[:3]), types
    assert types[3] == "list[str]"


def test_mypy_flags_the_mistakes(mypy_output):
    code, output = mypy_output
    assert code == 1
    marked = {k + 1 for k, line in enumerate(BAD.read_text().splitlines()) if "  # error:" in line}
    flagged = _messages(output, BAD, "error")
    assert set(flagged) == marked, output
    assert 'variable has type "str"' in flagged[min(marked)]


def test_user_script_runs():
    p = subprocess.run(
        [sys.executable, str(GOOD)], capture_output=True, text=True, env=_env(), timeout=300
    )
    assert p.returncode == 0, p.stderr
    summary = eval(p.stdout.splitlines()[0], {})  # the printed dict of floats
    assert summary["t_end"] == pytest.approx(1.0)
    assert summary["energy_span"] > 0.0  # driven by the sine torque: energy changes
