"""The rule registry: every lint rule, by stable code.

Codes are grouped by family prefix (F file, S structure, J joints, I inertia, G geometry,
P simulation in PyBullet, M MuJoCo, T target engines) and never reused. To add a rule: write one decorated function in its family module
(the decorator registers it; every module of this package is imported, so a new family module
needs no list either); docs/rules.md is generated from this registry
(``python -m ar3cli.lint.rules.docs > docs/rules.md``) and a test keeps the two equal.
"""

from __future__ import annotations

import importlib
import pkgutil

from ar3cli.lint.rules.base import FAMILIES, FAMILY_ORDER, Hit, Rule, registered

NOT_RULE_MODULES = frozenset({"base", "docs"})
"""Modules of this package that define no rules (the building blocks, the docs generator)."""
RULE_MODULES: tuple[str, ...] = tuple(sorted(
    info.name for info in pkgutil.iter_modules(__path__) if info.name not in NOT_RULE_MODULES))
"""Every module of this package that holds rules, found on disk: a new family module needs no list."""
for _module in RULE_MODULES:
    importlib.import_module(f"{__name__}.{_module}")

RULES: tuple[Rule, ...] = registered()
"""Every rule in family order (:data:`FAMILY_ORDER`), then by code: each one registered itself when its
module defined it (the :func:`~ar3cli.lint.rules.base.rule` decorator)."""
REGISTRY: dict[str, Rule] = {r.code: r for r in RULES}

__all__ = ["FAMILIES", "FAMILY_ORDER", "REGISTRY", "RULES", "Hit", "Rule", "matches", "validate_patterns"]


def matches(code: str, patterns) -> bool:
    """True when ``code`` is selected by any pattern: a full code, a prefix (``J``, ``J00``) or ``ALL``."""
    return any(pattern == "ALL" or code.startswith(pattern) for pattern in patterns)


OPT_IN_CODES: tuple[str, ...] = tuple(rule.code for rule in RULES if rule.opt_in)
"""The rules that run only when named (they read every collision mesh's triangles)."""


def validate_patterns(patterns, where: str) -> list[str]:
    """Upper-case the patterns and check each one selects at least one rule; ValueError otherwise.

    ``ALL`` written by the user means every rule: the opt-in ones are named after it (a default
    selection, which nobody wrote, leaves them out).
    """
    cleaned = []
    for raw in patterns:
        pattern = str(raw).strip().upper()
        if not pattern:
            continue
        if pattern != "ALL" and not any(code.startswith(pattern) for code in REGISTRY):
            raise ValueError(f"{where}: unknown rule code {raw!r} (codes look like F001, J006, or a prefix like J)")
        cleaned.append(pattern)
    if "ALL" in cleaned:
        cleaned += [code for code in OPT_IN_CODES if code not in cleaned]
    return cleaned
