"""``lint-urdf --explain CODE`` in the terminal: a rule's documentation as text."""

from __future__ import annotations

import textwrap

_SHOWN_FIRST = ("code", "name", "severity", "title", "why", "fix", "bad", "good", "needs_sim", "family", "anchor",
                "doc")
_PARAGRAPHS = {"why": "Why it matters", "fix": "Fix", "fixed_by": "Fixed by", "thresholds": "Thresholds",
               "references": "References"}


def explain_text(document: dict) -> str:
    """The terminal form of :func:`~ar3cli.lint.engine.rule_document`: the heading, then every
    paragraph the rule has (fields added to Rule later included), the examples, the link."""
    sim = "; runs only with --sim" if document.get("needs_sim") else ""
    out = [f"{document['code']} {document['name']} ({document['severity']}, {document['family']}{sim})", "",
           textwrap.fill(f"{document['title']}.", 100), ""]
    extra = [key for key in document if key not in _SHOWN_FIRST and key not in _PARAGRAPHS]
    for key in ("why", "fix", "fixed_by", "thresholds", "references", *extra):
        value = document.get(key)
        if value in (None, "", (), [], {}, False):
            continue
        label = _PARAGRAPHS.get(key) or key.replace("_", " ").capitalize()
        if key == "fixed_by":
            value = f"ar3cli {value}"
        text = value if isinstance(value, str) else ", ".join(map(str, value)) if isinstance(value, (list, tuple)) \
            else str(value)
        out += [f"{label}:", textwrap.fill(text, 100, initial_indent="  ", subsequent_indent="  "), ""]
    for key, label in (("bad", "Failing example"), ("good", "Passing example")):
        if document.get(key):
            out += [f"{label}:", textwrap.indent(document[key].rstrip("\n"), "  "), ""]
    out.append(f"Docs: {document['doc']} in ar3cli's source")
    return "\n".join(out) + "\n"
