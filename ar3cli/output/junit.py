"""JUnit XML for lint findings: the test-report format GitLab, GitHub actions (test-reporter,
action-junit-report), Jenkins and Azure show as a list of passed and failed tests.

The common JUnit schema (Jenkins' and Ant's XSD, which the report tools follow) allows one
``<failure>`` per ``<testcase>``: a tool shows the first and drops the rest. So, as ruff does:

- one ``<testsuite>`` per linted file (``name`` and ``file`` the file's path);
- one ``<testcase>`` per rule with findings at or above ``--fail-on`` (per finding with
  ``--no-group``), errors first, holding exactly one ``<failure>`` (``classname`` the path, ``name``
  ``CODE path:line:col``, ``type`` the rule code, ``message`` ``path:line:col: CODE message`` with
  the count; the text lists every finding of the rule in that file with its severity and the fix);
- a file without such findings is one passing ``<testcase>`` (``name`` the path), its findings
  below ``--fail-on`` in that case's ``<system-out>`` (a failing file keeps them in the suite's);
- a file whose check was cut short (pybullet crashed under ``--sim``) gets a testcase with one
  ``<error>``.

Written with :mod:`xml.etree.ElementTree`, which escapes markup; every string from a robot file or
a file name goes through :func:`~ar3cli.output.escape.xml_text` first (control characters, which
XML 1.0 cannot hold at all, and newlines in names written as ``\\xNN``).
"""

from __future__ import annotations

from collections.abc import Iterable

from ar3cli.findings import Finding, Severity
from ar3cli.output.escape import xml_text
from ar3cli.output.lint_report import RuleGroup, rule_groups
from ar3cli.output.lists import capped

SUITE = "ar3cli lint-urdf"
LISTED = 100
"""Findings one test case's text lists at most (the rest counted)."""


def _describe(finding: Finding, hint: bool = True) -> str:
    text = xml_text(f"{finding.location}: {finding.severity.value} {finding.rule}: {finding.message}")
    return text + (f"\n  fix: {xml_text(finding.hint)}" if finding.hint and hint else "")


def _describe_group(group: RuleGroup) -> str:
    """Every finding of the group (at most :data:`LISTED`); their fix once when they share it."""
    shown, left = capped(group.findings, LISTED)
    shared = len({finding.hint for finding in group.findings}) == 1
    lines = [_describe(finding, hint=not shared) for finding in shown] + ([f"and {left:,} more"] if left else [])
    if shared and group.first.hint:
        lines.append(f"  fix: {xml_text(group.first.hint)}")
    return "\n".join(lines)


def junit_document(files: Iterable[tuple[str, list[Finding], str | None]], fail_on: Severity,
                   grouped: bool = True) -> str:
    """The XML document for ``files`` = (path, findings, error or None) in run order; ``grouped``
    False: a test case per failing finding."""
    import xml.etree.ElementTree as ET

    root = ET.Element("testsuites", name=SUITE)
    totals = {"tests": 0, "failures": 0, "errors": 0}
    for path, findings, error in files:
        name = xml_text(path)
        suite = ET.SubElement(root, "testsuite", name=name, file=name)
        failing = rule_groups([f for f in findings if f.severity >= fail_on], grouped)
        passing = rule_groups([f for f in findings if not f.severity >= fail_on], grouped)
        for group in failing:
            first = group.first
            more = f" ({group.count} findings)" if group.count > 1 else ""
            case = ET.SubElement(suite, "testcase", classname=name, name=xml_text(f"{first.rule} {first.location}"),
                                 file=name, line=str(first.line or 0), time="0")
            failure = ET.SubElement(case, "failure", type=xml_text(first.rule),
                                    message=xml_text(f"{first.location}: {first.rule} {first.message}{more}"))
            failure.text = _describe_group(group)
        if error:
            case = ET.SubElement(suite, "testcase", classname=name, name=xml_text(f"check {path}"), file=name, time="0")
            element = ET.SubElement(case, "error", type="crash", message=xml_text(error))
            element.text = xml_text(error)
        holder = suite
        if not failing and not error:
            holder = ET.SubElement(suite, "testcase", classname=name, name=name, file=name, time="0")
        if passing:
            ET.SubElement(holder, "system-out").text = f"below --fail-on {fail_on.value}:\n" + "\n".join(
                map(_describe_group, passing))
        counts = {"tests": len(suite.findall("testcase")), "failures": len(failing), "errors": int(bool(error))}
        suite.attrib.update({key: str(value) for key, value in counts.items()}, skipped="0", time="0")
        for key, value in counts.items():
            totals[key] += value
    root.attrib.update({key: str(value) for key, value in totals.items()}, skipped="0", time="0")
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
