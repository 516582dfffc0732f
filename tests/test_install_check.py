"""install-check through the real CLI: JSON alone on stdout, a readable table, exit codes."""

from __future__ import annotations

import json

from ar3cli.doctor import checks as doctor


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
