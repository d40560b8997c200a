"""Shared fixtures: the command-line binary the package is compared with."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The `motorfactory` binary (MOTORFACTORY_BIN, else the checkout's release build)."""
    path = pathlib.Path(os.environ.get("MOTORFACTORY_BIN", ROOT / "target/release/motorfactory"))
    if not path.is_file():
        subprocess.run(["cargo", "build", "--release", "-q"], cwd=ROOT, check=True)
    return path


def dataset_files(folder: pathlib.Path) -> "dict[str, bytes]":
    """Every file of a dataset folder but the shards' manifests and the runs' lock files: what
    two runs that wrote the same dataset hold alike, byte for byte."""
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
        and not p.name.startswith("manifest-")
        and ".motorfactory" not in p.relative_to(folder).parts
    }
