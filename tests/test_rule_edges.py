"""Every numeric threshold of every lint rule, tested on both sides (issue 39).

The edges live in :mod:`tests.rule_edges`, keyed by rule code. The first test walks the rule registry:
a rule whose ``thresholds`` text names a constant (``NAME = value``) needs an edge for each, one that
writes only bare numbers at least one, so a new threshold cannot ship without its edge cases. The
other lints each edge's two documents with that rule alone and checks the one just past the threshold
is reported and the one just inside it is not.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.lint.rules import REGISTRY, RULES
from tests.rule_edges import EDGES, NOT_COMPARED, Doc, Edge

NAMED = re.compile(r"\b([A-Z][A-Z0-9_]{2,})\s*=\s*[-+]?[\d.π]")
"""``NAME = value`` in a rule's ``thresholds`` text (``FULL_TURN = 2π``, ``SAME_SPEED = 2%`` too)."""
BARE = re.compile(r"(?<![A-Za-z0-9_.])\d")
"""A number that is no part of a name (``G013``, ``I_max``, ``x1e6`` are not)."""


def named_constants(text: str | None) -> set[str]:
    return set(NAMED.findall(text or ""))


def has_numbers(text: str | None) -> bool:
    return bool(BARE.search(text or ""))


def test_every_threshold_of_every_rule_has_its_edges():
    missing = []
    for rule in RULES:
        edges = EDGES.get(rule.code, ())
        covered = {edge.constant for edge in edges} | {name for code, name in NOT_COMPARED if code == rule.code}
        for name in sorted(named_constants(rule.thresholds) - covered):
            missing.append(f"{rule.code}: no edge for {name}: add Edge({name!r}, fires=<a robot just past it>, "
                           f"quiet=<one just inside it>) to EDGES[{rule.code!r}] in tests/rule_edges.py (or, when "
                           "nothing is compared with it, a reason in NOT_COMPARED)")
        if has_numbers(rule.thresholds) and not edges:
            missing.append(f"{rule.code}: its thresholds text has numbers but no edge: add EDGES[{rule.code!r}] in "
                           "tests/rule_edges.py, an Edge per threshold")
    assert not missing, "\n".join(missing)


def test_every_edge_belongs_to_a_rule_that_still_has_it():
    """An edge named after a constant the rule no longer has (renamed, removed) is stale."""
    stale = []
    for code, edges in EDGES.items():
        rule = REGISTRY.get(code)
        if rule is None:
            stale.append(f"{code}: no such rule")
            continue
        module = importlib.import_module(rule.check.__module__) if rule.check else None
        for edge in edges:
            known = edge.constant in (rule.thresholds or "") or hasattr(module, edge.constant)
            if re.fullmatch(r"[A-Z][A-Z0-9_]+", edge.constant) and not known:
                stale.append(f"{code}: {edge.constant} is neither in its thresholds text nor in {rule.check.__module__}")
    for code, name in NOT_COMPARED:
        if name not in named_constants(REGISTRY[code].thresholds):
            stale.append(f"{code}: NOT_COMPARED names {name}, which its thresholds text does not")
    assert not stale, "\n".join(stale)


def _cases() -> list:
    """One case per edge, named ``CODE-CONSTANT`` (``-2`` for a second edge of one constant, ``-pure`` when it
    tests a function): benchmarks/mutations.py names them."""
    cases = []
    for code, edges in EDGES.items():
        seen: dict[str, int] = {}
        for edge in edges:
            seen[edge.constant] = seen.get(edge.constant, 0) + 1
            name = f"{code}-{edge.constant}" + (f"-{seen[edge.constant]}" if seen[edge.constant] > 1 else "")
            cases.append(pytest.param(code, edge, id=name + ("-pure" if edge.pure else "")))
    return cases


def _write(folder: Path, document: str | Doc) -> Path:
    document = document if isinstance(document, Doc) else Doc(document)
    folder.mkdir()
    for name, content in document.files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, int):  # a sparse file: its size is the point, not its bytes
            with path.open("wb") as handle:
                handle.truncate(content)
        else:
            path.write_bytes(content)
    path = folder / document.name
    path.write_text(document.text, encoding="utf-8")
    return path


def _reports(code: str, edge: Edge, path: Path) -> list[str]:
    """The messages of ``code``'s findings on ``path`` (those holding ``edge.contains``), the rule run alone."""
    options = LintOptions(sim=REGISTRY[code].needs_sim, select=[code])
    found = lint_file(path, options.rules(), options)
    assert found.loaded and found.error is None, (found.error, [f.message for f in found.findings])
    return [f.message for f in found.findings if f.rule == code and edge.contains in f.message]


@pytest.mark.parametrize("code, edge", _cases())
def test_threshold_edge(code: str, edge: Edge, tmp_path: Path):
    if edge.pure:
        assert edge.fires(), f"{code} {edge.constant}: the case just past the threshold is not reported"
        assert not edge.quiet(), f"{code} {edge.constant}: the case just inside the threshold is reported"
        return
    fired = _reports(code, edge, _write(tmp_path / "fires", edge.fires))
    assert fired, f"{code} {edge.constant}: the document just past the threshold is not reported"
    quiet = _reports(code, edge, _write(tmp_path / "quiet", edge.quiet))
    assert not quiet, f"{code} {edge.constant}: the document just inside the threshold is reported: {quiet}"
