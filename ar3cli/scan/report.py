"""What a scan store holds, summed up: counts by status and by rule, the worst files, the kept files.

:func:`summarize` is the JSON document of ``ar3cli scan-report``; :func:`tables` its text form,
and :func:`markdown` the same tables as GitHub Markdown (a CI job summary, an issue comment).
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from ar3cli.output.report import Table
from ar3cli.scan.keep import Keep, kept
from ar3cli.scan.record import STATUSES, Row, severity_rank


def summarize(rows: list[Row], filters: list[Keep], top: int) -> dict[str, Any]:
    """Counts by status, by rule (findings and files), the ``top`` worst files and the kept paths."""
    statuses = Counter(row.status for row in rows)
    findings: Counter[str] = Counter()
    files: Counter[str] = Counter()
    severity: dict[str, str] = {}
    for row in rows:
        codes = [f["rule"] for f in row.findings]
        findings.update(codes)
        files.update(set(codes))
        for f in row.findings:
            severity.setdefault(f["rule"], f["severity"])
    worst = sorted((row for row in rows if row.status != "clean" or row.findings), key=severity_rank, reverse=True)[:top]
    keep = kept(rows, filters)
    return {
        "files": len(rows),
        "statuses": {status: statuses[status] for status in STATUSES},
        "rules": [{"rule": code, "severity": severity[code], "findings": count, "files": files[code]}
                  for code, count in sorted(findings.items(), key=lambda item: (-item[1], item[0]))],
        "worst": [_worst(row) for row in worst],
        "keep": {"filters": [k.text for k in filters], "files": len(keep), "paths": [row.path for row in keep]},
    }


def _worst(row: Row) -> dict[str, Any]:
    counts = row.counts()
    rules = Counter(f["rule"] for f in row.findings)
    return {"path": row.path, "status": row.status, **counts,
            "top_rules": [code for code, _ in rules.most_common(3)], "message": row.message}


def tables(data: dict[str, Any]) -> list[Table]:
    """The report's text tables: statuses, rules, worst files."""
    status = Table("files by status", ["status", "files"], [[s, n] for s, n in data["statuses"].items()],
                   numeric_columns=("files",))
    rules = Table("findings by rule", ["rule", "severity", "findings", "files"],
                  [[r["rule"], r["severity"], r["findings"], r["files"]] for r in data["rules"]],
                  status_column="severity", numeric_columns=("findings", "files"))
    worst = Table("worst files", ["path", "status", "errors", "warnings", "info", "top rules / why"],
                  [[w["path"], w["status"], w["error"], w["warning"], w["info"],
                    w["message"] or ", ".join(w["top_rules"])] for w in data["worst"]],
                  numeric_columns=("errors", "warnings", "info"))
    return [table for table in (status, rules, worst) if table.rows]


def keep_line(data: dict[str, Any]) -> str:
    keep = data["keep"]
    filters = " and ".join(keep["filters"]) or "no filter"
    return f"{data['files']} files in the store; {keep['files']} kept by {filters}"


def markdown(data: dict[str, Any]) -> str:
    """The tables as GitHub Markdown, then the keep line (every cell escaped by the output layer)."""
    from ar3cli.output.escape import markdown_text
    from ar3cli.output.markdown_table import table_markdown

    out = [line for table in tables(data) for line in table_markdown(table, code_columns=("path",))]
    return "\n".join([*out, markdown_text(keep_line(data))]) + "\n"
