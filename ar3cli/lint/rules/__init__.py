"""The rule registry: every lint rule, by stable code.

Codes are grouped by family prefix (F file, S structure, J joints, I inertia, G geometry,
P simulation in PyBullet, M MuJoCo, T target engines) and never reused. To add a rule: write one decorated function in its family module
and add it to that module's ``RULES`` tuple; docs/rules.md is generated from this registry
(``python -m ar3cli.lint.rules.docs > docs/rules.md``) and a test keeps the two equal.
"""

from __future__ import annotations

from ar3cli.lint.rules import (
    consistency,
    file,
    geometry,
    inertia,
    joints,
    mujoco,
    plausibility,
    schema,
    sim,
    structure,
    targets,
)
from ar3cli.lint.rules.base import FAMILIES, Hit, Rule

FAMILY_ORDER = "FSJIGPMT"
"""Families in registry (and docs) order."""

RULES: tuple[Rule, ...] = tuple(sorted(
    (*file.RULES, *structure.RULES, *joints.RULES, *inertia.RULES, *inertia.NOT_FIXED_RULES, *geometry.RULES,
     *sim.RULES, *mujoco.RULES, *schema.RULES, *consistency.RULES, *plausibility.RULES, *targets.RULES),
    key=lambda r: (FAMILY_ORDER.index(r.code[0]), r.code)))
"""Every rule in family order, then by code (a family module may list its rules in another order:
``inertia.RULES`` is fix-inertia's order of reasons)."""
REGISTRY: dict[str, Rule] = {r.code: r for r in RULES}
assert len(REGISTRY) == len(RULES), "duplicate rule code"

__all__ = ["FAMILIES", "REGISTRY", "RULES", "Hit", "Rule", "matches", "validate_patterns"]


def matches(code: str, patterns) -> bool:
    """True when ``code`` is selected by any pattern: a full code, a prefix (``J``, ``J00``) or ``ALL``."""
    return any(pattern == "ALL" or code.startswith(pattern) for pattern in patterns)


def validate_patterns(patterns, where: str) -> list[str]:
    """Upper-case the patterns and check each one selects at least one rule; ValueError otherwise."""
    cleaned = []
    for raw in patterns:
        pattern = str(raw).strip().upper()
        if not pattern:
            continue
        if pattern != "ALL" and not any(code.startswith(pattern) for code in REGISTRY):
            raise ValueError(f"{where}: unknown rule code {raw!r} (codes look like F001, J006, or a prefix like J)")
        cleaned.append(pattern)
    return cleaned
