"""docs/reference.md is what tools/gen_api.py generates from the code now: regenerated here and
compared, with the diff and the command to run when it is stale. The generator's signature
fallback for compiled functions (pybind11's docstring lines) is checked on its own."""

import difflib
import importlib.util
import inspect
import re
from pathlib import Path

import armdyn as ad

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "docs" / "reference.md"


def _generator():
    spec = importlib.util.spec_from_file_location("gen_api", ROOT / "tools" / "gen_api.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


GEN = _generator()


def test_reference_is_in_step_with_the_code():
    new = GEN.generate()
    old = REFERENCE.read_text("utf-8")
    if new != old:
        diff = "".join(
            list(
                difflib.unified_diff(
                    old.splitlines(True), new.splitlines(True), "docs/reference.md", "generated"
                )
            )[:150]
        )
        raise AssertionError(f"docs/reference.md is stale; run `{GEN.COMMAND}`\n{diff}")


def test_reference_lists_every_public_name():
    text = REFERENCE.read_text("utf-8")
    headings = set(re.findall(r"^#+ `([\w.]+)`$", text, re.M))
    for name in ad.__all__:
        assert f"armdyn.{name}" in headings, name
    for name in dir(ad.ModelBuilder):
        if not name.startswith("_"):
            assert f"armdyn.ModelBuilder.{name}" in headings, name
    for name in dir(ad.Model):
        if not name.startswith("_"):
            assert f"armdyn.Model.{name}" in headings, name
    for name in ("constant", "cubic", "quintic", "sine", "spline"):
        assert f"armdyn.profiles.{name}" in headings, name
    for name in ad.scenes.__all__:
        assert any(h.startswith("armdyn.scenes.") and h.endswith("." + name) for h in headings)
    assert "armdyn.validation.paper_model_3dof" in headings
    for name in ("five_dof.five_dof_arm", "five_dof.three_dof_arm", "geared_arm.geared_arm_6dof"):
        assert f"armdyn.papers.{name}" in headings, name
    # documented in its module's section; the guide's ad.sizing.make_motor is the same function
    assert "armdyn.sizing.what_if.make_motor" in headings
    assert ad.sizing.make_motor is ad.sizing.what_if.make_motor


def test_simulate_signature_is_complete():
    """The hand-written signature the issue found lacking dop853, coordinates, u0/v0: the
    generated one is inspect.signature's, so it names every parameter."""
    text = REFERENCE.read_text("utf-8")
    entry = text.split("### `armdyn.simulate`", 1)[1].split("\n### ", 1)[0]
    params = inspect.signature(ad.simulate).parameters
    assert {"coordinates", "u0", "v0", "integrator", "q0", "qd0"} <= set(params)
    for name in params:
        assert re.search(rf"[(,] ?{name}\b", entry), name
    assert "dop853" in entry  # from the docstring's list of integrators


def test_fallback_reads_pybind11_signature_lines():
    def f():
        pass

    f.__doc__ = (
        "f(*args, **kwargs)\nOverloaded function.\n\n"
        "1. f(self: armdyn._core.Model, x: int) -> int\n"
        "\nFirst form.\n\n2. f(self: armdyn._core.Model, x: str) -> str\n\nSecond form.\n"
    )
    sigs, rest = GEN._pybind_signatures("f", f.__doc__)
    assert [GEN._drop_self(s) for s in sigs] == ["f(x: int) -> int", "f(x: str) -> str"]
    assert rest.split() == ["First", "form.", "Second", "form."]
    sigs, rest = GEN._pybind_signatures("g", "g(a: float) -> None\n\nDoes g.")
    assert sigs == ["g(a: float) -> None"] and rest.strip() == "Does g."
    # a compiled function, whatever inspect.signature says of it, gets one signature line
    # naming its parameters, and the docstring without pybind11's signature line
    sigs, doc = GEN.signatures("armdyn.forward_dynamics", ad.forward_dynamics)
    assert len(sigs) == 1 and sigs[0].startswith("armdyn.forward_dynamics(model")
    for name in ("q", "qd", "tau", "t", "method", "data"):
        assert re.search(rf"[(,] ?{name}\b", sigs[0]), name
    assert not doc.startswith("forward_dynamics(")


def test_addresses_are_removed():
    assert GEN._clean("<function f at 0x7f00ab12>") == "<function f>"
