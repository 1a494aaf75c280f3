"""Shared fixtures: where the repository, its data and the CLI are."""
import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def repo():
    return REPO


@pytest.fixture(scope="session")
def data_dir():
    return REPO / "data"


@pytest.fixture(scope="session")
def cli():
    """Path of the geods executable (GEODS_CLI, else the release build)."""
    path = pathlib.Path(os.environ.get("GEODS_CLI", REPO / "build" / "release" / "bin" / "geods")).resolve()
    if not path.exists():
        pytest.fail(f"geods CLI not found at {path}; build it or set GEODS_CLI")
    return path


@pytest.fixture
def workdir(tmp_path):
    """A scratch folder holding a link to data/, as the docs examples expect."""
    (tmp_path / "data").symlink_to(REPO / "data")
    return tmp_path
