"""Convex decomposition of a collision mesh, for fix-collision.

PyBullet (like most physics engines) collides a mesh of a moving link as its convex hull, so a
U-shaped gripper finger or an L-shaped bracket collides as the solid block around it. Whether a
mesh suffers from that is measured as ``hull volume / mesh volume`` (:func:`measure`; the mesh
volume needs a closed surface). A decomposition replaces the mesh by a few convex parts whose
hulls hug it:

* ``vhacd``: PyBullet's built-in V-HACD (``p.vhacd``), always available. It reads one OBJ and
  writes one OBJ holding every part as an ``o`` object; :func:`parse_obj_objects` splits it.
  Deterministic for given parameters (two runs give byte-identical output, checked in the tests).
* ``coacd``: CoACD (``pip install coacd``, the ``decompose`` extra), usually fewer, tighter parts;
  run with a fixed seed, so deterministic too.

Both are C++ code that may crash on odd input, so each runs in a forked child
(:func:`ar3cli.infra.isolation.run_isolated`): a crash is one line naming the mesh, and so is a
decomposition that outgrows the child's memory cap or its ``--timeout`` (per mesh; see
:mod:`ar3cli.infra.child_limits`: a high ``--resolution`` takes minutes on a large mesh). Every part is
written as its convex hull (computed with trimesh), so each part's own hull/mesh ratio is 1 and a
second fix-collision run leaves it alone. Parts stay in the source mesh's units: the ``scale`` of
the ``<mesh>`` element is kept and applies to them as it did to the original.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ar3cli.errors import UserError

METHODS = ("auto", "coacd", "vhacd")
VHACD_RESOLUTION = 100_000
"""Voxels of V-HACD's grid (its own default). Measured on the tests' U-shape (hull/mesh 2.74): 4 parts,
hull/mesh 1.16 in 0.4 s; at 20,000 voxels 4 parts, 1.33 in 0.1 s."""
VHACD_CONCAVITY = 0.0025
"""V-HACD's own default maximum concavity (fraction of the mesh's size)."""
COACD_THRESHOLD = 0.05
"""CoACD's own default concavity threshold."""
COACD_SEED = 0
"""Fixed: CoACD's search is random, the same seed gives the same parts."""


class MeshProblem(Exception):
    """The mesh cannot be measured or decomposed (unreadable, empty, ...)."""


@dataclass
class Measure:
    """A mesh in its own units (scale not applied) and its volumes with the scale applied (m^3)."""

    vertices: np.ndarray
    faces: np.ndarray
    closed: bool
    mesh_volume: float | None
    """None when the surface is open (no volume to compare the hull with)."""
    hull_volume: float

    @property
    def ratio(self) -> float | None:
        if self.mesh_volume is None or not self.mesh_volume > 0:
            return None
        return self.hull_volume / self.mesh_volume


@dataclass
class Part:
    """One convex part, in the source mesh's units."""

    vertices: np.ndarray
    faces: np.ndarray
    hull_volume: float
    """With the scale applied (m^3)."""


@dataclass
class Decomposition:
    method: str
    parts: list[Part] = field(default_factory=list)
    seconds: float = 0.0
    parameters: str = ""
    reused: bool = False
    """The parts of an earlier decomposition of the same file in this run (``seconds`` is 0)."""

    @property
    def hull_volume(self) -> float:
        return sum(part.hull_volume for part in self.parts)


def scale_factor(scale: tuple[float, ...]) -> float:
    """How much a ``scale`` multiplies volumes: |sx * sy * sz|."""
    return abs(float(np.prod(scale)))


def measure(path: Path, scale: tuple[float, ...]) -> Measure:
    """Load a mesh (vertices welded by position) and measure its volume and its hull's volume.

    ``hull / mesh`` does not depend on the scale (a linear map multiplies both volumes by the same
    determinant); the volumes reported are scaled.
    """
    from ar3cli.fix.geometry_mass import GeometryError, is_closed, load_welded_mesh

    try:
        mesh = load_welded_mesh(path)
    except GeometryError as exc:
        raise MeshProblem(str(exc).removeprefix("mesh ")) from None
    factor = scale_factor(scale)
    closed = bool(mesh.is_watertight or is_closed(mesh))
    mesh_volume = abs(float(mesh.volume)) * factor if closed else None
    try:
        hull_volume = float(mesh.convex_hull.volume) * factor
    except Exception as exc:  # noqa: BLE001 - qhull fails on flat or degenerate input
        raise MeshProblem(f"{path.name}: no convex hull ({exc})") from None
    return Measure(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64), closed,
                   mesh_volume, hull_volume)


def coacd_available() -> bool:
    import importlib.util

    return importlib.util.find_spec("coacd") is not None


def resolve_method(method: str) -> str:
    """``auto`` -> coacd when it is installed, else vhacd; ``coacd`` without it is a UserError."""
    if method not in METHODS:
        raise UserError(f"--method {method}: expected one of {', '.join(METHODS)}")
    if method == "auto":
        return "coacd" if coacd_available() else "vhacd"
    if method == "coacd" and not coacd_available():
        raise UserError("--method coacd: CoACD is not installed; run: pip install 'ar3cli[decompose]' "
                        "(or pip install coacd), or use --method vhacd")
    return method


def hull_part(vertices: np.ndarray, faces: np.ndarray, factor: float) -> Part | None:
    """The convex hull of a point set as a :class:`Part`; None when it encloses no volume."""
    from ar3cli.infra.held_import import import_holding_interrupts

    trimesh = import_holding_interrupts("trimesh")

    try:
        hull = trimesh.Trimesh(vertices=vertices, faces=faces, process=True).convex_hull
    except Exception:  # noqa: BLE001 - qhull fails on flat or degenerate input
        return None
    volume = float(hull.volume)
    if not volume > 0:
        return None
    return Part(np.asarray(hull.vertices, dtype=float), np.asarray(hull.faces, dtype=np.int64), volume * factor)


def decompose(mesh: Measure, method: str, subject: str, scale: tuple[float, ...],
              resolution: int = VHACD_RESOLUTION, cache: dict | None = None) -> Decomposition:
    """Decompose ``mesh`` with ``method`` (``vhacd`` or ``coacd``) in a forked child; each part
    comes back as its convex hull. A crash of the C++ code is a one-line UserError naming
    ``subject`` (the mesh file). ``cache`` (keyed by subject and parameters) lets a mesh named
    by several links, or by a visual and a collision, be decomposed once: the parts are in the
    mesh's own units, so only their volumes depend on ``scale``."""
    from ar3cli.infra.isolation import run_isolated
    from ar3cli.output.report import log

    vertices, faces = mesh.vertices, mesh.faces
    if method == "vhacd":
        parameters = f"vhacd resolution {resolution}"

        def work() -> list[tuple[np.ndarray, np.ndarray]]:
            return _vhacd(vertices, faces, resolution)
    else:
        parameters = f"coacd threshold {COACD_THRESHOLD} seed {COACD_SEED}"

        def work() -> list[tuple[np.ndarray, np.ndarray]]:
            return _coacd(vertices, faces)

    key = (subject, parameters)
    reused = cache is not None and key in cache
    if reused:
        hulls, seconds = cache[key][0], 0.0
    else:
        log(f"fix-collision: decomposing {Path(subject).name} with {parameters}...")
        start = time.perf_counter()
        raw = run_isolated(work, subject)
        hulls = [part for part in (hull_part(v, f, 1.0) for v, f in raw) if part is not None]
        seconds = time.perf_counter() - start
        if cache is not None:
            cache[key] = (hulls, seconds)
    factor = scale_factor(scale)
    parts = [Part(part.vertices, part.faces, part.hull_volume * factor) for part in hulls]
    return Decomposition(method, parts, seconds, parameters, reused)


def _vhacd(vertices: np.ndarray, faces: np.ndarray, resolution: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """pybullet's V-HACD (in the isolated child): write the mesh as OBJ, decompose, read the parts."""
    import tempfile

    from ar3cli.infra.isolation import report_stage
    from ar3cli.sim.capture import capture_fds
    from ar3cli.sim.session import import_pybullet

    p = import_pybullet()
    with tempfile.TemporaryDirectory(prefix="ar3cli-vhacd-") as folder:
        source, target, log = (Path(folder) / name for name in ("in.obj", "out.obj", "vhacd.log"))
        source.write_text(obj_text(vertices, faces))
        report_stage("decomposing it with pybullet's vhacd")
        with capture_fds():  # V-HACD prints its progress from C
            p.vhacd(str(source), str(target), str(log), concavity=VHACD_CONCAVITY, resolution=int(resolution))
        if not target.is_file():
            raise UserError("pybullet's vhacd wrote no output")
        return parse_obj_objects(target.read_text(encoding="utf-8", errors="replace"))


def _coacd(vertices: np.ndarray, faces: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """CoACD (in the isolated child), fixed seed."""
    import coacd

    from ar3cli.infra.isolation import report_stage
    from ar3cli.sim.capture import capture_fds

    report_stage("decomposing it with coacd")
    with capture_fds():
        coacd.set_log_level("error")
        result = coacd.run_coacd(coacd.Mesh(vertices, faces), threshold=COACD_THRESHOLD, seed=COACD_SEED)
    return [(np.asarray(v, dtype=float), np.asarray(f, dtype=np.int64)) for v, f in result]


def parse_obj_objects(text: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """Split an OBJ with several ``o`` objects (V-HACD's output) into (vertices, faces) per object.

    OBJ indices are global and 1-based (negative ones count back from the last vertex); each
    object keeps only the vertices its faces use. Polygons are fanned into triangles.
    """
    vertices: list[tuple[float, float, float]] = []
    objects: list[list[list[int]]] = []
    for line in text.splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "o" or (words[0] == "g" and not objects):
            objects.append([])
        elif words[0] == "v" and len(words) >= 4:
            vertices.append((float(words[1]), float(words[2]), float(words[3])))
        elif words[0] == "f" and len(words) >= 4:
            if not objects:
                objects.append([])
            indices = [int(word.split("/")[0]) for word in words[1:]]
            indices = [i - 1 if i > 0 else len(vertices) + i for i in indices]
            objects[-1].extend([indices[0], indices[k], indices[k + 1]] for k in range(1, len(indices) - 1))
    points = np.asarray(vertices, dtype=float).reshape(-1, 3)
    parts = []
    for triangles in objects:
        if not triangles:
            continue
        used, inverse = np.unique(np.asarray(triangles, dtype=np.int64), return_inverse=True)
        parts.append((points[used], inverse.reshape(-1, 3)))
    return parts


def obj_text(vertices: np.ndarray, faces: np.ndarray, comment: str = "", name: str = "") -> str:
    """A minimal OBJ (9 significant digits, far below any collision tolerance)."""
    lines = [f"# {comment}"] if comment else []
    if name:
        lines.append(f"o {name}")
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in np.asarray(vertices, dtype=float)]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces, dtype=np.int64)]
    return "\n".join(lines) + "\n"
