"""The rule registry collects itself: a rule cannot be defined and then forgotten (issue 23, step 2)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from ar3cli.lint import rules as rules_package
from ar3cli.lint.rules import FAMILY_ORDER, REGISTRY, RULE_MODULES, RULES, base
from ar3cli.lint.rules.base import FAMILIES, Rule, arm, rule


def test_every_module_of_the_package_is_collected():
    on_disk = {p.stem for p in Path(rules_package.__file__).parent.glob("*.py")} - {"__init__", "base", "docs"}
    assert set(RULE_MODULES) == on_disk


def test_every_rule_defined_in_a_module_is_in_the_registry():
    for name in RULE_MODULES:
        module = importlib.import_module(f"ar3cli.lint.rules.{name}")
        for value in vars(module).values():
            if isinstance(value, Rule):
                assert REGISTRY[value.code] is value, f"{name}: {value.code}"


def test_one_family_order_everywhere():
    assert "".join(FAMILIES) == FAMILY_ORDER
    assert [r.code for r in RULES] == sorted(REGISTRY, key=lambda c: (FAMILY_ORDER.index(c[0]), c))


def _docs() -> dict[str, str]:
    return {"why": "w", "fix": "f", "bad": arm(), "good": arm()}


def test_a_new_rule_registers_itself_and_a_reused_code_is_refused():
    try:
        @rule("S999", "test-only-rule", "warning", "a rule made by a test", **_docs())
        def made(ctx):
            yield from ()

        assert made in base.registered()
        with pytest.raises(ValueError, match="duplicate rule code S999"):
            rule("S999", "another-name", "warning", "t", **_docs())(None)
        with pytest.raises(ValueError, match="family prefix"):
            rule("X001", "bad-prefix", "warning", "t", **_docs())(None)
    finally:
        base._REGISTERED.pop("S999", None)
    assert "S999" not in REGISTRY
