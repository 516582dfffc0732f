"""``ar3cli install-check``: what this environment can run (the probes live in ``install_check/``)."""


from ar3cli.commands.options import FormatOption
from ar3cli.output.formats import finish
from ar3cli.output.report import Report, Table


def install_check(format: FormatOption = "text") -> None:
    """Check that Python, PyBullet and ar3cli's libraries are installed and behave.

    Each check prints ok / warn / fail / info, a detail, and for problems the exact command to run.
    Exit code 1 when any check fails.
    """
    from ar3cli.install_check.checks import run_checks

    checks = run_checks()
    ok = not any(check.status == "fail" for check in checks)
    table = Table(title="ar3cli install-check", columns=["check", "status", "detail", "hint"],
                  rows=[[c.name, c.status, c.detail, c.hint] for c in checks], status_column="status")
    failed = sum(c.status == "fail" for c in checks)
    warned = sum(c.status == "warn" for c in checks)
    verdict = "ready" if ok else "NOT ready"
    finish(Report(data={"ok": ok, "checks": [c.to_dict() for c in checks]}, tables=[table],
                  lines=[f"{verdict}: {len(checks)} checks, {failed} failed, {warned} warnings"], ok=ok), format)
