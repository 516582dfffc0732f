"""HTML pages: ``ar3cli report``'s one page per robot and ``lint-urdf --format html``'s batch page.

The renderer takes plain data only: the JSON documents the commands print with ``--format json``
(``info``, ``lint-urdf``, ``sample-collisions``, ``fk-verify``), their summary lines, the cited
source lines and fix commands, and the pictures as PNG bytes. It reads no file and imports no
feature, so the numbers on the page are the numbers of the JSON outputs: the data island
(``<script type="application/json" id="data">``) holds those documents as they are.
"""

from __future__ import annotations

import base64
from collections.abc import Mapping, Sequence
from typing import Any

from ar3cli.output.html_charts import heat_map_svg, torque_chart_svg
from ar3cli.output.html_page import SEVERITIES, badge, esc, findings_section, number, page, severity_counts

SECTIONS = (("summary", "Summary"), ("tree", "Kinematic tree"), ("renders", "Pictures"),
            ("findings", "Findings"), ("collisions", "Self-collision matrix"), ("torques", "Torque margins"),
            ("fk", "FK verification"), ("cross-check", "Cross-check"))
STATUS_BADGE = {"fail": ("fail", "\u2716 FAIL"), "warning": ("warning", "\u25b2 WARNING"), "pass": ("ok", "\u2714 PASS"),
                "not checked": ("unchecked", "\u2013 NOT CHECKED")}
"""A check's status as a badge: class and words (with a shape: colour is never the only cue)."""


def robot_page(data: Mapping[str, Any], context: Mapping[str, Any], pictures: Sequence[Mapping[str, Any]]) -> str:
    """The report of one robot: the verdict first, then one collapsed section per part, each showing
    its own verdict and count until it is opened. ``data``: ``verdict`` (``analysis.verdict.Verdict``'s
    JSON: ``status``, ``headline``, ``checks`` with ``key``, ``title``, ``status``, ``line``, ``count``;
    ``notes``), ``home`` (the home pose), ``info``, ``lint``, ``collisions``, ``fk``, ``cross_check``
    (JSON documents; a section that could not be computed is None and ``data["skipped"][section]``
    says why; ``cross_check`` is None without MuJoCo), ``settings``. ``context``: ``lines`` (each
    section's summary lines), ``sources`` and ``fixes`` (for the findings). ``pictures``: ``side``,
    ``geometry``, ``png`` (bytes), ``contacts``, or ``error``."""
    info, lint = data.get("info") or {}, data.get("lint") or {}
    skipped = data.get("skipped", {})
    lines = context.get("lines", {})
    verdict = data.get("verdict") or {}
    checks = {check.get("key"): check for check in verdict.get("checks", [])}
    title = f"ar3cli report: {info.get('name') or info.get('path') or 'robot'}"
    links = len(info.get("links", []))
    body = [f"<h1>{esc(title)}</h1>", f'<p class="mono muted">{esc(info.get("path"))}; '
            f'{esc(data.get("settings", {}).get("described", ""))}</p>',
            _verdict(verdict),
            "<nav>" + "".join(f'<a href="#{key}">{esc(name)}</a>' for key, name in SECTIONS) + "</nav>",
            f'<section id="summary"><h2>Summary</h2>{_summary(info, lines.get("info", []))}</section>\n',
            _section("tree", _tree(info), note=f"{links} link{'s' if links != 1 else ''}, "
                                                f"{int(info.get('dof') or 0)} DOF"),
            _section("renders", _pictures(pictures, data.get("home")), checks.get("renders")),
            _section("findings", severity_counts(lint.get("summary", {}))
                     + findings_section(lint.get("findings", []), context), checks.get("findings")),
            _section("collisions", _collisions(data.get("collisions"), lines.get("collisions", []),
                                               skipped.get("collisions")), checks.get("collisions")),
            _section("torques", _torques(info.get("torques"), lines.get("torques", []), skipped.get("torques")),
                     checks.get("torques")),
            _section("fk", _fk(data.get("fk"), lines.get("fk", []), skipped.get("fk")), checks.get("fk")),
            _section("cross-check", _cross_check(data.get("cross_check"), skipped.get("cross_check")),
                     checks.get("cross-check"))]
    return page(title, body, data)


def lint_page(data: Mapping[str, Any], context: Mapping[str, Any]) -> str:
    """``lint-urdf --format html``: the summary, then one section per file with its findings.
    ``data`` is lint-urdf's JSON document; ``context`` as for :func:`robot_page`."""
    summary = data.get("summary", {})
    findings = list(data.get("findings", []))
    fixes = list(context.get("fixes", []))
    body = ["<h1>ar3cli lint-urdf</h1>", f"<p>{esc(context.get('verdict', ''))}</p>", severity_counts(summary)]
    start = 0
    for at, result in enumerate(data.get("files", [])):
        # each file's findings follow the previous file's (their path may be an included xacro file)
        mine = list(range(start, min(start + int(result.get("findings", 0)), len(findings))))
        start = mine[-1] + 1 if mine else start
        error = f'<p>{badge("error")} not fully checked: {esc(result["error"])}</p>' if result.get("error") else ""
        own = {"sources": context.get("sources", {}), "fixes": [fixes[i] if i < len(fixes) else "" for i in mine]}
        body.append(f'<section id="file-{at}" data-findings="{int(result.get("findings", 0))}"><h2 class="mono">'
                    f'{esc(result.get("path"))}</h2>{error}{findings_section([findings[i] for i in mine], own)}</section>')
    return page("ar3cli lint-urdf", body, data)


def _section(key: str, content: str, check: Mapping[str, Any] | None = None, note: str = "") -> str:
    """A section collapsed to one line: its title, its check's status badge, count and line (or a
    ``note`` for a section without a verdict); the content one click away."""
    name = dict(SECTIONS)[key]
    status = str(check.get("status")) if check else ""
    head = f"<h2>{esc(name)}</h2>"
    if check:
        count = int(check.get("count") or 0)
        head += (f" {status_badge(status)}" + (f' <b class="count" data-check-count="{count}">{count}</b>' if count
                                               else "") + f' <span class="line">{esc(check.get("line"))}</span>')
    elif note:
        head += f' <span class="line">{esc(note)}</span>'
    return (f'<details class="section" id="{key}" data-status="{esc(status)}"><summary>{head}</summary>'
            f'<div class="body">{content}</div></details>\n')


def status_badge(status: str) -> str:
    """A check's status (``fail``, ``warning``, ``pass``, ``not checked``) as a badge with its word and shape."""
    css, words = STATUS_BADGE.get(status, ("unchecked", status.upper()))
    return f'<span class="badge {css}">{esc(words)}</span>'


def _verdict(verdict: Mapping[str, Any]) -> str:
    """The page's one verdict: the worst status of every section's check, its headline, one row per
    check (linking to its section) and the notes a reader needs first (the home pose is not all zeros)."""
    if not verdict:
        return ""
    status = str(verdict.get("status"))
    headline = str(verdict.get("headline", ""))
    words = headline.split(": ", 1)[1] if ": " in headline else headline
    rows = "".join(f'<tr data-check="{esc(check.get("key"))}" data-status="{esc(check.get("status"))}">'
                   f'<td>{status_badge(str(check.get("status")))}</td>'
                   f'<td><a href="#{esc(check.get("key"))}">{esc(check.get("title"))}</a></td>'
                   f'<td>{esc(check.get("line"))}</td></tr>' for check in verdict.get("checks", []))
    notes = _lines([f"note: {note}" for note in verdict.get("notes", [])])
    return (f'<section id="verdict" class="verdict {esc(STATUS_BADGE.get(status, ("unchecked",))[0])}" '
            f'data-verdict="{esc(status)}"><p class="headline">{status_badge(status)} {esc(words)}</p>'
            f'<table class="checks">{rows}</table>{notes}</section>\n')


def _skipped(why: str | None) -> str:
    return f'<p class="muted">not computed: {esc(why)}</p>' if why else '<p class="muted">not computed.</p>'


def _lines(lines: Sequence[str]) -> str:
    return "<ul>" + "".join(f"<li>{esc(line)}</li>" for line in lines) + "</ul>" if lines else ""


def _summary(info: Mapping[str, Any], lines: Sequence[str]) -> str:
    box = (info.get("bounding_box_m") or {}).get("size")
    cards = [("links", info.get("link_count"), "link_count"), ("joints", info.get("joint_count"), "joint_count"),
             ("DOF", info.get("dof"), "dof"), ("mass (kg)", number(info.get("total_mass_kg")), "total_mass_kg"),
             ("size (m)", " x ".join(number(v, 3) for v in box) if box else "-", "")]
    html = ['<div class="cards">']
    for label, value, key in cards:
        attribute = f' data-info="{key}"' if key else ""
        html.append(f'<div class="card">{esc(label)}<b{attribute}>{esc(value)}</b></div>')
    html.append("</div>")
    if lines:
        html.append(f"<details><summary>{len(lines)} facts (info)</summary>{_lines(lines)}</details>")
    return "".join(html)


def _tree(info: Mapping[str, Any]) -> str:
    """Nested ``<details>`` (collapsible without JS), built without recursion: a malicious file may
    hold a chain thousands of links deep."""
    links = {link.get("name"): link for link in info.get("links", [])}
    joints = {joint.get("name"): joint for joint in info.get("joints", [])}
    out = ['<p class="noprint"><button data-details="open">expand all</button>'
           '<button data-details="close">collapse all</button></p>']
    seen: set[str] = set()
    stack: list[Any] = [("link", name) for name in reversed(info.get("root_links", []))]
    while stack:
        kind, name = stack.pop()
        if kind == "close":
            out.append("</details>")
            continue
        if name in seen or name not in links:
            continue
        seen.add(name)
        link = links[name]
        via = joints.get(link.get("parent_joint")) if link.get("parent_joint") else None
        joint = f'<span class="joint">{esc(via.get("name"))} ({esc(via.get("type"))}) \u2192 </span>' if via else ""
        mass = f' <span class="muted">{number(link.get("mass_kg"))} kg</span>' if link.get("mass_kg") is not None else ""
        children = [joints[j].get("child") for j in link.get("child_joints", []) if j in joints]
        if not children:
            out.append(f'<div class="leaf">{joint}<b>{esc(name)}</b>{mass}</div>')
            continue
        out.append(f'<details class="tree" open><summary>{joint}<b>{esc(name)}</b>{mass}</summary>')
        stack.append(("close", None))
        stack += [("link", child) for child in reversed(children)]
    if info.get("unreachable_links"):
        out.append(f'<p>not reachable from the root: {esc(", ".join(map(str, info["unreachable_links"])))}</p>')
    return "".join(out)


def _pictures(pictures: Sequence[Mapping[str, Any]], home: Mapping[str, Any] | None) -> str:
    if not pictures:
        return _skipped(None)
    out, contacts = [], {}
    for picture in pictures:
        label = f"{picture.get('geometry')}, {picture.get('side')}"
        if picture.get("error"):
            out.append(f'<figure><figcaption>{esc(label)}: not drawn ({esc(picture["error"])})</figcaption></figure>')
            continue
        uri = "data:image/png;base64," + base64.b64encode(picture["png"]).decode("ascii")
        out.append(f'<figure><img src="{uri}" width="{int(picture.get("width", 0))}" '
                   f'height="{int(picture.get("height", 0))}" alt="{esc(label)}"><figcaption>{esc(label)}'
                   "</figcaption></figure>")
        for contact in picture.get("contacts", []):
            contacts[(contact["link_a"], contact["link_b"])] = contact["depth_m"]
    pose = _home_pose(home)
    note = ("<p>Links in contact at the home pose are drawn red "
            f"({len(contacts)} pair{'s' if len(contacts) != 1 else ''}):</p>" + _lines(
                [f"{a} / {b}: {number(depth, 3)} m deep" for (a, b), depth in sorted(contacts.items())])
            if contacts else "<p>No two non-adjacent links are in contact at the home pose.</p>")
    return pose + "<div>" + "".join(out) + "</div>" + note + \
        '<p class="muted">Collision geometry is drawn blue; contacts red.</p>'


def _home_pose(home: Mapping[str, Any] | None) -> str:
    """Which pose the pictures show: every joint at 0, or which joints are not and why."""
    if not home:
        return ""
    away = home.get("away_from_zero") or {}
    if not away:
        return '<p data-home="zero">Drawn at the home pose: every joint at 0.</p>'
    values = home.get("values") or {}
    items = [f"{name} = {number(values.get(name))} ({why})" for name, why in away.items()]
    return (f'<p data-home="moved">Drawn at the home pose, which is not all zeros: {len(items)} '
            f'joint{"s" if len(items) != 1 else ""} at another value:</p>' + _capped(items))


LIST_SHOWN = 8
"""Items of a long list shown before the rest is folded into one more click."""


def _capped(items: Sequence[str]) -> str:
    """A list of the first :data:`LIST_SHOWN` items, the rest behind a ``<details>`` with their count."""
    if len(items) <= LIST_SHOWN:
        return _lines(items)
    return (_lines(items[:LIST_SHOWN]) + f"<details><summary>and {len(items) - LIST_SHOWN} more</summary>"
            f"{_lines(items[LIST_SHOWN:])}</details>")


WARNING_WORDS = {"contact-at-home": ("pair", "in contact at the home pose but not adjacent"),
                 "pybullet-default-self-collision": ("pair", "always in contact, yet checked by PyBullet's "
                                                             "URDF_USE_SELF_COLLISION"),
                 "contact-only-at-limits": ("pair", "touching only at a joint limit (kept enabled)"),
                 "visual-only-links": ("warning", "about links with <visual> but no <collision>")}
"""What each kind of collision-matrix warning is about (its noun and the rest), for its one grouped line."""


def _collisions(collisions: Mapping[str, Any] | None, lines: Sequence[str], why: str | None) -> str:
    if not collisions:
        return _skipped(why)
    groups: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
    for warning in collisions.get("warnings", []):
        groups.setdefault((str(warning.get("severity")), str(warning.get("rule"))), []).append(warning)
    order = {level: rank for rank, level in enumerate(SEVERITIES)}
    grouped = []
    for (severity, rule), members in sorted(groups.items(), key=lambda item: order.get(item[0][0], len(order))):
        noun, what = WARNING_WORDS.get(rule, ("finding", rule))
        hint = members[0].get("hint")
        grouped.append(f'<details class="group" data-rule="{esc(rule)}" data-group-count="{len(members)}"><summary>'
                       f'{badge(severity)} {len(members)} {noun}{"s" if len(members) != 1 else ""} {esc(what)}</summary>'
                       + _lines([str(member.get("message")) for member in members])
                       + (f'<p class="muted">hint: {esc(hint)}</p>' if hint else "") + "</details>")
    return _lines(lines) + "".join(grouped) + heat_map_svg(collisions)


def _torques(torques: Mapping[str, Any] | None, lines: Sequence[str], why: str | None) -> str:
    if not torques:
        return _skipped(why)
    return _lines(lines) + torque_chart_svg(torques)


def _fk(fk: Mapping[str, Any] | None, lines: Sequence[str], why: str | None) -> str:
    if not fk:
        return _skipped(why)
    verdict = status_badge("pass" if fk.get("passed") else "fail")
    return (f'<p data-fk-passed="{str(bool(fk.get("passed"))).lower()}">{verdict} max position error '
            f'{number(fk.get("max_position_error_m"), 3)} m, max orientation error '
            f'{number(fk.get("max_orientation_error_rad"), 3)} rad over {int(fk.get("samples", 0))} samples</p>'
            + _lines(lines))


def _cross_check(result: Mapping[str, Any] | None, why: str | None = None) -> str:
    """``cross-check``'s verdict: the command puts its JSON document in ``data["cross_check"]``
    (``passed`` and ``lines``), or None where MuJoCo is not installed (or the check could not run: ``why``)."""
    if why:
        return _skipped(why)
    if not result:
        return ('<p class="muted">MuJoCo is not installed here: <code>pip install \'ar3cli[mujoco]\'</code> '
                'adds PyBullet-against-MuJoCo agreement to this page.</p>')
    verdict = status_badge("pass" if result.get("passed") else "fail")
    return f"<p>{verdict}</p>" + _lines([str(line) for line in result.get("lines", [])])
