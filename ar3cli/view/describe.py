"""The viewer panel's texts, as Markdown built from what the analysis layer answered (no viser here).

Every string that came from the robot file (names, messages, paths) goes through
:func:`ar3cli.view.text.literal`; everything else is ar3cli's own wording.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ar3cli.findings import Severity
from ar3cli.view.text import literal

if TYPE_CHECKING:
    from ar3cli.analysis.contacts import Contacts
    from ar3cli.analysis.link_findings import LinkFindings
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.findings import Finding

FINDINGS_SHOWN = 60
"""Findings the panel lists before it counts the rest (the terminal has them all: ar3cli lint-urdf)."""
PAIRS_SHOWN = 6
"""Pairs in contact named in the status before the rest are counted (a click on a link names all of its own)."""
SEVERITY_NAMES = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "info"}


@dataclass
class Status:
    """What the status block at the top of the panel says."""

    path: str
    links: int = 0
    joints: int = 0
    counts: Mapping[str, int] | None = None
    """Findings by severity (``error``, ``warning``, ``info``), None before the lint."""
    simulated: bool = False
    """Whether the counts include the PyBullet rules (False: they are still running)."""
    lint_error: str | None = None
    """Why the PyBullet rules did not run (a crash), None when they did or are running."""
    contacts: Contacts | None = None
    contact_error: str | None = None
    load_error: str | None = None
    """The last load failed with this: the robot on screen is the last good one."""


def status(state: Status) -> str:
    """The status block: the file, the robot's size, the findings, the contacts now, the banners."""
    lines = []
    if state.load_error is not None:
        good = "the last good load is shown" if state.links else "nothing to show yet"
        lines.append(f"**Does not load** ({good}): {literal(state.load_error)}")
    lines.append(f"**{literal(state.path)}**: {state.links} links, {state.joints} joints")
    if state.counts is not None:
        lines.append(f"Lint: {counted(state.counts)}" + ("" if state.simulated else " (simulated checks running)"))
    if state.lint_error is not None:
        lines.append(f"**Simulated checks not run:** {literal(state.lint_error)}")
    if state.contact_error is not None:
        lines.append(f"**Contacts not checked:** {literal(state.contact_error)}")
    elif state.contacts is not None:
        lines.append(f"In contact now: {contact_pairs(state.contacts)}")
    return "\n\n".join(lines)


def counted(counts: Mapping[str, int]) -> str:
    """``1 error, 2 warnings, 0 info``."""
    return ", ".join(f"{counts.get(name, 0)} {name}{'' if name == 'info' or counts.get(name, 0) == 1 else 's'}"
                     for name in ("error", "warning", "info"))


def contact_pairs(contacts: Contacts) -> str:
    """``none``, or the pairs in contact (``a`` – ``b``), the first :data:`PAIRS_SHOWN` named."""
    if contacts.note is not None:
        return f"none possible ({literal(contacts.note)})"
    unchecked = (f" (not checked, their collision mesh does not load: "
                 f"{', '.join(literal(link) for link in contacts.unchecked[:PAIRS_SHOWN])}"
                 f"{f' and {len(contacts.unchecked) - PAIRS_SHOWN} more' if len(contacts.unchecked) > PAIRS_SHOWN else ''})"
                 if contacts.unchecked else "")
    if not contacts.pairs:
        return "none" + unchecked
    named = [f"{literal(a)} \u2013 {literal(b)}" for a, b in contacts.pairs[:PAIRS_SHOWN]]
    more = len(contacts.pairs) - PAIRS_SHOWN
    return "; ".join(named) + (f"; and {more} more" if more > 0 else "") + unchecked


def findings_list(placed: LinkFindings | None, shown_path: str) -> str:
    """Every finding, worst first, each with the link it is about (a xacro's included file named)."""
    if placed is None:
        return "Linting\u2026"
    items: list[tuple[Finding, str | None]] = [(finding, link) for link, found in placed.by_link.items()
                                                for finding in found]
    items += [(finding, None) for finding in placed.unplaced]
    if not items:
        return "No findings."
    items.sort(key=lambda item: (-item[0].severity.rank, item[0].path != shown_path, item[0].line, item[0].rule))
    lines = [_finding_item(finding, link, shown_path) for finding, link in items[:FINDINGS_SHOWN]]
    if len(items) > FINDINGS_SHOWN:
        lines.append(f"- and {len(items) - FINDINGS_SHOWN} more: run `ar3cli lint-urdf` for the list")
    return "\n".join(lines)


def _finding_item(finding: Finding, link: str | None, shown_path: str) -> str:
    if finding.path == shown_path:
        where = f"line {finding.line}" if finding.line else "the file"
    else:
        where = f"{literal(finding.path)} line {finding.line}" if finding.line else literal(finding.path)
    about = f", link {literal(link)}" if link else ""
    return (f"- **{literal(finding.rule)}** {SEVERITY_NAMES.get(finding.severity, '')} ({where}{about}): "
            f"{literal(finding.message)}")


def link_card(analysis: RobotAnalysis, link: str, found: Sequence[Finding], touching: Iterable[str],
              shown_path: str) -> str:
    """What a click on ``link`` shows: its facts (mass, parent and child joints), its findings, what it touches now."""
    from ar3cli.analysis.facts import link_facts
    from ar3cli.errors import UserError

    try:
        facts = link_facts(analysis, link)
    except UserError:  # no summary for this robot (a joint type info cannot place): the rest is still shown
        facts = None
    blocks = [f"**{literal(link)}**"]
    if facts is not None:
        blocks.append("  \n".join(literal(line) for line in facts.lines()[1:]))
    touching = sorted(touching)
    if touching:
        blocks.append("In contact now with: " + ", ".join(literal(name) for name in touching))
    if found:
        blocks.append("\n".join(_finding_item(finding, None, shown_path) for finding in found[:FINDINGS_SHOWN]))
    else:
        blocks.append("No findings on this link.")
    return "\n\n".join(blocks)


def legend() -> str:
    """What the colours mean."""
    return ("Colours: **red** in contact at this pose (sample-collisions' check, adjacent links left out); a "
            "link whose worst finding is an error **magenta**, a warning **amber** (info findings are listed, not "
            "painted). Collision geometry is translucent teal, inertia boxes violet (red wireframe: no body has "
            "that inertia), centres of mass black spheres of lead of the link's mass.")


def notes(items: Iterable[str]) -> str:
    """What is drawn differently from the file, or not at all."""
    listed = [f"- {literal(item)}" for item in items]
    return "\n".join(listed) if listed else "Everything in the file is drawn."
