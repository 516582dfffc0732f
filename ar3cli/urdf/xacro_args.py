"""``--xacro-arg NAME:=VALUE`` options as a mapping, without importing xacro's machinery (a lint of
plain ``.urdf`` files never needs :mod:`ar3cli.urdf.xacro_expand`)."""

from __future__ import annotations


def parse_xacro_args(items: list[str] | None) -> dict[str, str]:
    """Turn repeated ``NAME:=VALUE`` options into a mapping; raises ValueError when malformed."""
    mapping: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition(":=")
        if not sep or not name.strip():
            raise ValueError(f"--xacro-arg expects NAME:=VALUE, got {item!r}")
        mapping[name.strip()] = value
    return mapping
