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
from ar3cli.output.html_page import badge, esc, findings_section, number, page, severity_counts

SECTIONS = (("summary", "Summary"), ("tree", "Kinematic tree"), ("renders", "Pictures"),
            ("findings", "Findings"), ("collisions", "Self-collision matrix"), ("torques", "Torque margins"),
            ("fk", "FK verification"), ("cross-check", "Cross-check"))


def robot_page(data: Mapping[str, Any], context: Mapping[str, Any], pictures: Sequence[Mapping[str, Any]]) -> str:
    """The report of one robot. ``data``: ``info``, ``lint``, ``collisions``, ``fk`` (JSON documents;
    a section that could not be computed is None and ``data["skipped"][section]`` says why),
    ``cross_check`` (None until that feature exists: its section says so), ``settings``.
    ``context``: ``lines`` (each section's summary lines), ``sources`` and ``fixes`` (for the
    findings). ``pictures``: ``side``, ``geometry``, ``png`` (bytes), ``contacts``, or ``error``."""
    info, lint = data.get("info") or {}, data.get("lint") or {}
    skipped = data.get("skipped", {})
    lines = context.get("lines", {})
    title = f"ar3cli report: {info.get('name') or info.get('path') or 'robot'}"
    body = [f"<h1>{esc(title)}</h1>", f'<p class="mono muted">{esc(info.get("path"))}; '
            f'{esc(data.get("settings", {}).get("described", ""))}</p>',
            "<nav>" + "".join(f'<a href="#{key}">{esc(name)}</a>' for key, name in SECTIONS) + "</nav>",
            _section("summary", _summary(info, lint, lines.get("info", []))),
            _section("tree", _tree(info)),
            _section("renders", _pictures(pictures)),
            _section("findings", severity_counts(lint.get("summary", {}))
                     + findings_section(lint.get("findings", []), context)),
            _section("collisions", _collisions(data.get("collisions"), lines.get("collisions", []),
                                               skipped.get("collisions"))),
            _section("torques", _torques(info.get("torques"), lines.get("torques", []), skipped.get("torques"))),
            _section("fk", _fk(data.get("fk"), lines.get("fk", []), skipped.get("fk"))),
            _section("cross-check", _cross_check(data.get("cross_check")))]
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


def _section(key: str, content: str) -> str:
    name = dict(SECTIONS)[key]
    return f'<section id="{key}"><h2>{esc(name)}</h2>{content}</section>\n'


def _skipped(why: str | None) -> str:
    return f'<p class="muted">not computed: {esc(why)}</p>' if why else '<p class="muted">not computed.</p>'


def _lines(lines: Sequence[str]) -> str:
    return "<ul>" + "".join(f"<li>{esc(line)}</li>" for line in lines) + "</ul>" if lines else ""


def _summary(info: Mapping[str, Any], lint: Mapping[str, Any], lines: Sequence[str]) -> str:
    box = (info.get("bounding_box_m") or {}).get("size")
    cards = [("links", info.get("link_count")), ("joints", info.get("joint_count")), ("DOF", info.get("dof")),
             ("mass (kg)", number(info.get("total_mass_kg"))),
             ("size (m)", " x ".join(number(v, 3) for v in box) if box else "-"),
             ("lint", "FAILED" if (lint.get("summary") or {}).get("failed") else "passed")]
    keys = ("link_count", "joint_count", "dof", "total_mass_kg", "", "")
    html = ['<div class="cards">']
    for (label, value), key in zip(cards, keys):
        attribute = f' data-info="{key}"' if key else ""
        html.append(f'<div class="card">{esc(label)}<b{attribute}>{esc(value)}</b></div>')
    return "".join(html) + "</div>" + _lines(lines)


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


def _pictures(pictures: Sequence[Mapping[str, Any]]) -> str:
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
    note = ("<p>Links in contact at the home pose are drawn red "
            f"({len(contacts)} pair{'s' if len(contacts) != 1 else ''}):</p>" + _lines(
                [f"{a} / {b}: {number(depth, 3)} m deep" for (a, b), depth in sorted(contacts.items())])
            if contacts else "<p>No two non-adjacent links are in contact at the home pose.</p>")
    return "<div>" + "".join(out) + "</div>" + note + \
        '<p class="muted">Collision geometry is drawn blue; contacts red.</p>'


def _collisions(collisions: Mapping[str, Any] | None, lines: Sequence[str], why: str | None) -> str:
    if not collisions:
        return _skipped(why)
    return _lines(lines) + heat_map_svg(collisions)


def _torques(torques: Mapping[str, Any] | None, lines: Sequence[str], why: str | None) -> str:
    if not torques:
        return _skipped(why)
    return _lines(lines) + torque_chart_svg(torques)


def _fk(fk: Mapping[str, Any] | None, lines: Sequence[str], why: str | None) -> str:
    if not fk:
        return _skipped(why)
    verdict = '<span class="badge ok">\u2714 PASS</span>' if fk.get("passed") else \
        '<span class="badge fail">\u2716 FAIL</span>'
    return (f'<p data-fk-passed="{str(bool(fk.get("passed"))).lower()}">{verdict} max position error '
            f'{number(fk.get("max_position_error_m"), 3)} m, max orientation error '
            f'{number(fk.get("max_orientation_error_rad"), 3)} rad over {int(fk.get("samples", 0))} samples</p>'
            + _lines(lines))


def _cross_check(result: Mapping[str, Any] | None) -> str:
    """``cross-check``'s verdict: the command puts its JSON document in ``data["cross_check"]``
    (``passed`` and ``lines``), or None where MuJoCo is not installed."""
    if not result:
        return ('<p class="muted">MuJoCo is not installed here: <code>pip install \'ar3cli[mujoco]\'</code> '
                'adds PyBullet-against-MuJoCo agreement to this page.</p>')
    verdict = '<span class="badge ok">\u2714 PASS</span>' if result.get("passed") else \
        '<span class="badge fail">\u2716 FAIL</span>'
    return f"<p>{verdict}</p>" + _lines([str(line) for line in result.get("lines", [])])
