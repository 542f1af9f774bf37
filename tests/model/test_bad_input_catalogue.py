"""Every entry of the bad-input catalogue raises its exception with a message naming the
culprit, and docs/bad_inputs.md is the catalogue's current rendering."""

import re
from pathlib import Path

import pytest
from bad_input_catalogue import CASES, render


def test_catalogue_has_at_least_40_cases():
    assert len(CASES) >= 40
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_input(case):
    _cid, _area, _what, fn, exc, pattern = case
    with pytest.raises(exc) as err:
        fn()
    assert re.search(pattern, str(err.value)), str(err.value)


def test_docs_table_is_current():
    """docs/bad_inputs.md lists every case with its exception (the message column is the
    rendering at the time it was generated; regenerate with the command in its header)."""
    doc = (Path(__file__).resolve().parents[2] / "docs" / "bad_inputs.md").read_text("utf-8")
    rows = [line for line in doc.splitlines() if line.startswith("| ") and "`" in line]
    assert len(rows) == len(CASES)
    for (cid, area, what, _fn, exc, _p), row in zip(CASES, rows, strict=True):
        assert row.startswith(f"| {cid} | {area} | {what} | `{exc.__name__}` | "), row
    assert render().count("\n") == doc.count("\n")
