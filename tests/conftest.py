"""Shared test helpers: run the real CLI in a subprocess, find real models, write small fixtures."""

from __future__ import annotations

import atexit
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import pytest

if "AR3CLI_CACHE_DIR" not in os.environ:
    _TEST_CACHE = tempfile.mkdtemp(prefix="ar3cli-test-cache-")
    os.environ["AR3CLI_CACHE_DIR"] = _TEST_CACHE
    atexit.register(shutil.rmtree, _TEST_CACHE, ignore_errors=True)  # no folder outlives the test run
"""Tests (and the CLI processes they start) never write to the user's ~/.cache."""

REPO = Path(__file__).resolve().parents[1]
ASSETS = REPO / "assets"
SHARED = REPO.parent / "shared"
"""The steering repo's shared/ folder sits beside the clone in CI and in development."""


@dataclass
class CliResult:
    code: int
    stdout: str
    stderr: str


def run_cli(*args: str, cwd: Path | None = None, env: dict[str, str] | None = None,
            timeout: float = 300) -> CliResult:
    """Run ``python -m ar3cli ARGS`` in a fresh process, as a user would (C-level output included)."""
    environment = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1", **(env or {})}
    completed = subprocess.run([sys.executable, "-m", "ar3cli", *args], cwd=cwd or REPO, env=environment,
                               capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)
    return CliResult(completed.returncode, completed.stdout, completed.stderr)


def cache_files(folder: Path, name: str) -> list[Path]:
    """The shard files of the on-disk cache ``name`` (e.g. ``lint-results-v1``) under ``folder``."""
    return sorted((folder / name).glob("*.json"))


def cache_entries(folder: Path, name: str) -> dict:
    """Every entry of the on-disk cache ``name`` under ``folder``, all its shard files merged."""
    import json

    return {key: value for shard in cache_files(folder, name) for key, value in json.loads(shard.read_text()).items()}


@pytest.fixture
def cli():
    """The :func:`run_cli` helper as a fixture."""
    return run_cli


@pytest.fixture
def session():
    """A fresh PyBullet session (DIRECT) for one test, closed afterwards."""
    from ar3cli.sim.session import Session

    with Session() as opened:
        yield opened


@pytest.fixture(scope="session")
def pybullet_data_dir() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath())


@pytest.fixture
def shared_dir() -> Path:
    """shared/ beside the clone; tests that need it skip cleanly where it is absent."""
    if not SHARED.is_dir():
        pytest.skip("the shared/ folder is not beside the clone (it is in CI)")
    return SHARED


@pytest.fixture
def write_urdf(tmp_path):
    """Write a small URDF (text) into tmp_path and return its path."""

    def write(text: str, name: str = "robot.urdf") -> Path:
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        return path

    return write


UNPRIVILEGED_UID = 65534
"""``nobody``: the user a root test run drops to where a check must see real permissions."""


def as_unprivileged(work, *paths: Path) -> None:
    """Run ``work()`` as a user the kernel really refuses writes to, whoever runs the tests.

    As root (CI), permission checks pass everywhere, so ``work`` runs in a forked child that gives
    ``paths`` to ``nobody`` and becomes ``nobody`` first; an exception in it (a failed assert) fails
    the test with its text. As anyone else, ``work()`` runs here.
    """
    if os.geteuid() != 0:
        work()
        return
    import traceback

    for path in paths:
        os.chown(path, UNPRIVILEGED_UID, UNPRIVILEGED_UID)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: drop root, run, report
        os.close(read)
        status = 0
        try:
            os.setgroups([])
            os.setgid(UNPRIVILEGED_UID)
            os.setuid(UNPRIVILEGED_UID)
            work()
        except BaseException:  # noqa: BLE001 - everything goes back to the parent as text
            os.write(write, traceback.format_exc().encode())
            status = 1
        os._exit(status)
    os.close(write)
    with os.fdopen(read, "rb") as stream:
        failure = stream.read().decode()
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, f"as uid {UNPRIVILEGED_UID}:\n{failure}"


@pytest.fixture
def open_tmp_path():
    """A temporary folder every user may enter (pytest's own sit under a root-only 0700 folder), for
    tests that drop to :data:`UNPRIVILEGED_UID`; removed afterwards."""
    folder = Path(tempfile.mkdtemp(prefix="ar3cli-test-"))
    folder.chmod(0o755)
    yield folder
    shutil.rmtree(folder, ignore_errors=True)
