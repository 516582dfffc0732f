"""Generate docs/rules.md from the registry: ``python -m ar3cli.lint.rules.docs > docs/rules.md``."""

from __future__ import annotations

from ar3cli.lint.rules import FAMILIES, RULES

HEADER = """# ar3cli lint-urdf rules

Generated from the rule registry by `python -m ar3cli.lint.rules.docs > docs/rules.md`; a test fails
when this file and the registry differ. Every example below is linted by the test suite: the
failing example must trigger its rule and the passing one must not.

Codes are stable. Select or ignore them by code or prefix (`--select J`, `--ignore I002`), in
`pyproject.toml` under `[tool.ar3cli.lint]`, or inline with `<!-- ar3cli: ignore[CODE] -->` as a
child of the element (or of any ancestor). P rules run only with `--sim`.
"""


FAMILY_TITLES = {"pybullet": "PyBullet", "mujoco": "MuJoCo", "targets": "Target engines"}
"""Headings for the families whose name does not capitalise into their title."""


def generate() -> str:
    """The whole Markdown document."""
    out = [HEADER, "| code | name | severity | title |", "| --- | --- | --- | --- |"]
    for rule in RULES:
        out.append(f"| [{rule.code}](#{rule.anchor}) | {rule.name} | {rule.severity.value} | {rule.title} |")
    family = None
    for rule in RULES:
        if rule.family != family:
            family = rule.family
            prefix = next(p for p, name in FAMILIES.items() if name == family)
            out += ["", f"## {FAMILY_TITLES.get(family, family.capitalize())} ({prefix})"]
        out += [
            "", f"### {rule.code} {rule.name}", "",
            f"**{rule.title}.** Severity: {rule.severity.value}." + (" Runs only with `--sim`." if rule.needs_sim else "")
            + (f" Opt-in: runs only when selected by its code (`--select {rule.code}`), as it reads every collision "
               "mesh's triangles." if rule.opt_in else ""),
            "", f"**Why it matters.** {rule.why}", "", f"**Fix.** {rule.fix}", "",
            *_optional(rule),
            "Failing example:", "", "```xml", rule.bad.rstrip("\n"), "```", "",
            "Passing example:", "", "```xml", rule.good.rstrip("\n"), "```",
        ]
    return "\n".join(out) + "\n"


def _optional(rule) -> list[str]:
    """The optional paragraphs: the fixing command, the thresholds, the references."""
    out = []
    if rule.fixed_by:
        out += [f"**Fixed by.** `ar3cli {rule.fixed_by}`.", ""]
    if rule.thresholds:
        out += [f"**Thresholds.** {rule.thresholds}", ""]
    if rule.references:
        out += [f"**References.** {rule.references}", ""]
    return out


if __name__ == "__main__":
    print(generate(), end="")
