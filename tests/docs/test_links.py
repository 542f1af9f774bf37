"""Every relative link and image of README.md and docs/*.md points at a file of the repository,
and every #anchor at a heading of its target (GitHub's heading slugs)."""

import re
from pathlib import Path

from doc_blocks import ROOT, fenced_blocks

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = heading.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    text = _prose(path.read_text("utf-8"))
    return {slug(m.group(1)) for m in re.finditer(r"^#+ (.+)$", text, re.M)}


def _prose(text: str) -> str:
    """The text without its fenced blocks (a `#` comment in code is no heading)."""
    for _, _, code in fenced_blocks(text):
        text = text.replace(code, "", 1)
    return text


def test_slug():
    assert slug("Error against run time (work–precision)") == "error-against-run-time-workprecision"
    assert slug("## `armdyn.sizing`".lstrip("# ")) == "armdynsizing"


def test_links_resolve():
    files = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    broken = []
    n = 0
    for path in files:
        for target in LINK.findall(_prose(path.read_text("utf-8"))):
            if re.match(r"^[a-z]+:", target):
                continue
            n += 1
            file, _, anchor = target.partition("#")
            dest = (path.parent / file).resolve() if file else path
            if not dest.exists():
                broken.append(f"{path.name}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{path.name}: {target} (no such heading)")
    assert n >= 40
    assert not broken, broken
