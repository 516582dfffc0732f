"""The self-collision matrix as a :class:`~ar3cli.output.report.Report`: JSON document, table, heat
map and summary lines."""

from __future__ import annotations

from ar3cli.collisions import matrix as cm
from ar3cli.collisions.run import MatrixRun
from ar3cli.collisions.srdf_files import STATUSES, Comparison, Merged
from ar3cli.output.report import OutputFormat, Report, Table
from ar3cli.urdf.model import Model


def matrix_report(model: Model, run: MatrixRun, fmt: OutputFormat | str,
                  comparison: Comparison | None = None, merged: Merged | None = None) -> Report:
    """Always ok: the warnings describe the robot, they do not fail the run. With ``comparison``
    (--srdf-compare) every pair carries what the existing SRDF says about it and a second table lists
    the disagreements; with ``merged`` (--srdf-merge) a line says what the merge changed."""
    from ar3cli.sim.session import PENETRATION_TOLERANCE

    counts = cm.category_counts(run.results)
    never_bound = cm.zero_success_upper_bound(run.samples)
    data = {
        "path": str(model.path), "robot": model.name, "samples": run.samples, "seed": run.seed, "jobs": run.jobs,
        "always_threshold": run.always_threshold, "contact_tolerance_m": PENETRATION_TOLERANCE,
        "links": list(run.links), "unchecked_links": list(run.unchecked), "limit_configurations": run.limit_configurations,
        "pairs": [result.to_dict() for result in run.results],
        "categories": counts, "never_upper_bound": never_bound,
        "warnings": [finding.to_dict() for finding in run.warnings],
        "configs_per_second": run.configs_per_second, "elapsed_s": run.elapsed_s,
    }
    if comparison is not None:
        for pair in data["pairs"]:
            pair["srdf"] = comparison.marks.get(frozenset((pair["link_a"], pair["link_b"])))
        data["srdf_compare"] = comparison.to_dict()
    if merged is not None:
        data["srdf_merge"] = merged.to_dict()
    if OutputFormat(fmt) is OutputFormat.json:
        return Report(data=data)
    title = f"self-collision pairs of {model.path.name} ({run.samples} samples, seed {run.seed})"
    columns = ["link a", "link b", "category", "collisions", "samples", "fraction", "95% interval", "at home",
               "limit hits"]
    rows = [_row(result) for result in _ordered(run.results)]
    caption = ("a link and its direct parent are adjacent and not sampled (-); a pair is counted only until its "
               "category is decided (samples: how many it was checked in; 0 for a pair touching at home), its "
               "fraction and interval are then estimates over those samples")
    if comparison is not None:
        columns.append("srdf")
        rows = [[*row, comparison.marks.get(frozenset(row[:2]), "")] for row in rows]
        caption += f"; srdf: why {comparison.path.name} disables the pair (empty: MoveIt checks it)"
    table = Table(title=title, columns=columns, rows=rows, caption=caption,
                  numeric_columns=("collisions", "samples", "fraction", "limit hits"))
    summary = ", ".join(f"{counts[c]} {c}" for c in cm.CATEGORIES)
    rate = run.configs_per_second
    lines = [
        f"seed {run.seed}: {run.samples} uniform samples + {run.limit_configurations} home/limit configurations, "
        f"{len(run.pairs)} pairs of {len(run.links)} links with collision geometry, {run.dof} joints",
        f"{summary}; {_count(sum(counts[c] for c in cm.DISABLED), 'pair')} to disable",
        _retired_line(run.results, run.samples),
        f"'never' means: collision probability below {never_bound:.2g} with 95% confidence (exact bound, "
        f"~3/N); more samples tighten it",
        f"{rate:,.0f} configurations/s with {_count(run.jobs, 'job')}" if rate else "",
    ]
    lines += [f"{w.severity.value}: {w.message}" + (f" ({w.hint})" if w.hint else "") for w in run.warnings]
    tables = [table]
    if comparison is not None:
        if comparison.rows:
            tables.append(compare_table(comparison, run.samples))
        lines.append(compare_summary(comparison))
    if merged is not None:
        lines.append(f"merged into {merged.target}: {_count(merged.removed, 'generated pair')} of {merged.source.name} "
                     f"replaced by {merged.written}; {merged.kept} hand-written collision entries kept")
    drawn = len(run.links) <= HEAT_MAP_LINKS
    if not drawn:
        lines.append(f"heat map left out: {len(run.links)} links (at most {HEAT_MAP_LINKS} fit a line; --png draws it)")
    return Report(data=data, tables=tables, renderables=[cm.heat_map(run.links, run.pairs, run.results)] if drawn else [],
                  lines=[line for line in lines if line])


HEAT_MAP_LINKS = 120
"""Links the text heat map draws at most: it takes two columns per link and a line per link, so a
robot of 5,000 links would print 50 MB of it."""


COMPARE_MEANING = {
    "dangerous": "disabled, but collides: MoveIt would plan through this contact",
    "missing": "enabled, but MoveIt disables it (adjacent, touching at home or almost always)",
    "wasted": "enabled, never collided: a check that never fires",
    "unknown": "names a link the URDF does not have",
}


def compare_table(comparison: Comparison, samples: int) -> Table:
    """The disagreements between the existing SRDF and the sampled matrix, worst first."""
    rows = []
    for row in comparison.rows:
        found = row.result
        if found is None:
            rows.append([row.status, row.link_a, row.link_b, row.srdf, "", "", "", "", row.line or ""])
            continue
        collisions = found.collisions if found.sampled and found.samples else "-"
        fraction = f"{found.fraction:.4f}" if found.sampled and found.samples else "-"
        rows.append([row.status, row.link_a, row.link_b, row.srdf, found.category, collisions, fraction,
                     len(found.limit_hits) or "", row.line or ""])
    caption = "; ".join(f"{status}: {meaning}" for status, meaning in COMPARE_MEANING.items())
    return Table(title=f"{comparison.path.name} against the sampled matrix ({samples} samples)",
                 columns=["status", "link a", "link b", "srdf", "category", "collisions", "fraction", "limit hits",
                          "srdf line"],
                 rows=rows, caption=caption, status_column="status",
                 numeric_columns=("collisions", "fraction", "limit hits", "srdf line"))


def compare_summary(comparison: Comparison) -> str:
    counts = ", ".join(f"{comparison.count(status)} {status}" for status in STATUSES)
    text = (f"{comparison.path.name}: {_count(comparison.disabled, 'disabled pair')} ({comparison.generated} "
            f"generated, {comparison.hand_written} hand-written); {counts}")
    if not comparison.rows:
        text += " (the SRDF and the sampled matrix agree)"
    if comparison.unsampled:
        text += f"; {comparison.unsampled} entries name links without collision geometry (nothing to check)"
    return text


def _ordered(results: list[cm.PairResult]) -> list[cm.PairResult]:
    return sorted(results, key=lambda r: (not r.sampled, -r.fraction, cm.CATEGORIES.index(r.category),
                                          r.link_a, r.link_b))


def _row(result: cm.PairResult) -> list:
    home = "yes" if result.at_home else ""
    if not result.sampled:
        return [result.link_a, result.link_b, result.category, "-", "-", "-", "-", home, ""]
    if not result.samples:  # decided before sampling (touching at home)
        return [result.link_a, result.link_b, result.category, "", 0, "", "", home, len(result.limit_hits) or ""]
    low, high = result.interval
    return [result.link_a, result.link_b, result.category, result.collisions, result.samples,
            f"{result.fraction:.4f}", f"{low:.4f}-{high:.4f}" if result.collisions else f"<= {result.upper_bound:.2g}",
            home, len(result.limit_hits) or ""]


def _retired_line(results: list[cm.PairResult], samples: int) -> str:
    """How many pairs were counted only until their category was decided, and what that means."""
    retired = [result for result in results if result.retired]
    if not retired:
        return ""
    return (f"{_count(len(retired), 'pair')} counted only until the category was decided (then filtered out "
            f"with setCollisionFilterPair): the categories are exact, the fractions and intervals of those pairs "
            f"are estimates over the samples each was checked in (column samples, of {samples})")


def _count(number: int, noun: str) -> str:
    """``1 pair``, ``3 pairs``."""
    return f"{number} {noun}{'' if number == 1 else 's'}"
