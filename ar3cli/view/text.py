"""Text from robot files made safe for the viewer's panel, which viser renders as Markdown.

viser's Markdown renderer passes raw HTML through unsanitised ("markdown must come from a trusted
server"), and Markdown itself turns ``[text](url)`` into links and ``![](url)`` into images the
browser fetches. A link or joint name, a finding's message or a path is the author's text: every
ASCII punctuation character is backslash-escaped (CommonMark shows an escaped character as itself),
control characters are shown as ``\\xNN`` (:func:`ar3cli.output.report.printable`), line breaks become
spaces and the text is cut at a length, so nothing a file contains can become markup, a link, an
image or a second line.
"""

from __future__ import annotations

import re

from ar3cli.output.report import printable

LONGEST = 400
"""Characters of one text shown (a 10,000-character link name must not fill the panel)."""
_PUNCTUATION = re.compile(r"([!-/:-@\[-`{-~])")


def literal(text: object, longest: int = LONGEST) -> str:
    """``text`` as Markdown that shows exactly it (shortened to ``longest`` characters with an ellipsis)."""
    shown = " ".join(printable(str(text)).split())
    if len(shown) > longest:
        shown = shown[:longest] + "\u2026"
    return _PUNCTUATION.sub(r"\\\1", shown)


def label(text: object, longest: int = 40) -> str:
    """``text`` for a control's label (plain text, not Markdown): one line, control characters shown, shortened."""
    shown = " ".join(printable(str(text)).split())
    return shown if len(shown) <= longest else shown[:longest - 1] + "\u2026"
