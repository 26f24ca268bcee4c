"""Shared fixtures of the Python package's tests: the repository root (bundled experiments and
records), the command-line program for parity checks, and a working folder."""

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def repo(monkeypatch):
    """The repository root, made the working directory (experiment paths as the README gives
    them, so messages and JSON name them as the command line does)."""
    monkeypatch.chdir(REPO)
    return REPO


def _stf_lab_bin():
    given = os.environ.get("STF_LAB_BIN")
    if given:
        return given
    for profile in ("release", "debug"):
        p = REPO / "target" / profile / "stf-lab"
        if p.is_file():
            return str(p)
    return shutil.which("stf-lab")


@pytest.fixture
def stf_lab_bin():
    """The `stf-lab` program (STF_LAB_BIN, as tests/python_package.rs sets it, or a build in
    target/); a parity test is skipped without one, and fails without one under
    STF_LAB_REQUIRE_PYTHON=1."""
    path = _stf_lab_bin()
    if path is None:
        if os.environ.get("STF_LAB_REQUIRE_PYTHON") == "1":
            pytest.fail("no stf-lab program for the parity check (set STF_LAB_BIN)")
        pytest.skip("no stf-lab program found: set STF_LAB_BIN or build it")
    return path
