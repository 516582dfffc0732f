"""The fix-mesh-paths fixer: mesh and texture URIs that work on one machine become ``package://``.

Absolute paths, ``file://`` URIs, ``package:///`` URIs (an empty package name, G002) and paths
relative to the robot file, and ``package://X/...`` URIs found only by PyBullet's fallback search
(X is no package ROS can find: lint-urdf's G009) are rewritten to ``package://NAME/<path relative to DIR>`` for the
``--package NAME=DIR`` whose DIR holds the file the URI points to (the deepest such DIR). Which
file that is, is the model's resolver's answer (:mod:`ar3cli.urdf.packages`, the one every
command uses). ``package:///REST`` is read as ``package://REST`` (its first folder naming the
package, as in Talos' ``package:///example-robot-data/robots/...``), else as a path relative to
the file (PyBullet's reading).

Every rewritten URI is resolved again by a fresh resolver that knows only ``NAME=DIR`` (no
ROS_PACKAGE_PATH, no fallback search counted), and must give the same file, else the element is
left alone and reported. URIs that do not resolve, or point outside every DIR, are reported as
not fixed with the reason. Other ``package://NAME/...`` URIs are left alone.

:func:`verify` loads the written file in PyBullet and checks that every rewritten mesh was
loaded from the file the old URI pointed to.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.fix.driver import Change, Fixer, FixerArgs, FixPlan, Skipped, check_row, verified_in_pybullet
from ar3cli.fix.settings import setting
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.urdf.edits import Document

FILENAME_ELEMENTS = ("mesh", "texture")
"""The URDF elements whose ``filename`` is a URI: ``<mesh>`` in a geometry, ``<texture>`` in a material."""


@dataclass
class MeshPathOptions:
    """fix-mesh-paths' own options (each :func:`~ar3cli.fix.settings.setting` is one), and the packages
    they name."""

    package: list[str] = setting(
        "--package", metavar="NAME=DIR",
        help="The package the meshes belong to: a URI whose file lies under DIR becomes "
             "package://NAME/PATH, PATH relative to DIR (repeatable; required).")
    verify: bool = setting("--verify/--no-verify", default=True,
                           help="After writing, load the result in PyBullet and check each rewritten mesh "
                                "comes from the same file.")
    packages: dict[str, Path] = field(default_factory=dict, init=False)
    """NAME -> DIR, in the order given."""

    def __post_init__(self) -> None:
        self.packages = parse_packages(self.package)


@contextlib.contextmanager
def with_packages(options: MeshPathOptions, args: FixerArgs) -> Iterator[FixerArgs]:
    """The run of fix-mesh-paths: every ``--package NAME=DIR`` is also a ``--package-path``, so the
    model resolves the URIs the fix writes (given before the user's own ``--package-path``)."""
    specs = [f"{name}={folder}" for name, folder in options.packages.items()]
    yield replace(args, package_path=specs + list(args.package_path or []))


def parse_packages(items: list[str] | None) -> dict[str, Path]:
    """``--package NAME=DIR`` options as a mapping; a malformed item or a missing DIR is a UserError."""
    packages: dict[str, Path] = {}
    for item in items or []:
        name, sep, folder = item.partition("=")
        name, folder = name.strip(), folder.strip()
        if not sep or not name or not folder:
            raise UserError(f"--package expects NAME=DIR, got {item!r}")
        if "/" in name or "\\" in name:
            raise UserError(f"--package {item}: a package name has no slash")
        path = Path(folder).expanduser()
        if not path.is_dir():
            raise UserError(f"--package {item}: {folder} is not a folder")
        if name in packages and packages[name] != path:
            raise UserError(f"--package {name} given twice with different folders")
        packages[name] = path
    if not packages:
        raise UserError("give at least one --package NAME=DIR (the package the meshes belong to)")
    return packages


def uri_kind(uri: str) -> str | None:
    """What is machine-bound about ``uri``: ``absolute``, ``file://``, ``package:///``, ``relative``,
    or None for a URI to leave alone (``package://NAME/...``, another scheme, empty)."""
    uri = uri.strip()
    if not uri:
        return None
    if uri.startswith("package:///"):
        return "package:///"
    if uri.startswith("file://"):
        return "file://"
    if "://" in uri:
        return None
    return "absolute" if Path(uri).is_absolute() else "relative"


def plan_mesh_paths(model, document: Document, options: MeshPathOptions) -> FixPlan:
    from ar3cli.urdf.packages import PackageResolver

    plan = FixPlan(context={"meshes": []})
    folders = {name: folder.resolve() for name, folder in options.packages.items()}
    fresh = {name: PackageResolver(model.path.parent, {name: folder}, environ={})
             for name, folder in options.packages.items()}
    for element in model.root.iter(*FILENAME_ELEMENTS):
        uri = element.get("filename")
        kind = uri_kind(uri or "") or _pybullet_only(model, uri or "")
        if kind is None:
            continue
        where, line = describe(element), element.sourceline or 0
        resolution = _resolve(model, uri, kind)
        if not resolution.found:
            plan.skipped.append(Skipped(where, line, f"{kind} URI does not resolve: {resolution.explain()}"))
            continue
        target = resolution.path.resolve()
        owner = _owner(target, folders)
        if owner is None and kind == PYBULLET_ONLY:
            continue  # package://X/... of a package outside the ones given: X may be a package ROS finds
        if owner is None:
            given = ", ".join(f"{name}={folder}" for name, folder in options.packages.items())
            shown = uri.strip() if Path(uri.strip()) == target else f"{uri.strip()} is {target}"
            plan.skipped.append(Skipped(where, line, f"{shown}: outside every --package folder ({given}); pass "
                                                     "--package NAME=DIR for the package that holds it"))
            continue
        name = owner
        new = f"package://{name}/{target.relative_to(folders[name]).as_posix()}"
        check = fresh[name].resolve(new)
        if not check.found or check.via != "package" or check.path.resolve() != target:
            got = check.path if check.found else check.explain()
            plan.skipped.append(Skipped(where, line, f"{new} would not resolve to {target} with "
                                                     f"--package-path {name}={options.packages[name]} (got {got}); "
                                                     "left as it is"))
            continue
        refused = document.refusal(element, ("filename",), same_for_every_use=True)
        if refused is not None:
            plan.skipped.append(Skipped(where, line, refused))
            continue
        document.set_attribute(document.span(element), "filename", new)
        plan.changes.append(Change(where, line, f"{element.tag} filename", uri, new,
                                   f"{kind} path, file under --package {name}"))
        plan.context["meshes"].append({"element": where, "tag": element.tag, "link": _link_name(element),
                                       "role": _role(element), "file": str(target)})
    return plan


PYBULLET_ONLY = "pybullet-only package://"
"""The kind of a ``package://X/...`` URI that only PyBullet's fallback search finds (G009)."""


def _pybullet_only(model, uri: str) -> str | None:
    """:data:`PYBULLET_ONLY` when ``uri`` is ``package://X/...`` and only PyBullet's fallback search finds it."""
    if not uri.strip().startswith("package://"):
        return None
    return PYBULLET_ONLY if model.resolver.resolve(uri).via == "pybullet-search" else None


def _resolve(model, uri: str, kind: str):
    """The model resolver's answer; ``package:///NAME/x`` first as ``package://NAME/x``, then as the
    relative path ``NAME/x`` (PyBullet's reading)."""
    if kind != "package:///":
        return model.resolver.resolve(uri)
    rest = uri.strip()[len("package:///"):]
    as_package = model.resolver.resolve("package://" + rest)
    if as_package.found:
        return as_package
    as_relative = model.resolver.resolve(rest)
    return as_relative if as_relative.found else as_package


def _owner(target: Path, folders: dict[str, Path]) -> str | None:
    """The package whose folder holds ``target`` (the deepest one when folders nest)."""
    owners = [name for name, folder in folders.items() if target.is_relative_to(folder)]
    return max(owners, key=lambda name: len(folders[name].parts)) if owners else None


def _ancestor(element, tag: str):
    element = element.getparent()
    while element is not None and element.tag != tag:
        element = element.getparent()
    return element


def _link_name(element) -> str | None:
    link = _ancestor(element, "link")
    return link.get("name", "") if link is not None else None


def _role(element) -> str | None:
    for role in ("visual", "collision"):
        if _ancestor(element, role) is not None:
            return role
    return None


def describe(element) -> str:
    """``link base visual``, ``link base collision 2`` (the second of several), ``material red``."""
    link, role = _ancestor(element, "link"), _role(element)
    if link is None:
        material = _ancestor(element, "material")
        return f"material {material.get('name', '')}" if material is not None else element.tag
    text = f"link {link.get('name', '')}"
    if role is not None:
        shape = _ancestor(element, role)
        siblings = link.findall(role)
        text += f" {role}" + (f" {siblings.index(shape) + 1}" if len(siblings) > 1 else "")
    return text


# ---- verification in PyBullet -----------------------------------------------------------------
def verify(model, plan: FixPlan) -> dict:
    """Load the fixed file in PyBullet; every rewritten visual/collision mesh must be loaded from the
    file its old URI pointed to (pybullet's getVisualShapeData / getCollisionShapeData)."""
    meshes = [m for m in plan.context.get("meshes", []) if m["tag"] == "mesh" and m["link"] is not None]
    return verified_in_pybullet(model, lambda: _checks_in_pybullet(model, meshes), nothing_changed=not meshes)


def _checks_in_pybullet(model, meshes: list[dict]) -> list[dict]:
    from ar3cli.sim.session import Session

    with Session() as session:
        body = session.load(model, visuals=True, allow_nan_frames=True)
        p, client = session.p, session.client
        index = body.link_index  # link name -> pybullet index, -1 for the base
        loaded: dict[tuple[str, int], set[str]] = {}
        for shape in p.getVisualShapeData(body.id, physicsClientId=client):
            loaded.setdefault(("visual", shape[1]), set()).add(_real(shape[4]))
        for link_index in index.values():
            for shape in p.getCollisionShapeData(body.id, link_index, physicsClientId=client):
                loaded.setdefault(("collision", link_index), set()).add(_real(shape[4]))
        checks: list[dict] = []
        for mesh in meshes:
            if mesh["link"] not in index:
                checks.append(check_row(mesh["element"], "mesh loaded", False, "link not found in pybullet"))
                continue
            if mesh["file"] not in loaded.get((mesh["role"], index[mesh["link"]]), set()):
                checks.append(check_row(mesh["element"], "mesh loaded", False,
                                     f"pybullet has no {mesh['role']} shape from {mesh['file']}"))
    count = len(meshes)
    summary = check_row("all rewritten meshes", "mesh loaded", True,
                     f"{count} rewritten mesh URI(s): pybullet loaded each from the file the old URI named")
    return checks or [summary]


def _real(name: bytes) -> str:
    text = name.decode("utf-8", "replace") if isinstance(name, bytes) else str(name)
    return str(Path(text).resolve()) if text else ""


FIXER = Fixer[MeshPathOptions]("fix-mesh-paths", plan_mesh_paths, verify, options=MeshPathOptions,
                                timeout=DEFAULT_TIMEOUT_S, session=with_packages, edits_xacro=True, help="""\
Rewrite machine-bound mesh and texture URIs to `package://NAME/...`, byte for byte, atomically.

Absolute paths, `file://` URIs, `package:///` URIs (no package name), paths relative to the
URDF and `package://X/...` URIs only PyBullet's fallback search finds (G009) are rewritten
when the file they point to lies under a --package DIR, after checking
that the new URI resolves to the same file with `--package-path NAME=DIR`. URIs that do not
resolve, or point outside every DIR, are reported and left alone.
""")
"""``ar3cli fix-mesh-paths``: :func:`plan_mesh_paths` inside :func:`with_packages`, then :func:`verify`
with ``--verify``."""
