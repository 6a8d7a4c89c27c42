"""Shared fixtures: the source tree, the `follicle` CLI (to check that Python and the CLI agree)."""
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(os.environ.get("FOLLICLE_SOURCE_DIR", Path(__file__).resolve().parents[2]))


@pytest.fixture
def root():
    return ROOT


@pytest.fixture
def cli():
    """Runs the follicle CLI; returns the CompletedProcess (text)."""
    exe = os.environ.get("FOLLICLE_CLI")
    if not exe:
        pytest.skip("FOLLICLE_CLI is not set (run through ctest)")

    def run(*args, check=False):
        return subprocess.run([exe, *map(str, args)], capture_output=True, text=True, check=check,
                              cwd=ROOT)

    return run
