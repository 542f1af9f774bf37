"""The session fixture of the documentation tests: every ```python block of README.md and
docs/*.md, run once (doc_blocks.py says how)."""

import pytest
from doc_blocks import Block, doc_files, run_blocks


@pytest.fixture(scope="session")
def doc_blocks(tmp_path_factory) -> list[Block]:
    return run_blocks(doc_files(), tmp_path_factory.mktemp("doc-blocks"))
