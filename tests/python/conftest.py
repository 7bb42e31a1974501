"""Shared fixtures: the command line to compare with and the repository's plans.

ctest runs these with PYTHONPATH=<build>/python and ARTCAL_CLI=<build>/tools/artcal
(tests/CMakeLists.txt); by hand: PYTHONPATH=build/python ARTCAL_CLI=build/tools/artcal
/usr/bin/python3 -m pytest tests/python
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli_path() -> str:
    return os.environ.get("ARTCAL_CLI", str(ROOT / "build" / "tools" / "artcal"))


def run_cli(*args: str, expect=(0, 1)) -> subprocess.CompletedProcess:
    """Runs the command line from the repository root (plans name their CSV files from there)."""
    done = subprocess.run([cli_path(), *args], cwd=ROOT, capture_output=True, text=True,
                          check=False)
    assert done.returncode in expect, done.stderr
    return done


def cli_json(*args: str, expect=(0, 1)):
    return json.loads(run_cli(*args, expect=expect).stdout)


def cli_error(*args: str) -> str:
    """The command line's one error line, without "error: "."""
    done = run_cli(*args, expect=(1, 2))
    lines = [line for line in done.stderr.splitlines() if line.startswith("error: ")]
    assert len(lines) == 1, done.stderr
    return lines[0][len("error: "):]


@pytest.fixture(autouse=True)
def at_root(monkeypatch):
    """Plans name their CSV files relative to the repository root, as the command line runs."""
    monkeypatch.chdir(ROOT)
