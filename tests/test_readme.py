"""The README's Python examples run as written (each in a fresh interpreter, in a scratch folder).

Every ```python block of README.md is one example; a block must finish without error and may
check its own results with ``assert``. The shell block of set-up commands is run by .ci/run.
"""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"
BLOCKS = re.findall(r"^```python\n(.*?)^```", README.read_text(encoding="utf-8"), flags=re.S | re.M)


def test_readme_has_the_promised_examples():
    text = "\n".join(BLOCKS)
    for needle in ("squeeze_out", "seal_leak", "tire_footprint", "run_sweep", "psd_from_heights"):
        assert needle in text, f"README has no runnable example using {needle}"


@pytest.mark.parametrize("i", range(len(BLOCKS)), ids=lambda i: f"block{i}")
def test_readme_example_runs(i, tmp_path):
    script = tmp_path / f"readme_block_{i}.py"
    script.write_text(BLOCKS[i], encoding="utf-8")
    res = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True,
                         timeout=600)
    assert res.returncode == 0, f"README block {i} failed:\n{BLOCKS[i]}\n--- stderr ---\n{res.stderr[-3000:]}"


def test_suite_runs_without_pytest_xdist():
    """pyproject's addopts ask pytest-xdist for every core (``-n auto --dist loadfile``);
    with pytest alone (here: the plugin disabled) the suite must still start, in one process,
    and say so, not stop at "unrecognized arguments: -n" (tests/conftest.py)."""
    root = README.parent
    res = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:xdist", "--collect-only",
                          "-q", "tests/test_readme.py"], cwd=root, capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    assert "test_suite_runs_without_pytest_xdist" in res.stdout
    res = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:xdist", "--co",
                          "tests/test_readme.py"], cwd=root, capture_output=True, text=True,
                         timeout=300)
    assert "pytest-xdist is not loaded: the tests run in one process" in res.stdout
