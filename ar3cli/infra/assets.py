"""Find the bundled models (the AR3, the cube, the broken examples) wherever ar3cli runs from.

In a wheel the repository's ``assets/`` folder is installed as ``ar3cli/assets``; in a source
checkout (editable install, tests) it is the ``assets/`` folder beside the package.
"""

from __future__ import annotations

from pathlib import Path

from ar3cli.errors import UserError

_PACKAGE_DIR = Path(__file__).resolve().parents[1]
"""The ar3cli package folder (this module sits in its infra/ package)."""


def assets_dir() -> Path:
    """The folder holding ``ar3/``, ``objects/`` and ``examples/``."""
    for candidate in (_PACKAGE_DIR / "assets", _PACKAGE_DIR.parent / "assets"):
        if (candidate / "ar3").is_dir():
            return candidate
    raise UserError("the bundled assets are missing; reinstall ar3cli: pip install --force-reinstall ar3cli")


def asset(relative: str) -> Path:
    """Path of one bundled file, e.g. ``asset("ar3/ar3.urdf")``."""
    path = assets_dir() / relative
    if not path.exists():
        raise UserError(f"bundled asset {relative} is missing from {assets_dir()}")
    return path


def rules_doc() -> Path | None:
    """docs/rules.md, the rules' documentation: shipped in the wheel as ``ar3cli/docs/rules.md``, beside
    the package in a source checkout; None where neither exists (nothing made up then)."""
    for candidate in (_PACKAGE_DIR / "docs" / "rules.md", _PACKAGE_DIR.parent / "docs" / "rules.md"):
        if candidate.is_file():
            return candidate
    return None
