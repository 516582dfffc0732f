"""The wheel a user installs with ``pip install .`` carries the bundled models and the CLI entry point."""

from __future__ import annotations

import subprocess
import sys
import zipfile

import pytest

from tests.conftest import ASSETS, REPO


@pytest.mark.slow
def test_wheel_contains_assets_and_console_script(tmp_path):
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path), str(REPO)],
                           capture_output=True, text=True, timeout=300)
    assert built.returncode == 0, built.stderr
    (wheel,) = tmp_path.glob("ar3cli-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for asset in ASSETS.rglob("*.urdf"):
        assert f"ar3cli/assets/{asset.relative_to(ASSETS).as_posix()}" in names
    entry_points = next(name for name in names if name.endswith("entry_points.txt"))
    assert "ar3cli = ar3cli.cli:run" in zipfile.ZipFile(wheel).read(entry_points).decode()
