"""File rules (F): can the file be read and parsed, and would a strict parser or ROS accept it."""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from functools import lru_cache
from pathlib import Path

from ar3cli.lint.rules.base import Hit, engine_rule, robot, rule

unreadable = engine_rule(
    "F001", "unreadable", "error", "File cannot be read",
    breaks="No engine or tool can read the file: nothing else is checked.",
    why="The path is missing, a directory, a pipe or device, too large, or not readable; nothing else can "
        "be checked.",
    fix="Check the path and its permissions.",
    bad="(a path that does not exist)", good=robot('<link name="base"/>'))

not_xml = engine_rule(
    "F002", "not-xml", "error", "File is not well-formed XML",
    breaks="urdfdom, PyBullet, MuJoCo and every XML parser refuse the file.",
    why="Every URDF consumer parses XML first; a syntax error (or an empty file, binary junk, or an "
        "entity declaration, which ar3cli refuses because entities can explode or read other files) "
        "stops all of them.",
    fix="Fix the XML at the reported line; remove any <!DOCTYPE>/<!ENTITY>.",
    bad='<?xml version="1.0"?>\n<robot name="r">\n  <link name="base">\n</robot>',
    good=robot('<link name="base"/>'))

not_robot = engine_rule(
    "F003", "not-robot", "error", "Root element is not <robot>",
    breaks="urdfdom and PyBullet refuse a file whose root element is not <robot>.",
    why="A URDF's root element must be <robot>; an SDF, MJCF or other XML file is not a URDF.",
    fix="Lint only URDF files, or convert the file to URDF.",
    bad='<?xml version="1.0"?>\n<sdf version="1.6"><model name="m"/></sdf>',
    good=robot('<link name="base"/>'))

xacro_failed = engine_rule(
    "F004", "xacro-failed", "error", "Xacro expansion failed",
    breaks="xacro stops: no URDF comes out for any tool.",
    why="A .xacro file must expand before it can be checked; undefined properties, missing includes "
        "or unknown packages stop the expansion.",
    fix="Pass --xacro-arg NAME:=VALUE / --package-path NAME=DIR, or fix the xacro at the reported place.",
    bad='<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
        '  <link name="${undefined_prefix}base"/>\n</robot>',
    good='<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
         '  <xacro:property name="prefix" value="my_"/>\n  <link name="${prefix}base"/>\n</robot>')

_PORTABILITY_QUIRKS = ("version-", "leading-junk", "trailing-junk", "undeclared-prefix")


@rule("F005", "strict-parser", "warning", "File needs a tolerant XML parser",
      engines=("ros",),
      why="""Strict parsers (urdfdom's TinyXML2, Python's xml.etree, ROS tools) reject
      version="0.0" declarations, blank lines or junk before the declaration, and bytes after the
      root element; namespace-aware ones (lxml, ROS 2 launch, xacro) reject an element prefix that
      is never declared (Drake's <drake:...> elements without xmlns:drake). PyBullet and ar3cli
      tolerate them, so such files work in one tool and fail in the next.""",
      fix='Write <?xml version="1.0"?> on the very first line and nothing after </robot>.',
      bad='<?xml version="0.0"?>\n<robot name="r">\n  <link name="base"/>\n</robot>\n',
      good=robot('<link name="base"/>'))
def strict_parser(ctx) -> Iterator[Hit]:
    for quirk in ctx.model.quirks:
        if quirk.code.startswith(_PORTABILITY_QUIRKS):
            hint = ('Declare each prefix on <robot> as xmlns:PREFIX="URI", whether it names elements or attributes '
                    '(Drake\'s drake: prefix is xmlns:drake="http://drake.mit.edu").'
                    if quirk.code == "undeclared-prefix" else None)
            yield Hit(quirk.message, line=quirk.line, hint=hint)


SUBSTITUTION = re.compile(r"\$\(|\$\{")
"""An unexpanded xacro or roslaunch substitution: ``$(find pkg)``, ``${var}`` (F006's; the mesh rules leave
such paths alone, and F007 such numbers)."""


@rule("F006", "unexpanded-substitution", "error", "Unexpanded $(...) or ${...} substitution",
      refused_by=("ros", "pybullet"),
      breaks="Every parser reads the text literally: urdfdom refuses a substituted number, and PyBullet cannot "
             "find a substituted mesh path and refuses the file.",
      why="""A URDF containing $(find pkg) or ${var} was written from a xacro file without
      expanding it (or by a broken generator); every URDF parser reads the text literally, so
      mesh paths and numbers are wrong.""",
      fix="Expand the xacro (xacro robot.urdf.xacro > robot.urdf) or lint the .xacro itself.",
      bad=robot('<link name="base"><visual><geometry><mesh filename="$(find pkg)/base.stl"/></geometry></visual></link>'),
      good=robot('<link name="base"><visual><geometry><box size="1 1 1"/></geometry></visual></link>'))
def unexpanded_substitution(ctx) -> Iterator[Hit]:
    if b"$" not in ctx.model.xml_bytes and b"&#" not in ctx.model.xml_bytes:
        return  # no "$" can reach an attribute (entities are refused): skip the walk over every attribute
    xacro_source = ctx.model.looks_like_xacro
    for element in ctx.model.root.iter():
        if not isinstance(element.tag, str):
            continue
        for key, value in element.attrib.items():
            if SUBSTITUTION.search(value):
                consequence = (": no tool can find the mesh (PyBullet refuses the file)"
                               if element.tag == "mesh" and key == "filename" else "")
                yield Hit(f"<{qualified_name(element, element.tag)} {qualified_name(element, key)}=\"{value}\"> "
                          f"contains an unexpanded substitution{consequence}", element,
                          hint=XACRO_SOURCE_HINT if xacro_source else None)


def qualified_name(element, name: str) -> str:
    """``name`` (a tag or an attribute of ``element``) as written, ``xacro:macro``, rather than lxml's Clark
    notation ``{http://www.ros.org/wiki/xacro}macro``."""
    if not name.startswith("{"):
        return name
    uri, _, local = name[1:].partition("}")
    prefix = next((key for key, value in (element.nsmap or {}).items() if value == uri and key), None)
    return f"{prefix}:{local}" if prefix else local


XACRO_SOURCE_HINT = ("This file is a xacro source (it holds <xacro:...> elements): rename it to .xacro (or "
                     ".urdf.xacro) and run ar3cli on it, or expand it: xacro FILE > robot.urdf.")


NUMERIC_ATTRIBUTES: dict[str, dict[str, int]] = {
    "origin": {"xyz": 3, "rpy": 3, "quat_xyzw": 4},
    "axis": {"xyz": 3},
    "box": {"size": 3},
    "mesh": {"scale": 0},  # 1 or 3 numbers (one number is G007's business)
    "cylinder": {"radius": 1, "length": 1},
    "capsule": {"radius": 1, "length": 1},
    "sphere": {"radius": 1},
    "mass": {"value": 1},
    "inertia": {key: 1 for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")},
    "limit": {"lower": 1, "upper": 1, "effort": 1, "velocity": 1, "acceleration": 1, "deceleration": 1, "jerk": 1},
    "dynamics": {"damping": 1, "friction": 1},
    "mimic": {"multiplier": 1, "offset": 1},
    "safety_controller": {"soft_lower_limit": 1, "soft_upper_limit": 1, "k_position": 1, "k_velocity": 1},
    "color": {"rgba": 4},
}
"""Element tag -> attribute -> how many numbers it must hold (0: one or three)."""


@lru_cache(maxsize=4096)
def number_problem(text: str, count: int) -> str | None:
    """Why ``text`` is not ``count`` finite numbers, or None when it is fine (cached: robot files
    repeat the same few texts, "0 0 0", "1 0 0", thousands of times)."""
    parts = text.split()
    expected = (1, 3) if count == 0 else (count,)
    if len(parts) in expected:
        try:  # the common case, a well-formed value, in one pass (a lint walks thousands of them)
            if all(map(math.isfinite, map(float, parts))):
                return None
        except ValueError:
            pass
    else:
        want = "1 or 3" if count == 0 else str(count)
        return f"has {len(parts)} number{'s' if len(parts) != 1 else ''}, expected {want}"
    for part in parts:
        try:
            value = float(part)
        except ValueError:
            return f"'{part}' is not a number"
        if not math.isfinite(value):
            return f"holds {part}, which is not a finite number"
    return None


@rule("F007", "malformed-number", "error", "Malformed number or wrong number of components",
      refused_by=("ros",),
      breaks="urdfdom refuses the file; PyBullet silently reads zeros, and nan or inf become NaN states.",
      why="""xyz/rpy/size/scale need exactly three numbers, rgba four, masses and limits one.
      Parsers disagree on what to do with "0 0" or "1,0,0": urdfdom refuses the file, PyBullet
      silently reads zeros, and nan or inf propagate into the physics as NaN states.""",
      fix="Write the right number of space-separated finite numbers (no commas, no units).",
      bad=robot('<link name="base"><visual><origin xyz="0 0"/><geometry><box size="1 1 1"/></geometry></visual></link>'),
      good=robot('<link name="base"><visual><origin xyz="0 0 0"/><geometry><box size="1 1 1"/></geometry></visual></link>'))
def malformed_number(ctx) -> Iterator[Hit]:
    for element in ctx.model.root.iter(*NUMERIC_ATTRIBUTES):
        spec = NUMERIC_ATTRIBUTES[element.tag]
        found = []
        for key, text in element.items():  # the attributes written (one or two), not every one the spec has
            count = spec.get(key)
            if count is None or ("$" in text and SUBSTITUTION.search(text)):
                continue  # unexpanded substitutions are F006's
            problem = number_problem(text, count)
            if problem:
                found.append((key, text, problem))
        if len(found) > 1:
            order = list(spec)
            found.sort(key=lambda item: order.index(item[0]))  # reported in the spec's order, as ever
        for key, text, problem in found:
            yield Hit(f"<{element.tag} {key}=\"{text}\"> {problem}", element)


LIBRARY = "F008"
"""The code of a xacro library's one line (:func:`macro_library_file`): the engine runs it alone on such a file."""


@rule(LIBRARY, "macro-library", "info", "A xacro library or fragment: checked where it is included",
      why="""A robot's urdf/ folder holds one entry file and files that only define xacro macros (or
      properties, or materials) for it to include: leg.xacro, utils/*.xacro, materials.xacro. Such a
      file instantiates no robot, so it has no name, no links and no joints of its own, and every
      robot rule would call it broken. Its content is checked where an entry file includes it: the
      entry file's findings point at this file's lines. This one line says so, and names the files of
      its package that include it. The same holds for a fragment that does not expand alone because it
      reads what its includer defines ($(arg model_dir) declared by the entry file, a $(find pkg) only
      its workspace resolves): when a file of its package includes it and expands, the failure alone is
      the includer's context missing, and this line names the includer and the reason. A fragment no
      expanding includer vouches for keeps its F004 error: a pull request cannot silence a broken robot by
      adding a file that includes it, nor pass one pre-commit lints without its includer.""",
      fix="Nothing to fix here: lint the entry file that includes it (lint-urdf on the folder does).",
      bad='''<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="length" value="0.3"/>
  <xacro:macro name="segment" params="name">
    <link name="${name}"/>
  </xacro:macro>
</robot>
''',
      good=robot('<link name="base"/>'),
      thresholds="A library: a file that makes no link and no joint, whose top level holds only xacro macro, property, "
                 "arg and include elements (also inside if/unless; property and macro also without the xacro: prefix, "
                 "as xacro before ROS Jade read them) and <material>s, and at least one macro, property or material. A "
                 "fragment: a xacro file that fails to expand alone and that a file of its package includes. The files "
                 "that include it are looked for in its package (at most 400 files).")
def macro_library_file(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.macro_library import macro_library

    library = macro_library(ctx.model)
    if library is not None:
        yield Hit(f"{library.describe()} and instantiates no robot: a xacro library, checked where an entry file "
                  f"includes it ({_includer_text(library.included_by)})", ctx.model.root)


def _includer_text(included_by) -> str:
    return f"included by {', '.join(included_by)}" if included_by else "no file of its package was found to include it"


def fragment_message(path, source: bytes, reason: str, expands_including: Callable[[Path], bool]) -> str | None:
    """F008's message for a xacro file whose expansion failed with ``reason`` (an F004) when it is a library,
    or a fragment that a file of its package includes and that expands there (``expands_including(includer)``:
    the includer expands, and what it included is this file). A fragment reads its includer's properties, or
    a ``$(arg NAME)`` it does not declare (xacro's arguments are global). Its includer checks it, so the
    file itself gets one info line instead of an error. None for an entry file, and for a fragment no
    working includer vouches for: its F004 stands (a pull request cannot silence a broken robot by adding
    a file that includes it, nor by an includer pre-commit does not lint)."""
    from ar3cli.urdf.macro_library import includers, library_in_source, shown_files

    library = library_in_source(source, path)
    if library is not None:
        return (f"{library.describe()} and instantiates no robot: a xacro library, checked where an entry file "
                f"includes it ({_includer_text(library.included_by)}); alone it does not expand: {reason}")
    working = [includer for includer in includers(path) if expands_including(includer)]
    if not working:
        return None
    where = ", ".join(shown_files(working, Path(path).parent))
    missing = _UNDEFINED_ARG.search(reason)
    if missing is not None and missing.group(1) in _undeclared_args(source):
        return (f"a xacro fragment: it reads $(arg {missing.group(1)}) without declaring it (<xacro:arg>), as an "
                f"include body reads its includer's arguments; it is checked where {where} includes it (that "
                "file expands), and does not expand alone")
    return (f"a xacro fragment included by {where}, where it is checked (that file expands): alone it does not "
            f"expand ({reason})")


_UNDEFINED_ARG = re.compile(r"Undefined substitution argument ([\w.-]+)")
_ARG_USE = re.compile(rb"\$\(arg\s+([\w.-]+)\s*\)")
_ARG_DECLARATION = re.compile(rb"<xacro:arg\b[^>]*\bname\s*=\s*[\"']([\w.-]+)[\"']")


def _undeclared_args(source: bytes) -> set[str]:
    """The names the file reads with ``$(arg NAME)`` and never declares with ``<xacro:arg name="NAME">``."""
    used = {match.group(1).decode("ascii", "replace") for match in _ARG_USE.finditer(source)}
    declared = {match.group(1).decode("ascii", "replace") for match in _ARG_DECLARATION.finditer(source)}
    return used - declared
