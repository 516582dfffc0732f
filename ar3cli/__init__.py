"""ar3cli: diagnose, fix and sim-check robot description files (URDF and xacro) with PyBullet."""

__version__ = "0.1.0"

RULES_DOC = "docs/rules.md"
"""Where every lint rule is documented: this path in ar3cli's source tree (generated from the rule
registry). ar3cli has no hosted address, so no URL is made up: SARIF carries the rule's text and this
path, ``lint-urdf --explain CODE`` prints the same documentation offline."""
