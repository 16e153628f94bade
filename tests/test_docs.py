"""The docs cannot rot: every ``>>>`` sample in docs/*.md runs as a doctest, and every complete
```python block marked runnable (the README's example and the docs' full programs) runs."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC_FILES = sorted(p for p in (ROOT / "docs").rglob("*.md") if ">>>" in p.read_text())


@pytest.mark.parametrize("path", DOC_FILES, ids=lambda p: p.name)
def test_doctests_in_docs(path):
    result = doctest.testfile(str(path), module_relative=False, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0, f"{result.failed} doctest failures in {path.name}"


def _python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def test_readme_example_runs_and_prints_what_it_says(capsys):
    (block,) = [b for b in _python_blocks(ROOT / "README.md") if "Scene(" in b]
    exec(compile(block, "README.md", "exec"), {})
    out = capsys.readouterr().out.splitlines()
    # The comments in the block say what it prints.
    expected = re.findall(r"# (\[.*?\]|[0-9.]+):", block)
    assert out == expected
