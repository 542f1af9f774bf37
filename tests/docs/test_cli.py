"""The command line's small things: `armdyn --version` prints the package's version (the one
pyproject.toml declares), and the times `armdyn reproduce --help` states are the README's
measured ones."""

import re
import subprocess
import sys
from pathlib import Path

import armdyn as ad
import pytest
from armdyn.__main__ import main

ROOT = Path(__file__).resolve().parents[2]


def _pyproject_version() -> str:
    text = (ROOT / "pyproject.toml").read_text()
    return re.search(r'^version = "([^"]+)"', text, re.M).group(1)


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out == f"armdyn {_pyproject_version()}\n"
    assert ad.__version__ == _pyproject_version()


def test_version_from_the_entry_point():
    out = subprocess.run(
        [sys.executable, "-m", "armdyn", "--version"], capture_output=True, text=True, check=True
    )
    assert out.stdout == f"armdyn {ad.__version__}\n"


def test_help_times_are_the_readme_measurements(capsys):
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    readme = " ".join((ROOT / "README.md").read_text().split())
    times = re.findall(r"\d+ min \d+ s|\d+(?:\.\d+)? s\b", help_text)
    assert len(times) >= 2, help_text
    for t in times:
        assert t in readme, t
