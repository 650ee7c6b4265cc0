"""Shared helpers of the Python package's tests.

The tests run against the installed package (``pip install .``, as ``.ci/run`` does in a fresh
virtual environment). Tests that compare with the command-line tool need the ``platen``
binary: ``PLATEN_CLI`` names it (``.ci/run`` sets it to the one ``cargo test`` built), else
``target/release/platen`` or ``target/debug/platen`` is used; without one they are skipped
with a message saying so. Tests that need the PEER records skip without ``PLATEN_RECORDS_DIR``.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "tests" / "data" / "reference"
SCENARIOS = ROOT / "scenarios"


def read_csv(path) -> dict:
    """Every column of a CSV as float64 arrays, each cell parsed by Python's correctly
    rounded ``float()`` (so that shortest round-trip text gives back the exact double)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return {name: np.array([float(r[j]) for r in body]) for j, name in enumerate(header)}


def cli_path():
    given = os.environ.get("PLATEN_CLI")
    if given:
        if not Path(given).is_file():
            raise FileNotFoundError(f"PLATEN_CLI={given} is not a file")
        return Path(given)
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "platen"
        if p.is_file():
            return p
    return None


@pytest.fixture(scope="session")
def cli():
    """Runs the ``platen`` binary: ``cli(args…)`` → CompletedProcess (text)."""
    binary = cli_path()
    if binary is None:
        pytest.skip("SKIPPED: no platen binary (set PLATEN_CLI or run cargo build) to compare with")

    def run(*args, check=True):
        p = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"platen {' '.join(map(str, args))} exited {p.returncode}: {p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    def run(*args):
        return json.loads(cli(*args, "--json").stdout)

    return run


def records_dir():
    d = os.environ.get("PLATEN_RECORDS_DIR")
    return Path(d) if d and Path(d).is_dir() else None
