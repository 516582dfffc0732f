"""The frame every HTML page of ar3cli shares: a self-contained document (inline CSS and JS, a strict
Content-Security-Policy that forbids any network request), the JSON data island, escaping, and
the findings section (lint-urdf's ``--format html`` and ``report`` show findings the same way).

Robot files are untrusted, so every string that came from one (names, messages, paths, source
lines) reaches the page through :func:`esc` (``html.escape`` with quotes, control characters and
bidi overrides shown as ``\\xNN``: :func:`ar3cli.output.escape.html_text`), and the data island is
JSON with ``<``, ``>`` and ``&`` written as ``\\u003c``..., so no name can close the script element.
Colours are the Okabe-Ito palette (safe for the common colour-vision deficiencies), and severity
is always written out as a word next to its colour.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from typing import Any

from ar3cli.output.escape import html_text

CSP = ("default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'unsafe-inline'; "
       "base-uri 'none'; form-action 'none'")
"""Nothing may be fetched: pictures are data URIs, style and script are inline."""

SEVERITIES = ("error", "warning", "info")
SEVERITY_MARK = {"error": "\u2716", "warning": "\u25b2", "info": "\u25cf"}
"""A shape per severity, so the colour is never the only cue (and a grey print still tells them apart)."""

CSS = """
:root{--error:#D55E00;--warning:#E69F00;--info:#0072B2;--ok:#009E73;--ink:#1b1b1b;--muted:#5a5a5a;--line:#d0d0d0;
--bg:#fff;--panel:#f6f6f4;font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:var(--ink)}
body{margin:0 auto;max-width:1200px;padding:1rem 1.5rem;background:var(--bg);line-height:1.4}
h1{font-size:1.6rem;margin:.2rem 0 .6rem}h2{font-size:1.25rem;border-bottom:2px solid var(--line);padding-bottom:.2rem;
margin-top:2rem}h3{font-size:1.05rem}
code,pre,.mono{font-family:ui-monospace,SFMono-Regular,Menlo,Consolas,monospace;font-size:.86rem}
nav a{margin-right:.8rem}a{color:#0b5fa5}
table{border-collapse:collapse;margin:.5rem 0}th,td{border:1px solid var(--line);padding:.2rem .5rem;text-align:left;
vertical-align:top}th{background:var(--panel)}td.num{text-align:right;font-variant-numeric:tabular-nums}
.badge{display:inline-block;padding:0 .45rem;border-radius:.6rem;font-weight:600;color:#fff;white-space:nowrap}
.badge.error{background:var(--error)}.badge.warning{background:var(--warning);color:#1b1b1b}
.badge.info{background:var(--info)}.badge.ok{background:var(--ok)}.badge.fail{background:var(--error)}
.badge.unchecked{background:#d9d9d9;color:var(--ink)}
.verdict{border:2px solid var(--line);border-left-width:10px;padding:.5rem .9rem;margin:.6rem 0 1rem;background:var(--panel)}
.verdict.fail{border-color:var(--error)}.verdict.warning{border-color:var(--warning)}.verdict.ok{border-color:var(--ok)}
.verdict .headline{font-size:1.2rem;font-weight:600;margin:.2rem 0 .5rem}
.verdict table.checks td{border:none;padding:.1rem .5rem .1rem 0}.verdict ul{margin:.3rem 0}
.verdict table.checks td:nth-child(-n+2){white-space:nowrap}
details.section{border-bottom:2px solid var(--line);margin-top:.4rem}
details.section>summary{cursor:pointer;padding:.35rem 0;list-style-position:outside}
details.section>summary h2{display:inline;border:none;margin:0 .5rem 0 0;padding:0}
details.section>summary .count{margin:0 .3rem}details.section>summary .line{color:var(--muted)}
details.section>.body{padding:.2rem 0 .8rem}
details.group{margin:.3rem 0}details.group>summary{cursor:pointer}
.legend{font-size:.9rem}.swatch{display:inline-block;width:1.1em;height:1.1em;line-height:1.1em;text-align:center;
font-size:.75em;font-weight:600;border:1px solid #555;vertical-align:middle}
.finding{border-left:6px solid var(--line);background:var(--panel);margin:.5rem 0;padding:.4rem .7rem}
.finding.error{border-color:var(--error)}.finding.warning{border-color:var(--warning)}
.finding.info{border-color:var(--info)}
.finding pre{background:#fff;border:1px solid var(--line);padding:.3rem;overflow-x:auto;margin:.3rem 0}
.finding pre mark{background:#fde9b8;color:inherit;display:block}
.fix code{background:#fff;border:1px solid var(--line);padding:0 .3rem}
.muted{color:var(--muted)}.cards{display:flex;flex-wrap:wrap;gap:.6rem}
.card{background:var(--panel);border:1px solid var(--line);padding:.4rem .8rem;min-width:8rem}
.card b{display:block;font-size:1.3rem}
figure{display:inline-block;margin:.3rem;text-align:center;vertical-align:top}
figure img{border:1px solid var(--line);max-width:100%;height:auto}
details.tree{margin-left:1.1rem}details.tree>summary{cursor:pointer}.tree .joint{color:var(--muted)}
.leaf{margin-left:2.2rem}
svg text{font-family:system-ui,sans-serif}
.heat rect:hover{stroke:#000;stroke-width:1.5}
button{font:inherit;margin-right:.4rem}
@media print{body{max-width:none;padding:0;font-size:10pt}nav,button,.noprint{display:none}
h2{break-after:avoid}.finding,figure,svg,table{break-inside:avoid}
*{-webkit-print-color-adjust:exact;print-color-adjust:exact}a{color:inherit;text-decoration:none}}
"""

SCRIPT = """
(function(){
  var data = JSON.parse(document.getElementById('data').textContent);
  document.documentElement.setAttribute('data-loaded', Object.keys(data).length);
  function all(open){document.querySelectorAll('details').forEach(function(d){d.open=open;});}
  document.querySelectorAll('button[data-details]').forEach(function(b){
    b.addEventListener('click', function(){all(b.getAttribute('data-details')==='open');});});
  function reveal(){
    var target = location.hash ? document.getElementById(location.hash.slice(1)) : null;
    if (target && target.tagName === 'DETAILS') { target.open = true; }
  }
  window.addEventListener('hashchange', reveal);
  document.querySelectorAll('a[href^="#"]').forEach(function(a){
    a.addEventListener('click', function(){
      var target = document.getElementById(a.getAttribute('href').slice(1));
      if (target && target.tagName === 'DETAILS') { target.open = true; }
    });});
  reveal();
  window.addEventListener('beforeprint', function(){all(true);});
})();
"""
"""The page's only script: parses the data island (a broken one is a console error the browser test
sees), expand/collapse buttons, a collapsed section opened when a link (the verdict's, the
navigation's) or the address leads to it, and every <details> opened for printing."""


esc = html_text
"""Text for HTML content or a quoted attribute; None is an empty string (control characters shown,
as in every output: :func:`ar3cli.output.escape.html_text`)."""


def number(value: Any, digits: int = 4) -> str:
    """A number for people (``digits`` significant digits), a dash for None."""
    if value is None:
        return "-"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return esc(value)
    if isinstance(value, int):
        return str(value)
    if value == 0 or 1e-3 <= abs(value) < 1e5:
        return f"{value:.{digits}g}"
    return f"{value:.{max(digits - 1, 1)}e}"


def data_island(data: Mapping[str, Any]) -> str:
    """The page's numbers as ``<script type="application/json" id="data">``: the same documents the
    commands print with ``--format json``, safe to embed (no ``</script>`` can appear in it)."""
    from ar3cli.output.report import _json_default

    text = json.dumps(data, default=_json_default, allow_nan=False, separators=(",", ":"))
    text = text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    return f'<script type="application/json" id="data">{text}</script>'


def page(title: str, body: Iterable[str], data: Mapping[str, Any]) -> str:
    """The whole document: head (CSP, CSS), ``body`` parts, the data island and the script."""
    return "".join([
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">",
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">',
        '<meta name="viewport" content="width=device-width,initial-scale=1">',
        f"<title>{esc(title)}</title><style>{CSS}</style></head><body>\n",
        *body,
        "\n", data_island(data), f"\n<script>{SCRIPT}</script>\n</body></html>\n",
    ])


def badge(severity: str) -> str:
    """A severity as a coloured word with its shape: colour is never the only cue."""
    mark = SEVERITY_MARK.get(severity, "")
    return f'<span class="badge {esc(severity)}">{mark} {esc(severity.upper())}</span>'


def severity_counts(summary: Mapping[str, Any]) -> str:
    """The lint summary's counts as cards, each number in a ``data-count`` attribute."""
    cards = [f'<div class="card">{badge(level)}<b data-count="{level}">{int(summary.get(level, 0))}</b></div>'
             for level in SEVERITIES]
    cards.append(f'<div class="card">findings<b data-count="findings">{int(summary.get("findings", 0))}</b></div>')
    return f'<div class="cards">{"".join(cards)}</div>'


def findings_section(findings: list[Mapping[str, Any]], context: Mapping[str, Any]) -> str:
    """Findings grouped by severity (worst first), each with its location, message, hint, the cited
    source lines (``context["sources"][path]``: ``{line: text}``) and the command that fixes it
    (``context["fixes"][index]``)."""
    if not findings:
        return '<p><span class="badge ok">\u2714 CLEAN</span> no findings.</p>'
    sources = context.get("sources", {})
    fixes = context.get("fixes", [])
    out = []
    for level in SEVERITIES:
        chosen = [(index, f) for index, f in enumerate(findings) if f.get("severity") == level]
        if not chosen:
            continue
        out.append(f"<h3>{badge(level)} {len(chosen)} {esc(level)}{'s' if len(chosen) != 1 and level != 'info' else ''}"
                   "</h3>")
        for index, finding in chosen:
            out.append(_finding(finding, sources.get(finding.get("path"), {}), fixes[index] if index < len(fixes) else ""))
    return "".join(out)


def _finding(finding: Mapping[str, Any], lines: Mapping[Any, str], fix: str) -> str:
    line = int(finding.get("line") or 0)
    where = f"{finding.get('path')}:{line}" if line else str(finding.get("path"))
    parts = [f'<div class="finding {esc(finding.get("severity"))}">',
             f'{badge(str(finding.get("severity")))} <code>{esc(finding.get("rule"))}</code> ',
             f'<span class="mono">{esc(where)}</span><br>{esc(finding.get("message"))}']
    if finding.get("hint"):
        parts.append(f'<div class="muted">hint: {esc(finding.get("hint"))}</div>')
    shown = sorted((int(number_), text) for number_, text in lines.items()
                   if line and abs(int(number_) - line) <= SOURCE_CONTEXT)
    if shown:
        rows = [(f"<mark>{esc(f'{n:>5} | {text}')}</mark>" if n == line else esc(f"{n:>5} | {text}") + "\n")
                for n, text in shown]
        parts.append(f"<pre>{''.join(rows)}</pre>")
    if fix:
        parts.append(f'<div class="fix">fix: <code>{esc(fix)}</code></div>')
    parts.append("</div>")
    return "".join(parts)


SOURCE_CONTEXT = 2
"""Lines shown before and after a finding's line."""
