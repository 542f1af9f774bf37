"""Memory-safe model bytes: thousands of mutated `Model` states (tests/model/model_bytes_fuzz.py:
counts and indices +-1 and extreme, floats to NaN/inf/1e308, byte flips, truncations,
extensions, swapped segments, other format versions) of three models that together use every
field of the format, each loaded in a child interpreter with a memory limit and a timeout. Each
either raises ModelError or loads as a model that works (forward dynamics, a short simulation,
a pickle round trip giving the same bytes); no signal, no timeout, no other exception. Fixed
seeds; 2,000 mutants per model, 6,000 in all, in parts of at most 1,000. Also the named
errors of a few hand-made bad states."""

from __future__ import annotations

import collections
import pickle
import struct

import armdyn as ad
import model_bytes_fuzz as fuzz
import pytest

PER_MODEL = 2000
# the builder model (17 bodies) costs most per loaded mutant: more, smaller parts
PARTS = {"builder": 4, "floating": 2, "ur5": 2}


@pytest.mark.parametrize(
    ("name", "part"), [(name, part) for name, n in PARTS.items() for part in range(n)]
)
def test_mutated_model_bytes_load_or_raise_model_error(name, part):
    count = PER_MODEL // PARTS[name]
    results = fuzz.fuzz(name, part, count)
    failures = [(label, verdict) for label, verdict in results if fuzz.is_failure(verdict)]
    assert not failures, failures[:20]
    counts = collections.Counter(verdict for _, verdict in results)
    # the mutants reach both outcomes: the refusals and models that load and run
    assert counts["refused"] > count // 5 and counts["loaded ok"] > count // 20, counts


def load(data):
    model = ad.Model.__new__(ad.Model)
    model.__setstate__((data,))
    return model


def test_bad_states_name_the_field():
    model = fuzz.floating_model()
    data = bytes(model.__getstate__()[0])
    assert load(data).__getstate__()[0] == data
    # the header: another format version, a builder's draft, not bytes at all
    other = data[:8] + struct.pack("<I", 1) + data[12:]
    with pytest.raises(ad.ModelError, match=r"format: format version 1, this armdyn reads"):
        load(other)
    draft = pickle.loads(pickle.dumps(ad.ModelBuilder())).__getstate__()[0]
    with pytest.raises(ad.ModelError, match=r"kind: a builder's draft, not a model"):
        load(draft)
    with pytest.raises(ad.ModelError, match=r"not one bytes object"):
        ad.Model.__new__(ad.Model).__setstate__(("text",))
    # the body count (after the 13-byte header and gravity) set to 2**62: refused before any
    # allocation, naming the count
    at = 13 + 24
    assert struct.unpack_from("<q", data, at)[0] == model.nb
    huge = data[:at] + struct.pack("<q", 2**62) + data[at + 8 :]
    with pytest.raises(ad.ModelError, match=r"model data: bodies: count 4611686018427387904"):
        load(huge)
    # one body fewer: the joints' indices no longer fit
    fewer = data[:at] + struct.pack("<q", model.nb - 1) + data[at + 8 :]
    with pytest.raises(ad.ModelError, match=r"model data: "):
        load(fewer)
    # the first body's mass (after its name) set to NaN, then to -1
    name = model.body_names[0].encode()
    mass_at = at + 8 + 8 + len(name)
    assert struct.unpack_from("<d", data, mass_at)[0] == model.masses[0]
    for bad, why in ((float("nan"), "must be finite"), (-1.0, "must be >= 0")):
        altered = data[:mass_at] + struct.pack("<d", bad) + data[mass_at + 8 :]
        with pytest.raises(ad.ModelError, match=rf"bodies\[0\] 'base'\.mass: {why}"):
            load(altered)
    with pytest.raises(ad.ModelError, match=r"trailing bytes"):
        load(data + b"\0")
    with pytest.raises(ad.ModelError, match=r"truncated"):
        load(data[:-1])


def test_a_builder_draft_is_checked_too():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.1, 0.1, 0.1])
    b.add_revolute("j", "ground", "a", (0, 0, 0), (0, 0, 1))
    data, physical = b.__getstate__()
    c = pickle.loads(pickle.dumps(b))
    assert c.__getstate__() == (data, physical)
    # the joint's child index (after its name and type) set to 1: only one body exists
    i = data.index(b"\x01\x00\x00\x00\x00\x00\x00\x00j") + 9  # the name 'j', then its type
    child = i + 8 + 8
    assert struct.unpack_from("<q", data, child)[0] == 0
    bad = data[:child] + struct.pack("<q", 1) + data[child + 8 :]
    with pytest.raises(ad.ModelError, match=r"joints\[0\] 'j'\.child: index 1 out of range"):
        ad.ModelBuilder.__new__(ad.ModelBuilder).__setstate__((bad, physical))
    with pytest.raises(ad.ModelError, match=r"not bytes and a bool"):
        ad.ModelBuilder.__new__(ad.ModelBuilder).__setstate__((data, 1))


@pytest.mark.parametrize(
    ("state", "match"),
    [
        ((1, 4, (0.0, 0.0, 0.0, 0.0), [0.0, 0.0], [1.0, 2.0], [], ""), "must increase strictly"),
        ((1, 0, (float("nan"), 0.0, 0.0, 0.0), [], [], [], ""), "must be finite"),
        ((1, 1, (0.0, 1.0, 1.0, 0.0), [], [], [], ""), "need t1 > t0"),
        ((1, 0, (1.0, 2.0, 0.0, 0.0), [], [], [], ""), "stored parameter 1"),
        ((1, "x", (0, 0, 0, 0), [], [], [], ""), "unknown pickled state"),
    ],
)
def test_a_pickled_profile_is_made_again_by_its_factory(state, match):
    """A Profile's pickled state goes through the factory's checks (as the profiles inside the
    model bytes do): a spline whose samples do not increase, a NaN constant, a cubic ending
    before it starts, a parameter the factory would not have stored, a kind that is not a
    number."""
    with pytest.raises(ad.ModelError, match=match):
        ad.Profile.__new__(ad.Profile).__setstate__(state)
