"""install-check's capability rows: each thing a command does with a library, tried for real.

An import check says a module is there; a capability check does the work a command does with it, on
a tiny input written to a temporary folder: read a COLLADA mesh (trimesh hands .dae to pycollada),
take a convex hull (trimesh hands it to scipy), decompose a mesh with pybullet's V-HACD, expand a
xacro macro, write a PNG. trimesh declares none of its optional libraries, so ``pip install ar3cli``
has them only because pyproject.toml lists them; a missing one makes the commands that need it refuse
every mesh of that kind, which is what these rows catch.

:data:`CAPABILITIES` is also the list of what needs which distribution that
``tests/test_plain_install.py`` holds against pyproject.toml's dependencies. A required capability
that does not work is a ``fail`` whose hint installs the distribution with the bounds ar3cli declares;
an optional one (CoACD) is ``info``.
"""

from __future__ import annotations

import importlib.metadata
import re
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ar3cli.install_check.record import Check


@dataclass(frozen=True)
class Capability:
    """One thing ar3cli does with a library: ``probe(folder)`` does it and returns what it saw."""

    name: str
    needs: tuple[str, ...]
    """Distributions (pip names) the probe needs beyond ar3cli's own code."""
    used_by: str
    probe: Callable[[Path], str]
    required: bool = True
    """A plain ``pip install ar3cli`` must have it; otherwise it is an extra."""
    extra: str = ""


CUBE_DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="0.01" name="centimeter"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="cube"><mesh>
    <source id="p"><float_array id="pa" count="24">0 0 0 0 0 2 0 2 0 0 2 2 2 0 0 2 0 2 2 2 0 2 2 2</float_array>
      <technique_common><accessor source="#pa" count="8" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>
      </technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="12"><input semantic="VERTEX" source="#v" offset="0"/>
      <p>0 1 3 0 3 2 4 6 7 4 7 5 0 4 5 0 5 1 2 3 7 2 7 6 0 2 6 0 6 4 1 5 7 1 7 3</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#cube"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""
"""A closed 2-unit cube: 8 cubic units."""

U_CORNERS = ((0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3))
U_OBJ = "".join(f"v {x} {y} {z}\n" for z in (0, 1) for x, y in U_CORNERS)
U_OBJ += "".join(f"f {a} {b} {c}\n" for a, b, c in (
    (1, 3, 2), (1, 4, 3), (1, 5, 4), (1, 6, 5), (1, 7, 6), (1, 8, 7),  # bottom, a fan from vertex 1
    (9, 10, 11), (9, 11, 12), (9, 12, 13), (9, 13, 14), (9, 14, 15), (9, 15, 16),  # top
    *((i, i % 8 + 1, i % 8 + 9) for i in range(1, 9)), *((i, i % 8 + 9, i + 8) for i in range(1, 9)),  # sides
))
"""An extruded U (3 x 3 x 1 with a 1 x 2 notch): 28 triangles, not convex, hull volume 9."""

CUBE_OBJ = "".join(f"v {x} {y} {z}\n" for z in (0, 1) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))) + "".join(
    f"f {a} {b} {c}\n" for a, b, c in ((1, 3, 2), (1, 4, 3), (5, 6, 7), (5, 7, 8), (1, 2, 6), (1, 6, 5),
                                      (2, 3, 7), (2, 7, 6), (3, 4, 8), (3, 8, 7), (4, 1, 5), (4, 5, 8)))
"""A unit cube for V-HACD: ~0.1 s where the U takes seconds (the probe is that it runs and writes parts)."""

XACRO = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="probe">
  <xacro:property name="length" value="0.5"/>
  <xacro:macro name="segment" params="name"><link name="${name}"/></xacro:macro>
  <xacro:segment name="base_${length * 2}"/>
</robot>
"""


def _version(distribution: str) -> str:
    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return "missing"


def declared_requirement(distribution: str) -> str:
    """``distribution`` with the bounds installed ar3cli declares (``scipy>=1.10,<2``), for a pip command."""
    try:
        requirements = importlib.metadata.requires("ar3cli") or []
    except importlib.metadata.PackageNotFoundError:
        requirements = []
    key = _normalise(distribution)
    for requirement in requirements:
        name = re.match(r"[A-Za-z0-9._-]+", requirement)
        if name and _normalise(name.group()) == key and "extra ==" not in requirement:
            return requirement.split(";")[0].replace(" ", "")
    return distribution


MODULE_DISTRIBUTIONS = {"collada": "pycollada", "PIL": "pillow", "yaml": "pyyaml"}
"""Import names that differ from their distribution's, for when the distribution is not installed
(``importlib.metadata.packages_distributions`` knows only installed ones)."""


def fix_command(capability: Capability, exc: BaseException) -> str:
    """The pip command that gives a failed required capability what it lacks: the distribution or
    module the error names, else the needed distributions that are not installed, else a reinstall of all of them."""
    suggested = re.search(r"pip install ([A-Za-z0-9_.-]+)", str(exc))  # trimesh's own "missing `pip install X`"
    if suggested:
        return f"pip install '{declared_requirement(suggested.group(1))}'"
    named = re.search(r"No module named '([\w.]+)'|import of ([\w.]+) halted", str(exc))
    module = getattr(exc, "name", None) or (named and (named.group(1) or named.group(2)))
    if module:
        top = module.partition(".")[0]
        installed = importlib.metadata.packages_distributions().get(top, [])
        wanted = [installed[0] if installed else MODULE_DISTRIBUTIONS.get(top, top)]
        return "pip install " + " ".join(f"'{declared_requirement(name)}'" for name in wanted)
    missing = [name for name in capability.needs if _version(name) == "missing"]
    if missing:
        return "pip install " + " ".join(f"'{declared_requirement(name)}'" for name in missing)
    everything = " ".join(f"'{declared_requirement(name)}'" for name in capability.needs) or "ar3cli"
    return f"pip install --force-reinstall {everything}"


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _load_mesh(path: Path):
    from ar3cli.infra.held_import import import_holding_interrupts

    trimesh = import_holding_interrupts("trimesh")

    return trimesh.load(str(path), force="mesh", process=True)


def probe_collada(folder: Path) -> str:
    path = folder / "cube.dae"
    path.write_text(CUBE_DAE, encoding="utf-8")
    mesh = _load_mesh(path)
    if len(mesh.faces) != 12 or abs(abs(float(mesh.volume)) - 8.0) > 1e-6:
        raise ValueError(f"a 12-triangle cube read as {len(mesh.faces)} triangles, volume {float(mesh.volume):.6g}")
    return f"trimesh {_version('trimesh')} + pycollada {_version('pycollada')}: a .dae cube read, exact volume"


def probe_stl_obj(folder: Path) -> str:
    from ar3cli.urdf.meshinfo import mesh_bounds

    obj = folder / "u.obj"
    obj.write_text(U_OBJ, encoding="utf-8")
    stl = folder / "u.stl"
    _load_mesh(obj).export(str(stl))
    counts = [len(_load_mesh(path).faces) for path in (obj, stl)]
    if counts != [28, 28] or mesh_bounds(stl) is None or mesh_bounds(obj) is None:
        raise ValueError(f"a 28-triangle mesh read as {counts} triangles (OBJ, STL)")
    return f"trimesh {_version('trimesh')}: OBJ and binary STL read and written, bounds by ar3cli's reader"


def probe_hull(folder: Path) -> str:
    obj = folder / "u.obj"
    obj.write_text(U_OBJ, encoding="utf-8")
    hull = _load_mesh(obj).convex_hull
    if abs(float(hull.volume) - 9.0) > 1e-6:
        raise ValueError(f"the hull of a 3 x 3 x 1 U has volume {float(hull.volume):.6g}, not 9")
    return f"scipy {_version('scipy')} (Qhull through trimesh): the hull of a U, exact volume"


def probe_vhacd(folder: Path) -> str:
    from ar3cli.sim.capture import capture_fds
    from ar3cli.sim.session import import_pybullet

    p = import_pybullet()
    source, target, log = folder / "cube.obj", folder / "parts.obj", folder / "vhacd.log"
    source.write_text(CUBE_OBJ, encoding="utf-8")
    with capture_fds():
        p.vhacd(str(source), str(target), str(log), resolution=10_000)
    text = target.read_text(encoding="utf-8", errors="replace") if target.is_file() else ""
    parts = len(re.findall(r"^o ", text, flags=re.MULTILINE))
    if parts < 1:
        raise ValueError("pybullet's vhacd wrote no part")
    return f"pybullet {_version('pybullet')} V-HACD: a cube decomposed into {parts} convex part(s)"


def probe_coacd(folder: Path) -> str:
    import coacd  # noqa: F401 - the probe is that it imports

    return f"coacd {_version('coacd')}: fix-collision --method auto uses it"


def probe_xacro(folder: Path) -> str:
    from ar3cli.urdf.packages import PackageResolver
    from ar3cli.urdf.xacro_expand import expand

    path = folder / "probe.urdf.xacro"
    path.write_text(XACRO, encoding="utf-8")
    text = expand(path, {}, PackageResolver(folder)).decode("utf-8")
    if 'name="base_1.0"' not in text:
        raise ValueError("a macro with a property expanded to the wrong URDF")
    return f"xacro {_version('xacro')}: a macro and a property expanded in-process (no ROS needed)"


def probe_png(folder: Path) -> str:
    from PIL import Image, ImageDraw, ImageFont

    image = Image.new("RGB", (16, 16), "white")
    ImageDraw.Draw(image).text((1, 1), "a", fill="black", font=ImageFont.load_default())
    image.save(folder / "probe.png")
    if (folder / "probe.png").read_bytes()[:4] != b"\x89PNG":
        raise ValueError("the PNG written has no PNG signature")
    return f"pillow {_version('pillow')}: PNG with text written (render, info --png, sample-collisions --png)"


def probe_toml(folder: Path) -> str:
    try:
        import tomllib
        reader = "tomllib"
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
        reader = f"tomli {_version('tomli')}"
    data = tomllib.loads('[tool.ar3cli.lint]\nignore = ["G008"]\n')
    if data["tool"]["ar3cli"]["lint"]["ignore"] != ["G008"]:
        raise ValueError("a [tool.ar3cli.lint] table read wrong")
    return f"{reader}: [tool.ar3cli.lint] in pyproject.toml is read"


CAPABILITIES: list[Capability] = [
    Capability("STL/OBJ meshes", ("trimesh", "numpy"), "every mesh command", probe_stl_obj),
    Capability("COLLADA meshes", ("trimesh", "pycollada"), "fix-inertia, fix-collision (.dae mass and hulls)",
               probe_collada),
    Capability("convex hulls", ("trimesh", "scipy"), "fix-inertia (open meshes), fix-collision", probe_hull),
    Capability("decomposition (V-HACD)", ("pybullet",), "fix-collision", probe_vhacd),
    Capability("decomposition (CoACD)", ("coacd",), "fix-collision --method coacd", probe_coacd,
               required=False, extra="decompose"),
    Capability("xacro expansion", ("xacro",), "every command on .xacro files", probe_xacro),
    Capability("PNG output", ("pillow",), "render, info --png, sample-collisions --png", probe_png),
    Capability("pyproject config", (), "lint-urdf's [tool.ar3cli.lint]", probe_toml),
]


def capability_check(capability: Capability) -> Callable[[], Check]:
    """The install-check row of ``capability``: ``ok`` with what the probe saw, else ``fail`` (required)
    or ``info`` (an extra), with the pip command that gives it."""

    def run() -> Check:
        try:
            with tempfile.TemporaryDirectory(prefix="ar3cli-doctor-") as folder:
                detail = capability.probe(Path(folder))
        except Exception as exc:  # noqa: BLE001 - whatever the library raises, the row says it and what to run
            reason = f"{type(exc).__name__}: {exc}".strip()
            if not capability.required:
                return Check(capability.name, "info", f"not installed (optional; {capability.used_by})",
                             f"pip install 'ar3cli[{capability.extra}]'")
            return Check(capability.name, "fail", f"does not work ({capability.used_by}): {reason}",
                         fix_command(capability, exc))
        return Check(capability.name, "ok", detail)

    run.__name__ = "check_" + capability.name
    return run


CAPABILITY_CHECKS: list[Callable[[], Check]] = [capability_check(c) for c in CAPABILITIES]
