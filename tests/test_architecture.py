"""The import-layer contract of docs/architecture.md: imports point down, no cycles, the picture is true.

Every ``import`` of an ar3cli module counts, also those inside functions (lazy imports are still
dependencies). ``python tests/test_architecture.py`` prints the diagram that docs/architecture.md
must hold between its ``<!-- layers -->`` markers.
"""

from __future__ import annotations

import ast
import re
import sys
from collections import defaultdict
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "ar3cli"
DOC = PACKAGE.parent / "docs" / "architecture.md"

LAYERS: list[tuple[str, list[str]]] = [
    ("entry point", ["__main__"]),
    ("application", ["cli"]),
    ("commands", ["commands"]),
    ("front-ends", ["server", "view"]),
    ("analysis", ["analysis"]),
    ("fixers", ["fix"]),
    ("features", ["lint", "collisions", "kinematics", "pictures", "grasp", "install_check", "info", "robot_diff", "scan",
                  "cross_check"]),
    ("simulation", ["sim"]),
    ("robot files", ["urdf"]),
    ("maths", ["maths"]),
    ("services", ["output", "infra"]),
    ("vocabulary", ["errors", "findings", "__init__"]),
]
"""Top to bottom. A module may import its own package and any package of a lower layer, never a
package of its own layer or of a higher one: features stay independent of each other."""
RANK = {package: len(LAYERS) - index for index, (_, packages) in enumerate(LAYERS) for package in packages}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


LAZY_IMPORT = re.compile(r"ar3cli(\.\w+)+:\w+")
"""A function named by a string, imported when needed (``importlib.import_module``)."""


def package_of(module: str) -> str:
    """``ar3cli.sim.session`` -> ``sim``; ``ar3cli.errors`` -> ``errors``; ``ar3cli`` -> ``__init__``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def imports_of(path: Path, modules: set[str]) -> set[str]:
    """The ar3cli modules ``path`` imports (``from ar3cli.x import y`` counts ``ar3cli.x.y`` when
    that is a module, else ``ar3cli.x``; a ``"ar3cli.x:function"`` string, imported by name later
    as cli.py's COMMANDS are, counts ``ar3cli.x``)."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and LAZY_IMPORT.fullmatch(node.value):
            found.add(node.value.partition(":")[0])
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names if alias.name.startswith("ar3cli"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("ar3cli") and not node.level:
            for alias in node.names:
                candidate = f"{node.module}.{alias.name}"
                found.add(candidate if candidate in modules else node.module)
    return found


def import_graph() -> dict[str, set[str]]:
    files = {module_name(path): path for path in PACKAGE.rglob("*.py")}
    modules = set(files)
    return {module: imports_of(path, modules) & modules - {module} for module, path in files.items()}


def package_edges(graph: dict[str, set[str]]) -> set[tuple[str, str]]:
    return {(package_of(a), package_of(b)) for a, targets in graph.items() for b in targets
            if package_of(a) != package_of(b)}


def mermaid(edges: set[tuple[str, str]]) -> str:
    """The package diagram: one box per layer, an arrow per package-level import (arrows into the
    vocabulary layer, which every package may use, are left out to keep the picture readable)."""
    vocabulary = set(LAYERS[-1][1])
    lines = ["```mermaid", "flowchart TD"]
    for index, (title, packages) in enumerate(LAYERS):
        shown = [p for p in packages if p not in ("__main__", "__init__")]
        if not shown:
            continue
        lines.append(f'  subgraph L{index}["{title}"]')
        lines += [f"    {p}" for p in shown]
        lines.append("  end")
    lines += [f"  {a} --> {b}" for a, b in sorted(edges) if "__" not in a + b and b not in vocabulary]
    lines.append("```")
    return "\n".join(lines) + "\n"


def test_every_package_has_a_layer() -> None:
    packages = {package_of(module) for module in import_graph()}
    assert packages <= set(RANK), f"give these packages a layer in LAYERS: {sorted(packages - set(RANK))}"


def test_imports_point_down_only() -> None:
    wrong = sorted(f"{a} imports {b}" for a, targets in import_graph().items() for b in targets
                   if package_of(a) != package_of(b) and RANK[package_of(a)] <= RANK[package_of(b)])
    assert not wrong, "imports against the layers (docs/architecture.md):\n" + "\n".join(wrong)


def test_no_import_cycles() -> None:
    graph = import_graph()
    state: dict[str, int] = defaultdict(int)  # 0 new, 1 on the stack, 2 done
    cycles: list[str] = []

    def visit(module: str, stack: list[str]) -> None:
        state[module] = 1
        for target in sorted(graph[module]):
            if state[target] == 1:
                cycles.append(" -> ".join([*stack[stack.index(target):], target]))
            elif state[target] == 0:
                visit(target, [*stack, target])
        state[module] = 2

    for module in sorted(graph):
        if state[module] == 0:
            visit(module, [module])
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


HEAVY = ("pybullet", "numpy", "trimesh", "yourdfpy", "rich", "lxml", "xacro", "PIL", "yaml")


def test_importing_the_cli_loads_no_heavy_library() -> None:
    """Every command module is imported at start-up: each imports its heavy libraries inside the
    function that needs them (docs/architecture.md, "Start-up budget")."""
    import subprocess

    code = f"import sys, ar3cli.cli; print(sorted(m for m in {HEAVY!r} if m in sys.modules))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=PACKAGE.parent)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


def test_ruff_is_clean() -> None:
    """The rule sets in pyproject.toml's [tool.ruff]; each remaining noqa says why."""
    import shutil
    import subprocess

    import pytest

    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    if not Path(ruff).exists():
        pytest.skip("ruff is not installed (pip install '.[test]' installs it)")
    result = subprocess.run([ruff, "check", "--no-cache", str(PACKAGE.parent)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


def test_the_documented_diagram_is_the_code() -> None:
    text = DOC.read_text(encoding="utf-8")
    start, end = text.index("<!-- layers -->\n") + len("<!-- layers -->\n"), text.index("<!-- /layers -->")
    assert text[start:end] == mermaid(package_edges(import_graph())), \
        "docs/architecture.md is stale: python tests/test_architecture.py prints the diagram"


def _resolves(dotted: str) -> bool:
    """Whether ``a.b.C`` names a module of ar3cli (or of one of its packages) and an attribute in it."""
    import importlib

    parts = dotted.split(".")
    prefixes = ["ar3cli"] + [f"ar3cli.{p.relative_to(PACKAGE).as_posix().replace('/', '.')}"
                             for p in PACKAGE.rglob("*") if p.is_dir() and (p / "__init__.py").exists()]
    for prefix in prefixes:
        for split in range(len(parts), 0, -1):
            try:
                target = importlib.import_module(".".join([prefix, *parts[:split]]))
            except ImportError:
                continue
            for name in parts[split:]:
                target = getattr(target, name, None)
            if target is not None:
                return True
    return False


def test_every_name_and_path_the_architecture_doc_cites_exists() -> None:
    """The registration statements ("the decorator registers it in ``lint.rules.REGISTRY``", "one line in
    ``cli.COMMANDS``", "``FIXER = Fixer(...)`` in ``fix/NAME_plan.py``") stay true: every dotted name
    in backticks resolves to something in ar3cli and every cited file or folder exists."""
    text = DOC.read_text(encoding="utf-8")
    names = set(re.findall(r"`([a-z_]+(?:\.[A-Za-z_]+)+)`", text))
    files = {n for n in names if n.endswith((".py", ".yaml", ".md"))}
    missing = [n for n in sorted(names - files) if not _resolves(n)]
    cited = set(re.findall(r"`([a-z_]+(?:/[A-Za-z_]+)*/(?:[A-Za-z_]+\.py)?)`", text)) | {f for f in files if f.endswith(".py")}
    here = {p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob("*")} | \
        {p.relative_to(PACKAGE).as_posix() + "/" for p in PACKAGE.rglob("*") if p.is_dir()}
    for path in sorted(cited):
        if "NAME" not in path and not (PACKAGE.parent / path).exists() and \
                path.rstrip("/") not in {h.rstrip("/") for h in here} and \
                not any(h.endswith("/" + path.rstrip("/")) for h in here):
            missing.append(path)
    assert not missing, f"docs/architecture.md cites what the code no longer has: {missing}"


if __name__ == "__main__":
    sys.stdout.write(mermaid(package_edges(import_graph())))
