"""Finds and runs the ```python blocks of README.md and docs/*.md.

A block runs alone, in a fresh namespace, as a user pasting it would run it, unless its first
line is a comment starting with ``# continues``: then it runs in the namespace the blocks before
it left, back to the last block without that line. The blocks run in a temporary working
directory (they may write reports). docs/reference.md is generated from docstrings and holds no
examples of its own."""

from __future__ import annotations

import os
import re
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GENERATED = {"reference.md"}
FENCE = re.compile(r"^```(\S*)\s*$")
CONTINUES = re.compile(r"^# continues\b")


def doc_files() -> list[Path]:
    docs = sorted(p for p in (ROOT / "docs").glob("*.md") if p.name not in GENERATED)
    return [ROOT / "README.md", *docs]


def fenced_blocks(text: str) -> list[tuple[int, str, str]]:
    """(line of the opening fence, language tag, code) of every fenced block, in order."""
    out, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m:
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            out.append((i + 1, m.group(1), "\n".join(lines[i + 1 : j]) + "\n"))
            i = j
        i += 1
    return out


@dataclass
class Block:
    file: str
    line: int
    code: str
    continues: bool
    ns: dict = field(default_factory=dict)
    seconds: float = 0.0  # CPU time of this process (not wall time: load does not add to it)
    error: str | None = None
    workdir: Path | None = None

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}"


def run_blocks(files: list[Path], workdir: Path) -> list[Block]:
    blocks: list[Block] = []
    cwd = Path.cwd()
    os.chdir(workdir)
    try:
        for path in files:
            ns: dict = {}
            for line, lang, code in fenced_blocks(path.read_text("utf-8")):
                if lang != "python":
                    continue
                continues = bool(CONTINUES.match(code))
                if not continues:  # a script's namespace: `if __name__ == "__main__":` runs
                    ns = {"__name__": "__main__"}
                block = Block(str(path.relative_to(ROOT)), line, code, continues, ns)
                block.workdir = workdir
                start = time.process_time()
                try:
                    exec(compile(code, block.where, "exec"), ns)
                except Exception as exc:  # reported by the tests
                    block.error = "".join(traceback.format_exception(exc)[-6:])
                block.seconds = time.process_time() - start
                blocks.append(block)
    finally:
        os.chdir(cwd)
    return blocks


def namespace_with(blocks: list[Block], file: str, *names: str) -> dict:
    """The namespace of the first block of ``file`` that defines every one of ``names``."""
    for b in blocks:
        if b.file == file and all(n in b.ns for n in names):
            assert b.error is None, f"{b.where} failed:\n{b.error}"
            return b.ns
    raise AssertionError(f"no python block of {file} defines {names}")
