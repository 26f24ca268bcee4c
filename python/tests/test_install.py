"""The package as installed: the Rust module beside the Python layer, its version the
workspace's, built for the stable ABI (one wheel for every Python from 3.9)."""

import re
from pathlib import Path

import stf_lab
from stf_lab import _stf_lab

from conftest import REPO


def test_the_version_is_the_workspaces():
    cargo = (REPO / "Cargo.toml").read_text()
    version = re.search(r'\[workspace\.package\]\s*version = "([^"]+)"', cargo).group(1)
    assert stf_lab.__version__ == version


def test_the_module_is_built_for_the_stable_abi():
    name = Path(_stf_lab.__file__).name
    assert name.startswith("_stf_lab.") and ".abi3." in name, name


def test_the_public_names_resolve():
    for name in stf_lab.__all__:
        assert getattr(stf_lab, name) is not None
