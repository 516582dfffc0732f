"""The fix-collision fixer: collision meshes that collide as a much larger convex hull.

A moving link's mesh collides in PyBullet as its convex hull. When ``hull volume / mesh volume``
is above ``--max-hull-ratio`` (default :data:`MAX_HULL_RATIO`; the mesh must be closed to have a
volume), that ``<collision>`` is replaced by one ``<collision>`` per convex part of a decomposition
(:mod:`ar3cli.fix.decompose`). Each new element is a byte copy of the old one with only the mesh
``filename`` changed (and ``_part_NN`` added to a ``name``), so ``<origin>``, ``scale`` and the
formatting stay. The part files are written in the source mesh's units (the kept ``scale`` applies
to them) into ``<folder of the written URDF>/collision/<link>/part_NN.obj``, named relative to
the URDF, or ``package://NAME/...`` when the old mesh was a ``package://`` URI and the folder lies
inside that package.

``--from-visual``: a link with ``<visual>`` but no ``<collision>`` gets collisions from its visuals:
a primitive copied as it is, a mesh as its convex hull (one part file), or decomposed when its hull
ratio is above the threshold.

Part files are written when the plan is made, before the URDF (so the URDF never names a file that
is not there, and the static lint of the result finds them); with ``--diff``/``--check`` they go to a
temporary folder the command removes. :func:`verify` loads the written URDF in PyBullet and checks
that each changed link has one collision shape per part, loaded from the part files.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.fix.driver import Change, Fixer, FixerArgs, FixPlan, Skipped, check_row, verified_in_pybullet
from ar3cli.fix.settings import setting
from ar3cli.infra.child_limits import LONG_TIMEOUT_S
from ar3cli.urdf.edits import Document, Span

MAX_HULL_RATIO = 2.0
"""hull/mesh volume above which a collision mesh is decomposed. A convex mesh is 1; the AR3's
own links measure 1.1 to 1.6 (blocky castings); a U or L whose hull doubles its volume collides
as a solid block where half of it is air."""
PARTS_FOLDER = "collision"
"""Folder beside the written URDF that holds ``<link>/part_NN.obj``."""
VERIFY_SAMPLES = 300
"""Configurations sampled (``--seed``-ed) to compare every pair's category before and after the fix:
enough to see a pair that starts colliding often, few enough to keep the check to seconds."""
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")
_PART_FILE = re.compile(r"part_(\d+)\.obj$")


@dataclass
class CollisionOptions:
    """fix-collision's own options (each :func:`~ar3cli.fix.settings.setting` is one), then the
    run's state: where part files go and which were created."""

    max_hull_ratio: float = setting(
        "--max-hull-ratio", default=MAX_HULL_RATIO,
        help="Decompose a collision mesh whose convex hull has more than this many times its volume (the mesh "
             "must be closed).")
    method: str = setting(
        "--method", default="auto",
        help="coacd, vhacd (pybullet's), or auto: coacd when installed (pip install 'ar3cli[decompose]'), "
             "else vhacd.")
    """After ``__post_init__``: ``vhacd`` or ``coacd``."""
    resolution: int = setting("--resolution", default=100_000, minimum=10_000, maximum=64_000_000,
                              help="vhacd's voxel count: higher is finer and slower.")
    from_visual: bool = setting(
        "--from-visual", default=False,
        help="Links with a `<visual>` but no `<collision>` get one: a primitive copied, a mesh as its convex "
             "hull (decomposed when its hull ratio is above the limit).")
    verify: bool = setting(
        "--verify/--no-verify", default=True,
        help="Compare the original and the fixed robot in PyBullet (home contacts and sampled pair categories; "
             "a decomposition that makes a pair collide more is refused), and after writing count each "
             "changed link's collision shapes.")
    samples: int = setting("--samples", "-n", default=VERIFY_SAMPLES, minimum=1, maximum=100_000,
                           help="Configurations sampled to compare pair categories before and after the fix.")
    seed: int = setting(default=0)
    output: Path | None = None
    write: bool = False
    """True when the URDF will be written: parts go to their final folder, else to ``staging``."""
    staging: Path | None = None
    created: dict[Path, list[Path]] = field(default_factory=dict)
    """Per written URDF path: files and folders created for it (removed again if it is not written)."""
    originals: dict[Path, bytes] = field(default_factory=dict)
    decompositions: dict = field(default_factory=dict)
    """Raw decompositions by mesh file and parameters (:func:`~ar3cli.fix.decompose.decompose`'s cache)."""
    follow_symlinks: bool = False
    """Write a symlinked URDF's target (``--follow-symlinks``); part folders never leave the URDF's folder."""

    def __post_init__(self) -> None:
        if not self.max_hull_ratio > 1.0:
            raise UserError(f"--max-hull-ratio {self.max_hull_ratio}: must be above 1 (a convex mesh is 1)")
        from ar3cli.fix.decompose import resolve_method  # numpy: when the command runs, not for --help

        self.method = resolve_method(self.method)

    def rollback(self) -> None:
        """Remove the part files of every URDF that was not rewritten (the run failed before it)."""
        for target, paths in self.created.items():
            try:
                unchanged = target.read_bytes() == self.originals.get(target)
            except OSError:
                unchanged = True  # an -o target that was never written
            if not unchanged:
                continue
            for path in reversed(paths):
                if path.is_dir():
                    _remove_empty(path)
                else:
                    path.unlink(missing_ok=True)


def _remove_empty(folder: Path) -> None:
    with contextlib.suppress(OSError):  # not empty: someone else's files are there too
        folder.rmdir()


@dataclass
class _Writer:
    """Places part files for one URDF: final folder (write mode) or staging, names, URIs."""

    options: CollisionOptions
    target: Path
    model: object
    used: dict[str, set[int]] = field(default_factory=dict)

    @property
    def root(self) -> Path:
        return self.target.parent / PARTS_FOLDER

    def folder(self, link: str) -> Path:
        return self.root / (_UNSAFE.sub("_", link).strip(".") or "link")

    def _where(self, link: str) -> Path:
        """Where the files go now: the final folder, or its mirror in the staging folder."""
        final = self.folder(link)
        if self.options.write:
            return final
        assert self.options.staging is not None
        tag = hashlib.sha1(str(self.target).encode()).hexdigest()[:12]  # one staging folder per URDF
        return self.options.staging / tag / final.relative_to(self.target.parent)

    def next_names(self, link: str, count: int) -> list[str]:
        """``part_NN.obj`` names not yet on disk in the link's folder nor given out in this run."""
        used = self.used.setdefault(link, set())
        folder = self.folder(link)
        if folder.is_dir():
            used.update(int(m.group(1)) for p in folder.iterdir() if (m := _PART_FILE.match(p.name)))
        names, index = [], 0
        while len(names) < count:
            if index not in used:
                used.add(index)
                names.append(f"part_{index:02d}.obj")
            index += 1
        return names

    def write(self, link: str, names: list[str], texts: list[str]) -> list[Path]:
        """Write the part files (atomically, never through a link); the paths written."""
        from ar3cli.infra.atomic import atomic_write, check_writable

        folder = self._where(link)
        created = self.options.created.setdefault(self.target, [])
        if self.options.write and not created:  # the first file for this URDF: may it be rewritten at all?
            check_writable(self.options.output or self.model.path, self.options.follow_symlinks)
        missing = [p for p in (folder.parent, folder) if not p.exists() and not p.is_symlink()]
        self._refuse_leaving(folder)
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise UserError(f"{folder}: cannot create the folder for the parts: {exc.strerror or exc}") from None
        self._refuse_leaving(folder)
        if self.options.write:
            created.extend(missing)
        paths = []
        for name, text in zip(names, texts):
            path = folder / name
            atomic_write(path, text.encode("utf-8"))
            paths.append(path)
            if self.options.write:
                created.append(path)
        return paths

    def _refuse_leaving(self, folder: Path) -> None:
        """UserError when ``collision/`` or ``collision/<link>/`` is a link that leads out of the
        URDF's folder (planted in a pull request, it would make ar3cli write anywhere)."""
        if not self.options.write:
            return  # the staging folder is ar3cli's own
        home = Path(os.path.realpath(self.target.parent))
        for step in (folder.parent, folder):
            if step.is_symlink() and not Path(os.path.realpath(step)).is_relative_to(home):
                raise UserError(f"{step}: is a symbolic link to {os.path.realpath(step)}, outside {home}; "
                                "ar3cli writes part files only inside the URDF's folder: remove the link")

    def uri(self, link: str, name: str, old_uri: str | None, old_resolution) -> str:
        """The ``filename`` for a part: relative to the URDF, or package:// like the old one."""
        final = self.folder(link) / name
        if old_uri and old_uri.strip().startswith("package://") and old_resolution is not None \
                and old_resolution.via == "package":
            package = old_uri.strip()[len("package://"):].partition("/")[0]
            root, _ = self.model.resolver.find_package(package)
            if root is not None:
                root = Path(os.path.realpath(root))
                if final.is_relative_to(root):
                    return f"package://{package}/{final.relative_to(root).as_posix()}"
        return final.relative_to(self.target.parent).as_posix()


def plan_collisions(model, document: Document, options: CollisionOptions) -> FixPlan:
    from ar3cli.fix.decompose import MeshProblem, measure

    plan = FixPlan(context={"links": {}, "path": model.path}, data={"collisions": []})
    target = Path(os.path.realpath(options.output or model.path))
    pending: list[_Replacement] = []
    inserts: list = []
    options.originals.setdefault(target, target.read_bytes() if target.is_file() else b"")
    writer = _Writer(options, target, model)
    measures: dict[tuple[str, tuple], object] = {}

    def measured(shape):
        geometry = shape.geometry
        key = (str(geometry.resolution.path), tuple(geometry.params["scale"]))
        if key not in measures:
            try:
                measures[key] = measure(Path(geometry.resolution.path), key[1])
            except MeshProblem as exc:
                measures[key] = exc
        return measures[key]

    for link in model.links:
        for shape in link.collisions:
            geometry = shape.geometry
            if geometry.kind != "mesh" or geometry.resolution is None or not geometry.resolution.found \
                    or geometry.params.get("scale") is None:
                continue  # a missing mesh or a bad scale is lint-urdf's G001 / G-rules, not ours
            result = measured(shape)
            row = _row(link, shape, result)
            if isinstance(result, MeshProblem):
                row["action"] = f"left alone: {result}"
            elif result.ratio is None:
                row["action"] = "left alone: open surface, no volume to compare the hull with"
            elif result.ratio <= options.max_hull_ratio:
                row["action"] = "left alone: hull ratio within the limit"
            else:
                _replace_collision(document, plan, writer, link, shape, result, row, options, pending)
            plan.data["collisions"].append(row)
        if options.from_visual and not link.collisions and link.visuals:
            _from_visuals(document, plan, writer, link, measured, options, inserts)
    if pending and options.verify and options.write:
        from ar3cli.fix.collision_compare import accept_replacements

        accepted = accept_replacements(model, target, pending, inserts, plan, options)
    else:
        accepted = pending
    for insert in inserts:
        insert(document)
    for replacement in pending:
        if replacement in accepted:
            replacement.accept(document, plan)
        else:
            replacement.refuse(plan, options)
    _summary_notes(plan, model.path, options)
    return plan


@dataclass
class _Replacement:
    """One collision mesh's decomposition, planned but not yet spliced: the comparison in PyBullet
    may refuse it (the mesh then keeps its original collision)."""

    link: str
    line: int
    row: dict
    splice: tuple[int, int, bytes]
    change: Change
    uris: list[str]
    note: str
    files: list[Path]
    refused_because: str = ""

    def accept(self, document: Document, plan: FixPlan) -> None:
        document.splice(*self.splice)
        plan.changes.append(self.change)
        plan.notes.append(self.note)
        plan.context["links"][self.link] = self.uris
        self.row.update(action="decomposed", files=self.uris)

    def refuse(self, plan: FixPlan, options: CollisionOptions) -> None:
        """Keep the original collision; remove the part files written for it."""
        self.row.update(action=f"refused: {self.refused_because}", files=[])
        plan.skipped.append(Skipped(f"link {self.link}", self.line, f"decomposition refused: {self.refused_because}; "
                                    "the original collision mesh is kept"))
        created = options.created.get(Path(os.path.realpath(options.output or plan.context["path"])), [])
        for path in self.files:
            path.unlink(missing_ok=True)
            if path in created:
                created.remove(path)
        for folder in {path.parent for path in self.files}:
            if folder in created:  # made for these parts alone: remove it when nothing else is in it
                _remove_empty(folder)
                if not folder.exists():
                    created.remove(folder)


def _summary_notes(plan: FixPlan, path: Path, options: CollisionOptions) -> None:
    rows = plan.data["collisions"]
    within = [r for r in rows if r["action"] == "left alone: hull ratio within the limit"]
    other = [r for r in rows if r["action"].startswith("left alone:") and r not in within]
    if within:
        worst = max(r["hull_ratio_before"] for r in within)
        plan.notes.append(f"{path}: {len(within)} collision mesh(es) left alone: hull/mesh at most {worst:.2f}, "
                          f"within --max-hull-ratio {options.max_hull_ratio:g}")
    for r in other:
        plan.notes.append(f"{path}: link {r['link']} collision mesh {r['mesh']} {r['action']}")
    if not options.write and plan.context["links"]:
        plan.notes.append(f"{path}: the part files are not written with --diff/--check, so the lint of the "
                          "result below counts them as missing (G001)")


def _row(link, shape, result) -> dict:
    from ar3cli.fix.decompose import MeshProblem

    row = {"link": link.name, "role": shape.role, "line": shape.element.sourceline or link.line,
           "mesh": shape.geometry.filename, "mesh_volume": None, "hull_volume_before": None,
           "hull_ratio_before": None, "action": "", "method": None, "parts": None, "files": [],
           "hull_volume_after": None, "hull_ratio_after": None, "seconds": None}
    if not isinstance(result, MeshProblem):
        row.update(mesh_volume=result.mesh_volume, hull_volume_before=result.hull_volume,
                   hull_ratio_before=result.ratio)
    return row


def _decompose(plan: FixPlan, writer: _Writer, link, shape, result, row: dict,
               options: CollisionOptions) -> tuple[list[str], list[Path]] | None:
    """Decompose one mesh, write its parts; the part file names and paths, or None (reported as
    not fixed). Its note (what the decomposition gained) is the last of ``plan.notes``."""
    from ar3cli.fix.decompose import decompose, obj_text

    geometry = shape.geometry
    path = Path(geometry.resolution.path)
    element = f"link {link.name}"
    line = row["line"]
    try:
        decomposition = decompose(result, options.method, str(path), tuple(geometry.params["scale"]),
                                  options.resolution, options.decompositions)
    except UserError as exc:  # a crash of the C++ code, one line
        plan.skipped.append(Skipped(element, line, f"{options.method} failed: {exc.message}"))
        row["action"] = "not fixed: decomposition failed"
        return None
    parts = decomposition.parts
    row.update(method=decomposition.parameters, seconds=round(decomposition.seconds, 3), reused=decomposition.reused)
    if len(parts) < 2 or not decomposition.hull_volume < result.hull_volume:
        plan.skipped.append(Skipped(element, line, f"{decomposition.parameters} gave {len(parts)} part(s) "
                                    f"with a hull volume of {decomposition.hull_volume:.4g} m^3 against "
                                    f"{result.hull_volume:.4g} m^3 before: nothing gained; try --method coacd "
                                    "or a higher --resolution, or simplify the mesh by hand"))
        row["action"] = "not fixed: no better decomposition"
        return None
    names = writer.next_names(link.name, len(parts))
    texts = [obj_text(part.vertices, part.faces, f"ar3cli fix-collision: convex part {i + 1} of {len(parts)} "
                      f"of {path.name} ({decomposition.parameters})", name.removesuffix(".obj"))
             for i, (part, name) in enumerate(zip(parts, names))]
    files = writer.write(link.name, names, texts)
    row.update(parts=len(parts), hull_volume_after=decomposition.hull_volume,
               hull_ratio_after=decomposition.hull_volume / result.mesh_volume)
    took = "the parts computed above" if decomposition.reused else f"{decomposition.seconds:.2f} s"
    plan.notes.append(f"{element}: {path.name} -> {len(parts)} convex parts ({decomposition.parameters}, "
                      f"{took}): hull volume {result.hull_volume:.4g} -> "
                      f"{decomposition.hull_volume:.4g} m^3 against a mesh volume of {result.mesh_volume:.4g} m^3 "
                      f"(hull/mesh {result.ratio:.3g} -> {row['hull_ratio_after']:.3g})")
    return names, files


def _replace_collision(document: Document, plan: FixPlan, writer: _Writer, link, shape, result, row: dict,
                       options: CollisionOptions, pending: list[_Replacement]) -> None:
    """Plan one ``<collision>``'s replacement by its parts (queued on ``pending``, spliced once accepted)."""
    decomposed = _decompose(plan, writer, link, shape, result, row, options)
    if decomposed is None:
        return
    names, files = decomposed
    note = plan.notes.pop()
    geometry = shape.geometry
    uris = [writer.uri(link.name, name, geometry.filename, geometry.resolution) for name in names]
    span = document.span(shape.element)
    mesh_span = document.span(geometry.element)
    filename = mesh_span.attributes["filename"]
    name_attribute = span.attributes.get("name")
    original = document.data[span.start:span.end]
    copies = []
    for index, uri in enumerate(uris):
        edits = [(filename.value_start, filename.value_end, _escape(uri, filename.quote))]
        if name_attribute is not None:
            old_name = document.data[name_attribute.value_start:name_attribute.value_end]
            edits.append((name_attribute.value_start, name_attribute.value_end,
                          old_name + f"_part_{index:02d}".encode()))
        copy = original
        for start, end, new in sorted(edits, reverse=True):
            copy = copy[:start - span.start] + new + copy[end - span.start:]
        copies.append(copy)
    separator = document.newline + document.indentation(span)
    change = Change(
        f"link {link.name}", row["line"], "collision mesh", f"{geometry.filename} (hull/mesh {result.ratio:.3g})",
        f"{len(uris)} parts {_folder_of(uris)} (hull/mesh {row['hull_ratio_after']:.3g})",
        f"{row['method']}, {_took(row)}")
    pending.append(_Replacement(link.name, row["line"], row, (span.start, span.end, separator.join(copies)), change,
                                uris, note, files))


def _took(row: dict) -> str:
    return "same parts as above" if row.get("reused") else f"{row['seconds']:.2f} s"


def _folder_of(uris: list[str]) -> str:
    first, last = uris[0], uris[-1]
    folder = first.rpartition("/")[0]
    return f"{folder}/{first.rpartition('/')[2]}..{last.rpartition('/')[2]}" if len(uris) > 1 else first


def _from_visuals(document: Document, plan: FixPlan, writer: _Writer, link, measured,
                  options: CollisionOptions, inserts: list) -> None:
    """Collisions for a link with visuals only, inserted after its last <visual> (queued on
    ``inserts`` as a function of the Document, so the comparison can apply it to a scratch copy)."""
    from ar3cli.fix.decompose import MeshProblem, hull_part, obj_text, scale_factor

    lines: list[str] = []
    uris_all: list[str] = []
    element = f"link {link.name}"
    for shape in link.visuals:
        geometry = shape.geometry
        line = shape.element.sourceline or link.line
        origin = _one_line(document, shape.origin.element) if shape.origin.element is not None else None
        if geometry.kind in ("box", "cylinder", "sphere", "capsule"):
            lines += _collision_lines(origin, _one_line(document, geometry.element))
            plan.changes.append(Change(element, line, "collision (added)", None,
                                       f"<{geometry.kind}> copied from the visual", "--from-visual"))
            continue
        if geometry.kind != "mesh" or geometry.resolution is None or not geometry.resolution.found \
                or geometry.params.get("scale") is None:
            plan.skipped.append(Skipped(element, line, "--from-visual: the visual has no usable geometry "
                                        "(a missing mesh? see ar3cli lint-urdf)"))
            continue
        result = measured(shape)
        row = _row(link, shape, result)
        plan.data["collisions"].append(row)
        if isinstance(result, MeshProblem):
            plan.skipped.append(Skipped(element, line, f"--from-visual: {result}"))
            row["action"] = f"not fixed: {result}"
            continue
        if result.ratio is not None and result.ratio > options.max_hull_ratio:
            decomposed = _decompose(plan, writer, link, shape, result, row, options)
            if decomposed is None:
                continue
            names = decomposed[0]
            source = f"--from-visual, {row['method']}, {_took(row)}"
            what = f"{len(names)} parts (hull/mesh {result.ratio:.3g} -> {row['hull_ratio_after']:.3g})"
        else:
            part = hull_part(result.vertices, result.faces, scale_factor(tuple(geometry.params["scale"])))
            if part is None:
                plan.skipped.append(Skipped(element, line, f"--from-visual: {geometry.filename} has no convex hull"))
                continue
            names = writer.next_names(link.name, 1)
            path = Path(geometry.resolution.path)
            writer.write(link.name, names, [obj_text(part.vertices, part.faces,
                                                     f"ar3cli fix-collision: convex hull of {path.name}", "hull")])
            ratio = "open surface" if result.ratio is None else f"hull/mesh {result.ratio:.3g}"
            what = f"convex hull ({ratio})"
            source = "--from-visual"
            row.update(action="convex hull", parts=1, files=[], hull_volume_after=part.hull_volume,
                       hull_ratio_after=(part.hull_volume / result.mesh_volume) if result.mesh_volume else None)
        uris = [writer.uri(link.name, name, geometry.filename, geometry.resolution) for name in names]
        row["files"] = uris
        if row["action"] != "convex hull":
            row["action"] = "decomposed"
        scale = geometry.element.get("scale")
        for uri in uris:
            attributes = [document.format_attr("filename", uri).decode()]
            if scale is not None:
                attributes.append(document.format_attr("scale", scale).decode())
            lines += _collision_lines(origin, f"<mesh {' '.join(attributes)}/>")
        uris_all += uris
        plan.changes.append(Change(element, line, "collision (added)", None,
                                   f"{what}: {_folder_of(uris)} from {geometry.filename}", source))
    if not lines:
        return
    last_visual = link.visuals[-1].element

    def insert(target: Document) -> None:
        target.insert_child(target.span(link.element), lines, after=target.span(last_visual))

    inserts.append(insert)
    plan.context["links"][link.name] = uris_all or None


def _collision_lines(origin: str | None, shape: str) -> list[str]:
    return ["<collision>", *([f"  {origin}"] if origin else []), "  <geometry>", f"    {shape}", "  </geometry>",
            "</collision>"]


def _one_line(document: Document, element) -> str:
    """The element's own text from the file (quotes and attribute order kept), on one line."""
    span: Span = document.span(element)
    return " ".join(document.data[span.start:span.end].decode("utf-8", "replace").split())


def _escape(value: str, quote: bytes) -> bytes:
    text = value.replace("&", "&amp;").replace("<", "&lt;")
    text = text.replace('"', "&quot;") if quote == b'"' else text.replace("'", "&apos;")
    return text.encode("utf-8")


@contextlib.contextmanager
def staged(options: CollisionOptions, args: FixerArgs) -> Iterator[FixerArgs]:
    """The run of fix-collision: part files are staged in a temporary folder (``--diff``/``--check``)
    or written beside the URDF; afterwards the part files of a URDF that was not rewritten (an error,
    a failed check) and the staging folder are removed, whatever ended the run."""
    options.output, options.write, options.follow_symlinks = args.output, args.writes, args.follow_symlinks
    options.staging = Path(tempfile.mkdtemp(prefix="ar3cli-parts-"))
    try:
        yield args
    finally:
        options.rollback()
        shutil.rmtree(options.staging, ignore_errors=True)


# ---- verification in PyBullet -----------------------------------------------------------------
def verify(model, plan: FixPlan) -> dict:
    """Load the written file in PyBullet (in a child); every changed link must have one collision
    shape per ``<collision>``, the part files among them. The rows of the comparison of the original
    and the fixed robot (:mod:`ar3cli.fix.collision_compare`, made on these same bytes before the
    write) are added, so the table says what was compared."""
    from ar3cli.fix.collision_compare import comparison_rows

    links = plan.context.get("links", {})
    expected = {link.name: len(link.collisions) for link in model.links if link.name in links}
    files = {name: [str(Path(model.resolver.resolve(uri).path or uri).resolve()) for uri in uris or []]
             for name, uris in links.items()}
    result = verified_in_pybullet(model, lambda: _checks_in_pybullet(model, expected, files), nothing_changed=not links)
    rows = comparison_rows(plan.context.get("comparison")) if links else []
    if not rows:
        return result
    return {**result, "checks": result["checks"] + rows,
            "verified": result["verified"] and all(row["status"] == "ok" for row in rows)}


def _checks_in_pybullet(model, expected: dict[str, int], files: dict[str, list[str]]) -> list[dict]:
    from ar3cli.sim.session import Session

    checks = []
    with Session() as session:
        body = session.load(model, visuals=False, allow_nan_frames=True)
        p, client = session.p, session.client
        for name, count in expected.items():
            if name not in body.link_index:
                checks.append(check_row(f"link {name}", "collision shapes", False, "link not found in pybullet"))
                continue
            shapes = p.getCollisionShapeData(body.id, body.link_index[name], physicsClientId=client)
            loaded = {str(Path(s[4].decode("utf-8", "replace")).resolve()) for s in shapes if s[4]}
            missing = [Path(f).name for f in files.get(name, []) if f not in loaded]
            ok = len(shapes) == count and not missing
            detail = f"{len(shapes)} collision shape(s) for {count} <collision>"
            if missing:
                detail += f"; not loaded: {listed(missing)}"
            elif files.get(name):
                detail += f", {len(files[name])} part file(s) loaded"
            checks.append(check_row(f"link {name}", "collision shapes", ok, detail))
    return checks


FIXER = Fixer[CollisionOptions]("fix-collision", plan_collisions, verify, options=CollisionOptions,
                                 timeout=LONG_TIMEOUT_S, session=staged, help="""\
Replace a collision mesh that collides as a much larger convex hull by convex parts.

PyBullet collides a moving link's mesh as its convex hull. Where hull volume / mesh volume is
above --max-hull-ratio, that `<collision>` becomes one `<collision>` per part of a convex
decomposition (CoACD or pybullet's V-HACD), written as OBJ files in
`collision/LINK/` beside the URDF; origin, scale and formatting are kept. With --diff or
--check nothing is written, part files included.
""")
"""``ar3cli fix-collision``: :func:`plan_collisions` inside :func:`staged`, then :func:`verify` with
``--verify``."""
