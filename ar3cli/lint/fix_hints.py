"""Which ar3cli command fixes a file's findings: the exact command lines ``lint-urdf --fix-hint`` prints.

Each rule names its fixer in ``fixed_by`` (``docs/rules.md``); this module turns a file's findings
into one command per fixer, with the options that fixer needs for them (fix-inertia needs a mass
source for links that have none, but not for frame links, which get a tiny inertial; ``NAME=DIR``
and ``joint_limits.yaml`` are placeholders the user fills in).
"""

from __future__ import annotations

import shlex
from collections.abc import Iterable

from ar3cli.findings import Finding
from ar3cli.lint.rules import REGISTRY
from ar3cli.lint.rules.inertia import FRAME_LINK_PHRASE, fixed_link_inertial_missing

NEEDS_MASS = frozenset({"I001", "I002", "I003"})
"""Findings on links without a valid mass: fix-inertia needs --density (or --mass, --total-mass), except
for frame links (I002 on a link without geometry: fix-inertia writes a tiny inertial, no mass needed)."""


def needs_mass(finding: Finding) -> bool:
    """True when fix-inertia needs a mass source (``--density``) to fix ``finding``."""
    if finding.rule not in NEEDS_MASS:
        return False
    return not (finding.rule == fixed_link_inertial_missing.code and FRAME_LINK_PHRASE in finding.message)


def fixed_by(code: str) -> str | None:
    """The command (with options) that fixes findings of rule ``code``, or None."""
    rule = REGISTRY.get(code)
    return rule.fixed_by if rule is not None else None


def fix_commands(path: str, findings: Iterable[Finding]) -> list[str]:
    """``ar3cli COMMAND [OPTIONS] PATH`` lines that fix ``findings`` of the file at ``path``, one per
    fixer, options merged, in a stable order; each followed by the codes it addresses."""
    by_command: dict[str, tuple[list[str], set[str]]] = {}
    for finding in findings:
        spec = fixed_by(finding.rule)
        if not spec:
            continue
        command, *options = spec.split()
        known, codes = by_command.setdefault(command, ([], set()))
        if needs_mass(finding):
            options = [*options, "--density", "KG_PER_M3"]
        for index in range(0, len(options)):
            option = options[index]
            if option.startswith("--") and option not in known:
                value = options[index + 1] if index + 1 < len(options) and not options[index + 1].startswith("--") else None
                known += [option, *([value] if value else [])]
        codes.add(finding.rule)
    return [f"ar3cli {command} {shlex.quote(path)}{''.join(' ' + o for o in options)}  # {', '.join(sorted(codes))}"
            for command, (options, codes) in sorted(by_command.items())]
