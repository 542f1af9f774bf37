"""load_urdf in its own module (armdyn.urdf): it remembers where each model came from, and the
viewer asks it (armdyn.urdf.urdf_source) instead of the loader pushing the file to the viewer.
The old paths armdyn.load_urdf and armdyn.simulation.load_urdf are the same function."""

import gc
import os
import weakref
from pathlib import Path

import armdyn as ad
import armdyn.simulation
import armdyn.urdf
import pytest

DATA = Path(__file__).resolve().parents[1] / "data" / "urdf"


def test_old_paths_are_the_loader():
    assert ad.load_urdf is armdyn.simulation.load_urdf is armdyn.urdf.load_urdf


def test_a_file_is_remembered_by_its_absolute_path(monkeypatch):
    monkeypatch.chdir(DATA)
    model = ad.load_urdf("slider.urdf")  # a relative path: remembered absolute
    assert armdyn.urdf.urdf_source(model) == os.path.join(str(DATA), "slider.urdf")
    model = ad.load_urdf(Path("slider.urdf"))  # an os.PathLike as well
    assert armdyn.urdf.urdf_source(model) == os.path.join(str(DATA), "slider.urdf")


def test_text_is_remembered_as_text_and_a_builder_model_has_none():
    xml = (DATA / "slider.urdf").read_text(encoding="utf-8")
    assert armdyn.urdf.urdf_source(ad.load_urdf(xml)) == xml
    assert armdyn.urdf.urdf_source(ad.load_urdf(xml.encode("utf-8"))) == xml
    built = ad.scenes.double_pendulum()
    assert armdyn.urdf.urdf_source(built) is None


def test_the_registry_keeps_no_model_alive():
    model = ad.load_urdf(DATA / "slider.urdf")
    ref = weakref.ref(model)
    gc.collect()  # other tests' models gone first: only this one may leave below
    n = len(armdyn.urdf._SOURCES)
    del model
    gc.collect()
    assert ref() is None and len(armdyn.urdf._SOURCES) == n - 1


def test_a_failed_load_remembers_nothing():
    gc.collect()
    n = len(armdyn.urdf._SOURCES)
    with pytest.raises(ad.UrdfError):
        ad.load_urdf(DATA / "bad_syntax.urdf")
    assert len(armdyn.urdf._SOURCES) == n
