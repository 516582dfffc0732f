"""Install = what runs: every library ar3cli imports at run time is a declared dependency.

Cheap checks on the source and pyproject.toml (no venv is built here; ``.ci/run``'s second stage
builds one and runs every command from it). A library only the ``test`` extra brings (yourdfpy once
brought pycollada and scipy) would pass the test suite and fail a user; these tests fail first.
"""

from __future__ import annotations

import ast
import re
import sys

from tests.conftest import REPO

IMPORT_DISTRIBUTIONS = {"PIL": "pillow", "yaml": "pyyaml", "pybullet_data": "pybullet", "collada": "pycollada"}
"""Import names whose distribution has another name; any other import is its own distribution."""

GUARDED = {"coacd": "decompose", "mujoco": "mujoco", "ray": "ray", "pygls": "server", "lsprotocol": "server",
           "viser": "view", "tomli": None, "click": None}
"""Imports that may be absent: coacd, mujoco, ray, pygls, lsprotocol and viser belong to extras (fix-collision
checks ``find_spec`` first; ``--engine mujoco``, cross-check, ``scan --backend ray``, ``server`` and ``view``
say in one line how to install them), tomli is declared for Python < 3.11 only (``tomllib`` is used where it exists),
click is the fallback of options.py for a typer that does not vendor it (typer then depends on it)."""


def _pyproject() -> dict:
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    return tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))


def _name(requirement: str) -> str:
    return re.sub(r"[-_.]+", "-", re.match(r"[A-Za-z0-9._-]+", requirement).group()).lower()


def declared() -> set[str]:
    return {_name(r) for r in _pyproject()["project"]["dependencies"]}


def runtime_imports() -> dict[str, set[str]]:
    """Top-level third-party module -> the ar3cli files that import it (at module level or inside a function)."""
    found: dict[str, set[str]] = {}
    for path in sorted((REPO / "ar3cli").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            elif _held_import(node):  # import_holding_interrupts("trimesh") is an import too
                names = [node.args[0].value]
            else:
                continue
            for name in names:
                top = name.partition(".")[0]
                if top != "ar3cli" and top not in sys.stdlib_module_names and top != "tomllib":
                    found.setdefault(top, set()).add(str(path.relative_to(REPO)))
    return found


def _held_import(node: ast.AST) -> bool:
    """A call ``import_holding_interrupts("name")`` (:mod:`ar3cli.infra.held_import`)."""
    return (isinstance(node, ast.Call) and getattr(node.func, "id", None) == "import_holding_interrupts"
            and len(node.args) == 1 and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str))


def test_every_runtime_import_is_a_declared_dependency():
    dependencies = declared()
    extras = {name: {_name(r) for r in requirements}
              for name, requirements in _pyproject()["project"]["optional-dependencies"].items()}
    undeclared = {}
    for module, files in runtime_imports().items():
        distribution = _name(IMPORT_DISTRIBUTIONS.get(module, module))
        if module in GUARDED:
            extra = GUARDED[module]
            assert extra is None or distribution in extras[extra], f"{module} is in no {extra!r} extra"
            continue
        if distribution not in dependencies:
            undeclared[distribution] = sorted(files)
    assert not undeclared, f"imported by ar3cli but not in pyproject's dependencies: {undeclared}"
    assert "tomli" in dependencies, "Python 3.10 reads [tool.ar3cli.lint] with tomli"


def test_the_scan_sees_imports_inside_functions():
    imports = runtime_imports()
    assert "ar3cli/fix/geometry_mass.py" in imports["trimesh"]  # imported inside load_welded_mesh
    assert {"PIL", "pybullet", "xacro", "coacd"} <= set(imports)


def test_every_capability_needs_only_declared_libraries():
    """trimesh declares none of its optional libraries: what a capability needs must be listed by ar3cli."""
    from ar3cli.install_check.capabilities import CAPABILITIES

    dependencies = declared()
    extras = {name: {_name(r) for r in requirements}
              for name, requirements in _pyproject()["project"]["optional-dependencies"].items()}
    for capability in CAPABILITIES:
        available = dependencies if capability.required else dependencies | extras[capability.extra]
        assert {_name(n) for n in capability.needs} <= available, capability.name
    assert {"pycollada", "scipy"} <= dependencies


def test_the_test_extra_holds_no_runtime_library():
    """A library in the test extra that ar3cli imports would hide a missing dependency from CI's test run,
    unless it belongs to an extra of its own and its absence is a one-line error (GUARDED: mujoco, ray)."""
    test_extra = {_name(r) for r in _pyproject()["project"]["optional-dependencies"]["test"]}
    used = {_name(IMPORT_DISTRIBUTIONS.get(m, m)) for m in runtime_imports()}
    optional = {_name(IMPORT_DISTRIBUTIONS.get(m, m)) for m, extra in GUARDED.items() if extra}
    assert not (test_extra & used - declared() - optional)


def test_ci_runs_the_plain_install_stage_after_the_readme_command():
    run = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    readme_stage, _, plain_stage = run.partition("Second stage")
    assert 'bash -euo pipefail -c "$command"' in readme_stage
    assert "pip install" in plain_stage and "[test]" not in plain_stage
    assert ".ci/plain_install_smoke.py" in plain_stage and (REPO / ".ci" / "plain_install_smoke.py").is_file()


def _smoke_module():
    import importlib.util

    spec = importlib.util.spec_from_file_location("plain_install_smoke", REPO / ".ci" / "plain_install_smoke.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_smoke_fixture_has_what_its_steps_need(tmp_path, cli):
    """CI's plain-install stage depends on its fixture: a closed U-shaped STL whose hull is far larger
    (fix-collision must decompose it), a .dae link without an inertial (fix-inertia must compute one)."""
    import trimesh

    smoke = _smoke_module()
    robot = smoke.make_robot(tmp_path)
    u = trimesh.load(str(tmp_path / "meshes" / "u.stl"))
    assert u.is_watertight and u.convex_hull.volume / u.volume > 2
    assert "<inertial>" not in smoke.link_text(robot, "cube_link")
    assert str(tmp_path.resolve()) in robot.read_text()  # fix-mesh-paths has an absolute path to rewrite
    result = cli("info", str(robot), "--format", "json")
    assert result.code == 0, result.stderr
