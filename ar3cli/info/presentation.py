"""``ar3cli info``'s report: the JSON document, and for people the joint and mass tables, the
kinematic tree (an output :class:`~ar3cli.output.report.Tree`) and a few summary lines."""

from __future__ import annotations

from ar3cli.findings import listed
from ar3cli.info.summary import JointInfo, Summary
from ar3cli.info.torques import TOO_WEAK, TorqueCheck
from ar3cli.output.report import Report, Table, Tree, format_cell

ONE_LINE_LIST = 12
"""Name lists longer than this are cut in the summary lines (the JSON has them all)."""


def library_report(path, library) -> Report:
    """The Report for a xacro library (:class:`~ar3cli.urdf.macro_library.MacroLibrary`): one line, not
    tables of a robot that is not there (no name, no links)."""
    where = (f"; run ar3cli info on the file that includes it: {', '.join(library.included_by)}"
             if library.included_by else "; run ar3cli info on the entry file that includes it")
    data = {"path": str(path), "macro_library": {"macros": list(library.macros), "properties": library.properties,
                                                 "materials": library.materials,
                                                 "included_by": list(library.included_by)}}
    return Report(data=data, lines=[f"{path}: a xacro library, not a robot: it {library.describe()} and "
                                    f"instantiates none{where}"])


def report(summary: Summary, tree: bool = True, torques: TorqueCheck | None = None,
           picture: str | None = None) -> Report:
    """The Report for ``summary``; ``tree=False`` leaves the tree out (JSON has no use for it).
    ``torques`` adds the gravity torque table, its summary and warnings (JSON: ``torques``);
    ``picture`` is the path of the tree picture written (JSON: ``png``)."""
    data = summary.to_dict()
    tables = [joint_table(summary), mass_table(summary)]
    lines = summary_lines(summary)
    if torques is not None:
        data["torques"] = torques.to_dict()
        tables.append(torque_table(torques))
        lines += torque_lines(torques)
    if picture is not None:
        data["png"] = picture
        lines.append(f"kinematic tree picture written to {picture}")
    return Report(data=data, tables=tables, renderables=[kinematic_tree(summary)] if tree else [], lines=lines)


def torque_table(check: TorqueCheck) -> Table:
    rows = []
    for joint in check.joints:
        needed = f"{joint.needed:.4g} {joint.unit}"
        effort = "-" if joint.effort is None else f"{joint.effort:g} {joint.unit}"
        margin = "-" if joint.margin is None else f"{joint.margin:.3g}"
        name = joint.name + (f" (follows {joint.mimic_of})" if joint.mimic_of else "")
        rows.append([name, needed, joint.at, effort, margin, joint.status])
    return Table(title=f"gravity torques: worst of {check.configurations} configurations "
                       f"({check.limit_configurations} home/limit + {check.samples} samples, seed {check.seed})",
                 columns=["joint", "max |torque| needed", "at", "declared effort", "margin", "status"], rows=rows,
                 numeric_columns=("max |torque| needed", "declared effort", "margin"), status_column="status")


def torque_lines(check: TorqueCheck) -> list[str]:
    if not check.joints:
        return ["gravity torques: no actuated joint"]
    weak, missing = check.too_weak, check.without_effort
    checked = [joint for joint in check.joints if joint.margin is not None]
    line = (f"gravity torques: {len(check.joints) - len(weak) - len(missing)} of {_count(len(check.joints), 'joint')} "
            "can hold the robot up")
    if checked:
        least = min(checked, key=lambda joint: joint.margin)  # type: ignore[arg-type,return-value]
        line += f"; smallest margin {least.margin:.3g} ({least.name})"
    lines = [line]
    lines += [f"warning: joint {joint.name} is {TOO_WEAK}: it needs {joint.needed:.4g} {joint.unit} to hold the robot "
              f"at '{joint.at}' but declares effort {joint.effort:g} {joint.unit}" for joint in weak]
    if missing:
        lines.append(f"no effort declared (limit effort missing or 0): {_names([joint.name for joint in missing])}")
    return lines


def joint_table(summary: Summary) -> Table:
    rows = []
    for joint in summary.movable_joints:
        low, high = ("unlimited", "unlimited") if joint.unlimited else (joint.lower, joint.upper)
        rows.append([joint.name, joint.type, _axis(joint), low, high, joint.effort, joint.velocity, _mimic(joint)])
    return Table(title=f"movable joints ({len(rows)}, DOF {summary.dof}; rad or m, N m or N, rad/s or m/s)",
                 columns=["joint", "type", "axis", "lower", "upper", "effort", "velocity", "note"], rows=rows,
                 numeric_columns=("lower", "upper", "effort", "velocity"))


def mass_table(summary: Summary) -> Table:
    total = summary.total_mass
    rows = [[link.name, link.mass, _share(link.mass, total), link.mass_note] for link in summary.links]
    return Table(title=f"link masses (total {total:.4g} kg)", columns=["link", "mass (kg)", "share", "note"],
                 rows=rows, numeric_columns=("mass (kg)", "share"))


def kinematic_tree(summary: Summary) -> Tree:
    """The kinematic tree: each root link, and under each link the joints leading to its children
    (the output layer draws it and escapes the names)."""
    children: dict[str | None, list[JointInfo]] = {}
    for joint in summary.joints:
        children.setdefault(joint.parent, []).append(joint)
    top = Tree(f"kinematic tree of {summary.name or summary.path.name}", style="bold")
    seen: set[str] = set()

    def grow(node: Tree, link: str) -> None:
        """Iterative, not recursive: a chain of thousands of links (a rope, a snake) stays fine."""
        stack = [(node, link)]
        seen.add(link)
        while stack:
            node, link = stack.pop()
            branches = []
            for joint in children.get(link, []):
                child = joint.child or "?"
                loop = child in seen
                branch = Tree(f"{child}  ({joint_label(joint)})" + ("  [loop]" if loop else ""))
                node.children.append(branch)
                if not loop:
                    seen.add(child)
                    branches.append((branch, child))
            stack += reversed(branches)

    for root in summary.roots:
        top.children.append(Tree(f"{root}  (root)"))
        grow(top.children[-1], root)
    for name in summary.unreachable:
        if name not in seen:
            top.children.append(Tree(f"{name}  (not reachable from the root)"))
            grow(top.children[-1], name)
    return top


def summary_lines(summary: Summary) -> list[str]:
    roots = _names(summary.roots) or "none"
    lines = [f"{summary.name or '(no name)'} ({summary.path}): {_count(len(summary.links), 'link')}, "
             f"{_count(len(summary.joints), 'joint')}, "
             f"root link{'s' if len(summary.roots) != 1 else ''} {roots}"]
    movable = summary.movable_joints
    by_type: dict[str, int] = {}
    for joint in movable:
        by_type[joint.type] = by_type.get(joint.type, 0) + 1
    kinds = ", ".join(f"{count} {kind}" for kind, count in by_type.items())
    mimics = sum(1 for joint in movable if joint.mimic is not None and joint.dof == 0)
    lines.append(f"DOF {summary.dof}: {_count(len(movable), 'movable joint')}" + (f" ({kinds})" if kinds else "")
                 + (f", of which {mimics} mimic (following another joint, no DOF of their own)" if mimics else ""))
    massless = summary.massless_links
    detail = (f"; {_count(len(massless), 'link')} counted as 0: " + _names([f"{link.name} ({link.mass_note})"
                                                                    for link in massless])) if massless else ""
    lines.append(f"total mass {summary.total_mass:.4g} kg{detail}")
    floating, fixed = summary.pybullet_mass(fixed_base=False), summary.pybullet_mass(fixed_base=True)
    if floating != summary.total_mass or fixed != summary.total_mass:
        lines.append(f"PyBullet simulates {floating:.4g} kg floating, {fixed:.4g} kg with a fixed base (1 kg for each link "
                     "without <inertial>; a fixed base weighs 0)")
    root = summary.roots[0] if len(summary.roots) == 1 else "the root link"
    if summary.centre_of_mass is not None:
        lines.append(f"centre of mass at the zero configuration: {_point(summary.centre_of_mass)} m "
                     f"(in {root}'s frame)")
    else:
        lines.append("centre of mass: n/a")
    box = summary.bounding_box
    if box is not None:
        extent = ", ".join(f"{axis} {_metres(low)} .. {_metres(high)}" for axis, low, high in zip("xyz", box.low, box.high))
        size = " x ".join(map(_metres, box.size))
        left_out = ""
        if box.shapes_left_out:
            left_out = (f"; covers only {box.shapes} of {box.shapes + box.shapes_left_out} shapes (the others are of "
                        "unknown size: unresolved or unreadable meshes)")
        geometry = "visual geometry"
        if box.collision_links:
            geometry += f"; collision geometry for {_count(len(box.collision_links), 'link')}"
        lines.append(f"bounding box at the zero configuration ({geometry}): {extent} m; size {size} m{left_out}")
    else:
        lines.append("bounding box: n/a (no shape of known size was placed)")
    lines.append(_mesh_line(summary))
    unresolved = summary.meshes.unresolved
    if unresolved:
        problems = listed(dict.fromkeys(item["problem"] for item in unresolved), 3, separator="; ")
        lines.append(f"unresolved meshes ({len(unresolved)} of {summary.meshes.files} files: {problems}): "
                     + _names([item["uri"] for item in unresolved], most=3)
                     + ("" if len(unresolved) <= 3 else "; --format json lists them all"))
    leaves = summary.end_effectors
    lines.append(f"end effectors (leaf links, {len(leaves)}): {_names(leaves) or 'none'}")
    if summary.unreachable:
        lines.append(f"not reachable from the root ({len(summary.unreachable)}): {_names(summary.unreachable)}")
    lines += [f"note: {note}" for note in summary.notes]
    return lines


def _mesh_line(summary: Summary) -> str:
    facts = summary.meshes
    if not facts.references:
        return "meshes: none"
    formats = ", ".join(f"{count} {kind}" for kind, count in facts.formats.items())
    line = f"meshes: {_count(facts.references, 'reference')} to {_count(facts.files, 'file')} ({formats})"
    if facts.lfs_pointers:
        line += f"; {len(facts.lfs_pointers)} are Git LFS pointers (run git lfs pull)"
    counted = facts.counted_files
    if facts.triangles is None:
        line += "; triangles n/a (counted for binary STL only)"
    else:
        roles = ", ".join(f"{role} {count:,}" for role, count in facts.triangles_by_role.items() if count is not None)
        scope = "" if counted == facts.files else f" in {counted} of {facts.files} files, counted for binary STL only"
        line += f"; {facts.triangles:,} triangles ({roles}){scope}"
    return line


def joint_label(joint: JointInfo) -> str:
    """``name: type, axis X Y Z, LOWER .. UPPER unit, follows LEADER``: one joint in one line (the
    tree's edges, an editor's hover)."""
    parts = [f"{joint.name}: {joint.type}"]
    if joint.axis is not None and joint.type != "fixed":
        parts.append(f"axis {_axis(joint)}")
    if joint.unlimited:
        parts.append("unlimited")
    elif joint.type in ("revolute", "prismatic"):
        if joint.lower is None and joint.upper is None:
            parts.append("no limits")
        else:
            unit = "rad" if joint.type == "revolute" else "m"
            parts.append(f"{format_cell(joint.lower)} .. {format_cell(joint.upper)} {unit}")
    if joint.mimic is not None:
        parts.append(_mimic(joint))
    return ", ".join(parts)


def _axis(joint: JointInfo) -> str:
    if joint.axis is None:
        return ""
    text = " ".join(f"{v:g}" for v in joint.axis)
    return text if joint.axis_given else f"{text} (default)"


def _mimic(joint: JointInfo) -> str:
    if joint.mimic is None:
        return ""
    text = f"follows {joint.mimic['joint']}"
    if joint.mimic["multiplier"] != 1.0:
        text += f" x {joint.mimic['multiplier']:g}"
    if joint.mimic["offset"] != 0.0:
        text += f" {'+' if joint.mimic['offset'] > 0 else '-'} {abs(joint.mimic['offset']):g}"
    if joint.dof:
        text += " (no such joint: counted as a DOF)"
    return text


def _share(mass: float | None, total: float) -> str:
    return f"{100 * mass / total:.1f}%" if mass is not None and total > 0 else "-"


def _metres(value: float) -> str:
    """0.1 mm resolution; a rounding to zero drops its sign."""
    text = f"{value:.4f}"
    return text[1:] if text == "-0.0000" else text


def _point(values) -> str:
    return "(" + ", ".join(map(_metres, values)) + ")"


def _count(number: int, noun: str) -> str:
    return f"{number} {noun}" if number == 1 else f"{number} {noun}s"


def _names(names: list[str], most: int = ONE_LINE_LIST) -> str:
    return listed(names, most)
