"""JUnit XML for lint findings: the test-report format GitLab, GitHub actions (test-reporter,
action-junit-report), Jenkins and Azure show as a list of passed and failed tests.

The common JUnit schema (Jenkins' and Ant's XSD, which the report tools follow) allows one
``<failure>`` per ``<testcase>``: a tool shows the first and drops the rest. So, as ruff does:

- one ``<testsuite>`` per linted file (``name`` and ``file`` the file's path);
- one ``<testcase>`` per finding at or above ``--fail-on``, holding exactly one ``<failure>``
  (``classname`` the path, ``name`` ``CODE path:line:col``, ``type`` the rule code, ``message``
  ``path:line:col: CODE message``; the text adds the severity and the fix);
- a file without such findings is one passing ``<testcase>`` (``name`` the path), its findings
  below ``--fail-on`` in that case's ``<system-out>`` (a failing file keeps them in the suite's);
- a file whose check was cut short (pybullet crashed under ``--sim``) gets a testcase with one
  ``<error>``.

Written with :mod:`xml.etree.ElementTree`, which escapes markup; characters XML 1.0 cannot hold at
all (control bytes from a binary file's message) are written as ``\\xNN``.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from ar3cli.findings import Finding, Severity

SUITE = "ar3cli lint-urdf"
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def xml_text(text: str) -> str:
    """``text`` with the characters XML 1.0 forbids (even escaped) written as ``\\xNN``."""
    return _NOT_XML.sub(lambda match: f"\\x{ord(match.group()):02x}", text)


def _describe(finding: Finding) -> str:
    text = f"{finding.location}: {finding.severity.value} {finding.rule}: {finding.message}"
    return text + (f"\n  fix: {finding.hint}" if finding.hint else "")


def junit_document(files: Iterable[tuple[str, list[Finding], str | None]], fail_on: Severity) -> str:
    """The XML document for ``files`` = (path, findings, error or None) in run order."""
    import xml.etree.ElementTree as ET

    root = ET.Element("testsuites", name=SUITE)
    totals = {"tests": 0, "failures": 0, "errors": 0}
    for path, findings, error in files:
        name = xml_text(path)
        suite = ET.SubElement(root, "testsuite", name=name, file=name)
        failing = [f for f in findings if f.severity >= fail_on]
        passing = [f for f in findings if not f.severity >= fail_on]
        for finding in failing:
            case = ET.SubElement(suite, "testcase", classname=name, name=xml_text(f"{finding.rule} {finding.location}"),
                                 file=name, line=str(finding.line or 0), time="0")
            failure = ET.SubElement(case, "failure", type=finding.rule,
                                    message=xml_text(f"{finding.location}: {finding.rule} {finding.message}"))
            failure.text = xml_text(_describe(finding))
        if error:
            case = ET.SubElement(suite, "testcase", classname=name, name=xml_text(f"check {path}"), file=name, time="0")
            element = ET.SubElement(case, "error", type="crash", message=xml_text(error))
            element.text = xml_text(error)
        holder = suite
        if not failing and not error:
            holder = ET.SubElement(suite, "testcase", classname=name, name=name, file=name, time="0")
        if passing:
            ET.SubElement(holder, "system-out").text = xml_text(
                f"below --fail-on {fail_on.value}:\n" + "\n".join(map(_describe, passing)))
        counts = {"tests": len(suite.findall("testcase")), "failures": len(failing), "errors": int(bool(error))}
        suite.attrib.update({key: str(value) for key, value in counts.items()}, skipped="0", time="0")
        for key, value in counts.items():
            totals[key] += value
    root.attrib.update({key: str(value) for key, value in totals.items()}, skipped="0", time="0")
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
