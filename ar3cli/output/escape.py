"""The output boundary: one escaping function per kind of output, for every string that came from a
robot file, a file name or the environment (names, paths, messages that quote them).

A robot file is the attacker's text (ar3cli gates strangers' pull requests), and so is a file name.
Written raw, a newline in a link name (``&#10;``) starts a line of its own, which GitHub's runner
reads as a workflow command (``::stop-commands::x`` silences every later annotation); an escape
sequence repaints the terminal; a bidi override reorders what a reviewer reads; ``![x](url)`` is an
image in a pull-request comment; a byte that is not UTF-8 (a file named with byte 0xFF) cannot be
encoded at all. Each function below makes a string inert for one kind of output:

============================  ==============================================================
:func:`terminal`              text on stdout/stderr: tables, lines, logs, error lines
:func:`terminal_lines`        a file quoted line by line (a fixer's ``--diff``)
:func:`github_data`           a workflow command's message (``::error ...::MESSAGE``)
:func:`github_property`       a workflow command's property (``file=``, ``title=``)
:func:`markdown_text`         Markdown prose and table cells (``--format markdown``, the step summary)
:func:`markdown_code`         a Markdown code span (a path), safe in a table cell
:func:`html_text`             HTML content and quoted attributes
:func:`xml_text`              XML text and attributes (JUnit), before ElementTree escapes markup
============================  ==============================================================

Every kind starts from :func:`terminal`: control characters (C0 but tab, so newline and carriage
return too; DEL; C1 such as CSI 0x9b), the bidirectional marks, embeddings, overrides and
isolates ("Trojan Source"), the Unicode line and paragraph separators and lone surrogates (the
bytes of a file name that are not UTF-8, kept by Python as U+DC80-U+DCFF) are written as ``\\xNN``
(``\\uNNNN`` above 0xff); a non-UTF-8 byte is shown as the byte it was (``\\xff``). JSON and SARIF
keep the exact strings: JSON's own escaping (``ensure_ascii``) is their boundary.
"""

from __future__ import annotations

import html
import re

_CONTROL = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028-\u202e\u2066-\u2069\ud800-\udfff]")
"""What a terminal, a log viewer or a line-based reader obeys (or cannot encode) instead of showing:
C0 controls but tab (newline starts a forged line, ESC an escape sequence, CR rewrites the line),
DEL, C1 controls (CSI 0x9b, NEL 0x85), the bidi marks, embeddings, overrides and isolates, the
line and paragraph separators U+2028/U+2029, and lone surrogates (undecodable file-name bytes)."""

_SURROGATE_BYTES = range(0xDC80, 0xDD00)
"""Where Python's ``surrogateescape`` keeps the bytes 0x80-0xff of a name that is not UTF-8."""


def _shown(match: re.Match) -> str:
    code = ord(match.group())
    if code in _SURROGATE_BYTES:
        return f"\\x{code - 0xDC00:02x}"
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def terminal(text: str) -> str:
    """``text`` on one line, with every character a terminal or log would obey (see :data:`_CONTROL`)
    written as ``\\xNN`` / ``\\uNNNN``: the function every text output uses for names, paths and
    messages (as :func:`ar3cli.output.report.printable`)."""
    if text.isprintable():  # the usual case, one C-level scan; every character of _CONTROL is non-printable
        return text
    return _CONTROL.sub(_shown, text)


def terminal_lines(text: str) -> str:
    """Text that quotes a file line by line (a fixer's unified diff): each line through
    :func:`terminal`, its line ending (``\\n``, ``\\r\\n``) kept, so the diff still applies to
    every file without control characters."""
    if text.isprintable():
        return text
    lines = text.split("\n")
    return "\n".join(terminal(line[:-1]) + "\r" if line.endswith("\r") else terminal(line) for line in lines)


def github_data(text: str) -> str:
    """A workflow command's message: :func:`terminal`, then ``%``, CR and LF percent-encoded (the
    runner's own escaping, which it decodes for display)."""
    return terminal(text).replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def github_property(text: str) -> str:
    """A workflow command's property value (``file=``, ``title=``): :func:`github_data` plus ``:``
    and ``,``, which end a property."""
    return github_data(text).replace(":", "%3A").replace(",", "%2C")


_MARKDOWN_PUNCTUATION = re.compile(r"[\\`*_\[\]!|~$]|(?<=[Ww][Ww][Ww])\.|:(?=//)")
"""What starts or closes inline Markdown: code spans, emphasis, links and images (``[``, ``]``,
``!``), table cells, strikethrough, math (``$``), and the two GitHub "extended autolinks" (``www.``
and ``scheme://``): each is backslash-escaped, which CommonMark allows for any ASCII punctuation."""


def markdown_text(text: str) -> str:
    """Text for Markdown prose or a table cell that renders as exactly these characters: no image,
    link, autolink, code span, emphasis, HTML tag, math or cell break, and no ``@mention``.

    :func:`terminal` first (one line, no controls); then ``&``, ``<`` and ``>`` as HTML entities (no
    tag, no ``<url>`` autolink), inline punctuation backslash-escaped (:data:`_MARKDOWN_PUNCTUATION`),
    and a word joiner (U+2060, invisible) after each ``@``: GitHub finds mentions in the rendered
    text, where a backslash no longer is.
    """
    text = terminal(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return _MARKDOWN_PUNCTUATION.sub(r"\\\g<0>", text).replace("@", "@\u2060")


def markdown_code(text: str) -> str:
    """``text`` as one Markdown code span (a path, ``path:line:col``), also inside a table cell.

    Inside a code span nothing is Markdown, so only the span's own end matters: the fence is one
    backtick longer than the longest run of backticks in the text (padded with a space when the
    text starts or ends with one), and ``|`` is escaped (GitHub splits table cells first).
    """
    text = terminal(text).replace("|", "\\|")
    longest = max((len(run) for run in re.findall("`+", text)), default=0)
    fence = "`" * (longest + 1)
    pad = " " if text[:1] in ("`", " ") or text[-1:] in ("`", " ") else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def html_text(value: object) -> str:
    """Text for HTML content or a quoted attribute: :func:`terminal`, then ``html.escape`` with
    quotes (a bidi override would reorder the page as it reorders a terminal)."""
    return "" if value is None else html.escape(terminal(str(value)), quote=True)


_NOT_XML = re.compile("[\ufffe\uffff]")
"""What XML 1.0 forbids that :func:`terminal` leaves (it takes every control and surrogate)."""


def xml_text(text: str) -> str:
    """Text for an XML element or attribute (JUnit): :func:`terminal` (which also removes every
    character XML 1.0 forbids but U+FFFE/U+FFFF, written as ``\\uNNNN``); ElementTree then escapes
    the markup."""
    return _NOT_XML.sub(_shown, terminal(text))
