"""docs/python.md runs as written: its ```python blocks, in order, in a temporary folder where
the repository's files are reachable by the same relative paths (``scenarios/``, ``tests/``,
``examples/``, ``benches/`` linked in), and every file the page names ships with the
repository."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "python.md"


def python_blocks(markdown: str) -> list[str]:
    """The ```python blocks of a Markdown text, in order."""
    return re.findall(r"^```python\n(.*?)^```", markdown, flags=re.S | re.M)


def test_the_page_has_python_to_run():
    blocks = python_blocks(PAGE.read_text(encoding="utf-8"))
    assert blocks, "docs/python.md has no ```python block"
    assert python_blocks("text\n```python\nx = 1\n```\n\n```sh\nls\n```\n") == ["x = 1\n"]


def test_every_file_the_page_names_ships_with_the_repository():
    text = PAGE.read_text(encoding="utf-8")
    names = set(re.findall(r"[\"`]((?:scenarios|tests|examples|benches|python|tools)/[^\"`\s]+\.(?:json|csv|py|ipynb))[\"`]", text))
    assert len(names) >= 5, names
    missing = sorted(n for n in names if not (ROOT / n).is_file())
    assert not missing, f"docs/python.md names files that are not in the repository: {missing}"


def test_the_python_blocks_run_in_order(tmp_path, monkeypatch):
    pytest.importorskip("pandas", reason="docs/python.md calls run.to_pandas(): pip install '.[test]'")
    for name in ("scenarios", "tests", "examples", "benches"):
        os.symlink(ROOT / name, tmp_path / name)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__docs__"}
    for i, block in enumerate(python_blocks(PAGE.read_text(encoding="utf-8"))):
        exec(compile(block, f"docs/python.md block {i + 1}", "exec"), namespace)
