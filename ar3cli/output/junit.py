"""JUnit XML for lint findings: the test-report format GitLab, GitHub actions (test-reporter,
action-junit-report), Jenkins and Azure show as a list of passed and failed tests.

One ``<testsuite>`` per run, one ``<testcase>`` per linted file (``classname`` ``ar3cli.lint-urdf``,
``name`` and ``file`` the file's path). Each finding at or above ``--fail-on`` is a ``<failure>``
(``type`` its rule code, ``message`` ``path:line:col: CODE message``, the text adds the severity
and the fix); the findings below it go to the test case's ``<system-out>``, so a file with only
those passes. A file whose check was cut short (pybullet crashed under ``--sim``) gets an
``<error>``. Written with :mod:`xml.etree.ElementTree`, which escapes markup; characters XML 1.0
cannot hold at all (control bytes from a binary file's message) are written as ``\\xNN``.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from ar3cli.findings import Finding, Severity

SUITE = "ar3cli lint-urdf"
CLASSNAME = "ar3cli.lint-urdf"
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

    suite = ET.Element("testsuite", name=SUITE)
    tests = failures = errors = 0
    for path, findings, error in files:
        tests += 1
        case = ET.SubElement(suite, "testcase", classname=CLASSNAME, name=xml_text(path), file=xml_text(path),
                             time="0")
        failing = [f for f in findings if f.severity >= fail_on]
        passing = [f for f in findings if not f.severity >= fail_on]
        for finding in failing:
            failure = ET.SubElement(case, "failure", type=finding.rule,
                                    message=xml_text(f"{finding.location}: {finding.rule} {finding.message}"))
            failure.text = xml_text(_describe(finding))
        if error:
            element = ET.SubElement(case, "error", type="crash", message=xml_text(error))
            element.text = xml_text(error)
        if passing:
            ET.SubElement(case, "system-out").text = xml_text(
                f"below --fail-on {fail_on.value}:\n" + "\n".join(map(_describe, passing)))
        failures += bool(failing)
        errors += bool(error)
    counts = {"tests": str(tests), "failures": str(failures), "errors": str(errors), "skipped": "0", "time": "0"}
    suite.attrib.update(counts)
    root = ET.Element("testsuites", name=SUITE, **counts)
    root.append(suite)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
