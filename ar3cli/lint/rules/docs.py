"""Generate docs/rules.md from the registry: ``python -m ar3cli.lint.rules.docs > docs/rules.md``."""

from __future__ import annotations

from ar3cli.lint.rules import FAMILIES, RULES
from ar3cli.lint.rules.base import ENGINE_NAMES

HEADER = """# ar3cli lint-urdf rules

Generated from the rule registry by `python -m ar3cli.lint.rules.docs > docs/rules.md`; a test fails
when this file and the registry differ. Every example below is linted by the test suite: the
failing example must trigger its rule and the passing one must not.

Codes are stable. Select or ignore them by code or prefix (`--select J`, `--ignore I002`), in
`pyproject.toml` under `[tool.ar3cli.lint]`, or inline with `<!-- ar3cli: ignore[CODE] -->` as a
child of the element (or of any ancestor). P rules run only with `--sim`, M rules with `--sim --engine
mujoco`. `--select ALL` (on the command line or in the configuration) runs every rule, the opt-in ones
included; without `--select`, opt-in rules run only when their code is named.
"""

POLICY = """## Severity policy

Every rule says which engines and tools its finding is about (*About* below: PyBullet, ROS (urdfdom and
what is built on it: check_urdf, robot_state_publisher, RViz, MoveIt, KDL), MuJoCo, Isaac Sim, Drake,
Gazebo, or every engine), and its severity follows one policy, which `tests/test_severity_policy.py`
checks for every rule:

- **error**: some engine or tool refuses the file, or measurably misbehaves on it (NaN states, a
  phantom kilogram, a joint whose stops are gone). The rule names which, and how (*Error because*).
  A file with an error does not do what it says somewhere it is meant to run.
- **warning**: the file loads, but a user will likely be hurt: a value in the wrong unit, a mesh
  that misses its part, a limit nobody can use.
- **info**: a fact worth knowing that hurts nobody by itself (an engine's idiom, a portability note).

**Severity follows `--target`.** A rule about some engines only (not every engine) is target-bound:
when `--target` (default: `pybullet,ros`) names none of its engines, its findings are infos. PyBullet's
1 kg default for a link without `<inertial>` (I002) is a warning for a PyBullet user and an info for
a robot meant for ROS only (`--target ros`); urdfdom's refusal of a `<robot>` without a name (S001)
is an error for ROS and an info for `--target pybullet`. Simulation rules (P, M) are about the
engine `--engine` chose and keep their severity; the T rules run only for their targets (or when
`--select` names their code) and keep theirs.

**One cause, one finding.** Where one mistake would trip several rules, one rule reports it and its
message lists the consequences: an unexpanded mesh path is F006's (not also G001's), a joint that
cannot move is J004's (not also J008's), a tensor that is not a body's is I004's or I005's (not also
I007's), an `<inertial>` missing both children is one S019 finding. An engine rule does not restate a
static one: P001 and M001 stay quiet when a static error already says why the engine refuses the file,
M002 about a mesh G001, F006, G004 or G011 reports. A frame welded to the root is the base's, listed in
its one I012 finding (not an I002 each). A xacro library or include body that does not expand alone is
one F008 line (its includer reports the failure), and a macro file's finding is reported once in a
folder lint, however many linted files include it.
"""


FAMILY_TITLES = {"pybullet": "PyBullet", "mujoco": "MuJoCo", "targets": "Target engines"}
"""Headings for the families whose name does not capitalise into their title."""


def generate() -> str:
    """The whole Markdown document."""
    out = [HEADER, POLICY, "## Rules", "", "| code | name | severity | about | title |",
           "| --- | --- | --- | --- | --- |"]
    for rule in RULES:
        about = ", ".join(ENGINE_NAMES[engine] for engine in rule.engines)
        out.append(f"| [{rule.code}](#{rule.anchor}) | {rule.name} | {rule.severity.value} | {about} | {rule.title} |")
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
            "", _about(rule), "",
            *([f"**Error because.** {rule.breaks}", ""] if rule.breaks else []),
            f"**Why it matters.** {rule.why}", "", f"**Fix.** {rule.fix}", "",
            *_optional(rule),
            "Failing example:", "", "```xml", rule.bad.rstrip("\n"), "```", "",
            "Passing example:", "", "```xml", rule.good.rstrip("\n"), "```",
        ]
    return "\n".join(out) + "\n"


def _about(rule) -> str:
    """"**About.** PyBullet, MuJoCo (target-bound: an info unless --target names one of them)."""
    names = ", ".join(ENGINE_NAMES[engine] for engine in rule.engines)
    bound = " Target-bound: an info when `--target` names none of these." if rule.target_bound else ""
    return f"**About.** {names}.{bound}"


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
