"""Real models: every pybullet_data URDF lints without a traceback, and known problems are found."""

from __future__ import annotations

from pathlib import Path

import pytest

from ar3cli.lint.engine import LintOptions, lint_paths
from ar3cli.lint.rules.docs import generate
from tests.conftest import REPO


def _findings(results, name: str) -> list:
    (result,) = [r for r in results if r.path.endswith(name)]
    return result.findings


@pytest.fixture(scope="module")
def pybullet_results():
    import pybullet_data

    root = Path(pybullet_data.getDataPath())
    return lint_paths([root], LintOptions())


def test_every_pybullet_data_file_lints(pybullet_results):
    assert len(pybullet_results) >= 1095  # 95 models + 1000 random_urdfs
    assert all(result.loaded for result in pybullet_results)


def test_random_urdfs_have_a_zero_principal_moment(pybullet_results):
    random_results = [r for r in pybullet_results if "/random_urdfs/" in r.path]
    assert len(random_results) == 1000
    # every random object declares izz="0" with ixx = iyy = 1 on a 0.1 kg, ~10 cm object
    assert all(any(f.rule == "I004" and "(0, 1, 1)" in f.message for f in r.findings) for r in random_results)


def test_known_findings_on_real_models(pybullet_results):
    kuka = _findings(pybullet_results, "kuka_iiwa/model_for_sdf.urdf")
    missing = [f for f in kuka if f.rule == "G001"]
    assert len(missing) == 8 and "meshes/coarse/link_0.stl" in missing[0].message
    panda = _findings(pybullet_results, "franka_panda/panda.urdf")
    fingers = [f for f in panda if f.rule == "I007" and "finger" in f.message]
    assert len(fingers) == 2 and all("31x" in f.message for f in fingers)  # against visual and collision: 0.0318 m
    assert {f.rule for f in _findings(pybullet_results, "r2d2.urdf")} >= {"J006"}
    laikago = _findings(pybullet_results, "laikago/laikago.urdf")
    assert sum(f.rule == "I006" for f in laikago) == 13  # all-zero tensors on every link
    bike = _findings(pybullet_results, "bicycle/bike.urdf")
    assert any(f.rule == "F007" and "'0.07,'" in f.message for f in bike)
    husky = _findings(pybullet_results, "husky/husky.urdf")
    assert sum(f.rule == "F006" for f in husky) == 2
    assert any(f.rule == "F005" and "NUL" in f.message for f in _findings(pybullet_results, "humanoid/humanoid.urdf"))
    assert sum(f.rule == "S010" for f in _findings(pybullet_results, "humanoid/humanoid.urdf")) == 8


def test_real_ar3_description(shared_dir):
    description = shared_dir / "models" / "ar3_description"
    options = LintOptions(package_paths={"ar3_description": description})
    (urdf,) = lint_paths([description / "urdf" / "ar3.urdf"], options)
    continuous = [f for f in urdf.findings if f.rule == "J011"]
    assert [f.message.split("'")[1] for f in continuous] == [f"joint_{i}" for i in range(1, 6)]
    (xacro,) = lint_paths([description / "urdf" / "ar3.urdf.xacro"], options)
    zero = [f for f in xacro.findings if f.rule == "J008"]
    assert len(zero) == 6 and all("effort=0 and velocity=0" in f.message for f in zero)
    assert all(f.path.endswith("ar3.urdf.xacro") and f.line > 0 for f in zero)


def test_bundled_examples():
    examples = REPO / "assets" / "examples"
    if not examples.is_dir():
        pytest.skip("assets/examples not present")
    results = {Path(r.path).name: {f.rule for f in r.findings} for r in lint_paths([examples], LintOptions())}
    assert "I001" in results["ar3_no_inertia.urdf"]
    assert "J006" in results["ar3_fake_continuous.urdf"]
    assert "J008" in results["ar3_zero_effort.urdf"]


def test_docs_rules_md_is_generated_from_the_registry():
    committed = (REPO / "docs" / "rules.md").read_text(encoding="utf-8")
    assert committed == generate(), "docs/rules.md is stale: python -m ar3cli.lint.rules.docs > docs/rules.md"


def test_pre_commit_hooks_file():
    import yaml

    hooks = {hook["id"]: hook for hook in yaml.safe_load((REPO / ".pre-commit-hooks.yaml").read_text())}
    assert hooks["ar3cli-lint"]["entry"] == "ar3cli lint-urdf" and hooks["ar3cli-lint"]["files"] == r"\.(urdf|xacro)$"
    assert hooks["ar3cli-lint-sim"]["entry"] == "ar3cli lint-urdf --sim" and hooks["ar3cli-lint-sim"]["require_serial"]
