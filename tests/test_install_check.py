"""install-check through the real CLI: JSON alone on stdout, a readable table, exit codes."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from ar3cli.install_check import checks as doctor
from tests.conftest import REPO


def test_json_is_clean_and_ok(cli):
    result = cli("install-check", "--format", "json")
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)  # stdout holds the JSON document alone
    assert data["ok"] is True
    names = [check["name"] for check in data["checks"]]
    for expected in ("python", "pybullet", "numpy", "physics", "determinism", "pybullet_data", "xacro",
                     "trimesh", "typer", "rich", "conda/pip", "renderer"):
        assert expected in names
    assert all(set(check) == {"name", "status", "detail", "hint"} for check in data["checks"])
    assert all(check["status"] in {"ok", "warn", "fail", "info"} for check in data["checks"])
    physics = next(c for c in data["checks"] if c["name"] == "physics")
    assert "ms/step" in physics["detail"]


def test_table_output(cli):
    result = cli("install-check")
    assert result.code == 0
    assert "determinism" in result.stdout and "bit-identical" in result.stdout
    assert "ready:" in result.stdout


def test_failing_check_gives_hint_and_crash_is_contained():
    def broken() -> doctor.Check:
        raise RuntimeError("boom")

    results = doctor.run_checks([doctor.check_import("no_such_module_xyz", "no-such-dist"), broken])
    assert results[0].status == "fail" and results[0].hint == "pip install --force-reinstall no-such-dist"
    assert results[1].status == "fail" and "boom" in results[1].detail


def test_determinism_check_detects_identical_states():
    assert doctor.check_determinism().status == "ok"


def test_a_line_per_capability(cli):
    from ar3cli.install_check.capabilities import CAPABILITIES

    data = json.loads(cli("install-check", "--format", "json").stdout)
    rows = {check["name"]: check for check in data["checks"]}
    for capability in CAPABILITIES:
        row = rows[capability.name]
        assert row["status"] in ({"ok"} if capability.required else {"ok", "info"}), row
    assert "pycollada" in rows["COLLADA meshes"]["detail"] and "scipy" in rows["convex hulls"]["detail"]
    assert "V-HACD" in rows["decomposition (V-HACD)"]["detail"]
    if rows["decomposition (CoACD)"]["status"] == "info":
        assert rows["decomposition (CoACD)"]["hint"] == "pip install 'ar3cli[decompose]'"


BLOCKED = """
import json, sys
for module in sys.argv[1].split(","):
    sys.modules[module] = None  # as if the distribution were not installed
from ar3cli.install_check.capabilities import CAPABILITIES, capability_check
capability = next(c for c in CAPABILITIES if c.name == sys.argv[2])
print(json.dumps(capability_check(capability)().to_dict()))
"""


@pytest.mark.parametrize(("blocked", "name", "distribution"), [
    ("scipy,scipy.spatial", "convex hulls", "scipy"),
    ("collada", "COLLADA meshes", "pycollada"),
    ("PIL,PIL.Image", "PNG output", "pillow"),
    ("coacd", "decomposition (CoACD)", "ar3cli[decompose]"),
])
def test_a_missing_library_fails_its_capability_with_the_pip_command(blocked, name, distribution):
    """A plain install that lacks a runtime library (as pycollada and scipy once were) is not 'ready'."""
    result = subprocess.run([sys.executable, "-c", BLOCKED, blocked, name], capture_output=True, text=True,
                            timeout=120, cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)})
    row = json.loads(result.stdout)
    assert row["status"] == ("info" if distribution.startswith("ar3cli[") else "fail"), row
    assert row["hint"].startswith(f"pip install '{distribution}"), row
