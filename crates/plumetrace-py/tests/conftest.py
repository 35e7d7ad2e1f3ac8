"""Shared fixtures: the command-line binary the Python results are compared with."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The `plumetrace` binary (PLUMETRACE_BIN, or the repository's release build)."""
    given = os.environ.get("PLUMETRACE_BIN")
    path = pathlib.Path(given) if given else REPO / "target" / "release" / "plumetrace"
    if not path.exists():
        if given:
            pytest.fail(f"PLUMETRACE_BIN={given} does not exist")
        pytest.skip("no release build of the command line (cargo build --release)")
    return path


def run_cli(cli: pathlib.Path, *args: str) -> str:
    """Runs the command line; returns its standard output."""
    out = subprocess.run([str(cli), *args], check=True, capture_output=True, text=True)
    return out.stdout
