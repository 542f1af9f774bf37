"""Every ```python block of README.md and docs/*.md runs, as pasted (alone, unless it says it
continues the block before it), and all of them together are a few seconds of computation
(CPU time of this process, which other processes on a loaded machine do not add to); every
other fenced block says what it is (```text, ```bash, ...), so that a reader knows what is
meant to run."""

import pytest
from doc_blocks import ROOT, doc_files, fenced_blocks

# CPU seconds of all blocks together (the report of test_blocks_are_quick prints them); three
# times what they take means some block became a long computation. CPU time, not wall time: a
# busy machine slows the blocks down but does not add to it (Dask workers' own CPU is not counted)
TOTAL_SECONDS = 60.0


FILES = [path.relative_to(ROOT).as_posix() for path in doc_files()]


@pytest.mark.parametrize("file", FILES)
def test_every_python_block_runs(doc_file_blocks, file):
    """One file at a time (each test runs that file's blocks, once per session)."""
    blocks = doc_file_blocks(file)
    failed = [f"{b.where}:\n{b.error}" for b in blocks if b.error is not None]
    assert not failed, "\n".join(failed)


def test_the_blocks_are_found(doc_blocks):
    assert len(doc_blocks) >= 15
    assert {b.file for b in doc_blocks} >= {"README.md", "docs/api.md"}


def test_continuing_blocks_say_so(doc_blocks):
    """A block that says it continues follows another python block of the same file; the README
    quick start and the first block of each file stand alone."""
    first = {}
    for b in doc_blocks:
        first.setdefault(b.file, b)
    assert all(not b.continues for b in first.values())


def test_blocks_are_quick(doc_blocks):
    total = sum(b.seconds for b in doc_blocks)
    slowest = sorted(doc_blocks, key=lambda b: -b.seconds)[:3]
    print(f"\n{len(doc_blocks)} blocks in {total:.1f} CPU s; slowest:")
    for b in slowest:
        print(f"  {b.where}: {b.seconds:.1f} CPU s")
    assert total < TOTAL_SECONDS, [(b.where, round(b.seconds, 1)) for b in slowest]


def test_every_fence_names_its_language():
    untagged = [
        f"{path.name}:{line}"
        for path in doc_files()
        for line, lang, _ in fenced_blocks(path.read_text("utf-8"))
        if not lang
    ]
    assert not untagged, untagged


def test_fence_parser():
    text = "a\n```python\nx = 1\n```\n```text\n$ out\n```\n```\nbare\n```\n"
    expected = [(2, "python", "x = 1\n"), (5, "text", "$ out\n"), (8, "", "bare\n")]
    assert fenced_blocks(text) == expected
