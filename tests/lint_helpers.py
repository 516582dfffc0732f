"""Small helpers the rule tests share: lint a file with the default rules, and build the little
robots the cases are made of (imported by tests/test_rules_*.py)."""

from __future__ import annotations

from pathlib import Path

from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.lint.rules.base import LINK_INERTIAL, robot


def findings(path: Path) -> list:
    options = LintOptions()
    return lint_file(path, options.rules(), options).findings


def rules_of(path: Path) -> set[str]:
    return {f.rule for f in findings(path)}


def tensor(ixx, iyy, izz, mass=1.0) -> str:
    return (f'<inertial><mass value="{mass}"/><inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" '
            f'izz="{izz}"/></inertial>')


def fixed_child(link_extra: str, name: str = "flange") -> str:
    return robot(f"""
        <link name="base">{LINK_INERTIAL}</link><link name="{name}">{link_extra}</link>
        <joint name="{name}_joint" type="fixed"><parent link="base"/><child link="{name}"/></joint>""")


def welded_to_arm(link_extra: str, name: str = "flange") -> str:
    """A link welded to a moving arm (not to the root, whose welded frames are I012's)."""
    return robot(f"""
        <link name="base">{LINK_INERTIAL}</link><link name="arm">{LINK_INERTIAL}</link><link name="{name}">{link_extra}</link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
          <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
        <joint name="{name}_joint" type="fixed"><parent link="arm"/><child link="{name}"/></joint>""")


def mesh_link(filename: str, role: str = "collision", extra: str = "") -> str:
    return robot(f'<link name="part">{LINK_INERTIAL}<{role}{extra}><geometry><mesh filename="{filename}"/>'
                 f'</geometry></{role}></link>')
