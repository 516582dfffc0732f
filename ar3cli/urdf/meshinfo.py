"""Cheap facts about mesh files for the linter: bounding boxes and Git LFS pointers.

STL (binary and ASCII) and OBJ vertices are read in plain Python: importing numpy costs ~0.1 s
and trimesh ~0.5 s, more than reading the meshes of a typical robot (the Franka Panda's 18 OBJ
files, 52k vertices, take ~25 ms), so a static lint never imports either for them. Binary STL
files of at least :data:`NUMPY_MIN_BYTES` are read with numpy, where its import pays for
itself. Other formats (COLLADA .dae, ...) fall back to trimesh, imported only then. Results are
cached per path for the process (bulk lints share meshes between models) and on disk between runs
(:mod:`ar3cli.infra.file_cache`, keyed by path, modification time and size).
"""

from __future__ import annotations

import math
import os
import re
import struct
import sys
from array import array
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

from ar3cli.infra.file_cache import MISSING, file_facts

LFS_POINTER_PREFIX = b"version https://git-lfs.github.com/spec/"
LFS_POINTER_MAX_BYTES = 1024
"""Git LFS's specification: "Pointer files must be less than 1024 bytes in size"."""
MAX_MESH_BYTES = 200 * 1024 * 1024
NUMPY_MIN_BYTES = 16 * 1024 * 1024
"""Binary STL size from which numpy is faster, import included (measured: plain Python ~7 ms/MB,
numpy ~3 ms/MB plus ~0.1 s to import it)."""

Bounds = tuple[tuple[float, float, float], tuple[float, float, float]]
Columns = tuple[Sequence[float], Sequence[float], Sequence[float]]
"""Vertex coordinates as three sequences: all x, all y, all z."""

_OBJ_VERTEX = re.compile(rb"\nv[ \t]([^\n]*)")
"""Vertex lines; the literal ``\\nv`` prefix lets ``re`` skip ahead (20x faster than a ``^`` pattern)."""
_STL_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")
_STL_RECORD = 50
"""Bytes per binary STL triangle: normal (3 float32), 3 vertices (9 float32), attribute (uint16)."""


_DISK_CACHE = file_facts("mesh-bounds", version=2)


def is_lfs_pointer(path: Path) -> bool:
    """True when ``path`` is a Git LFS pointer (the mesh was never pulled: ``git lfs pull``).

    The spec keeps pointer files under 1024 bytes: a larger file is not opened (a stat is ~3x
    cheaper than open, read and close, and a bulk lint asks for every mesh).
    """
    try:
        if os.stat(path).st_size >= LFS_POINTER_MAX_BYTES:
            return False
        with path.open("rb") as handle:
            return handle.read(len(LFS_POINTER_PREFIX)) == LFS_POINTER_PREFIX
    except OSError:
        return False


def mesh_bounds(path: Path) -> Bounds | None:
    """(min corner, max corner) of the mesh's vertices in file units, or None if unreadable/empty.

    Vertices with a nan or infinite coordinate are ignored.
    """
    try:
        stat = path.stat()
    except OSError:
        return None
    stored = _DISK_CACHE.get(path, stat)
    if stored is None:
        return None
    if stored is not MISSING:
        try:
            low, high = (tuple(map(float, stored[0])), tuple(map(float, stored[1])))
            if len(low) == len(high) == 3:
                return low, high  # type: ignore[return-value]
        except (TypeError, ValueError, IndexError, KeyError):
            pass  # a damaged entry: read the mesh again
    bounds = _mesh_bounds(path, stat.st_mtime_ns, stat.st_size)
    _DISK_CACHE.put(path, stat, [list(bounds[0]), list(bounds[1])] if bounds else None)
    return bounds


@lru_cache(maxsize=1024)
def _mesh_bounds(path: Path, _mtime_ns: int, size: int) -> Bounds | None:
    """Cached by path, modification time and size, so a rewritten mesh is read again."""
    try:
        if size > MAX_MESH_BYTES or is_lfs_pointer(path):
            return None
        suffix = path.suffix.lower()
        if suffix == ".stl":
            data = path.read_bytes()
            if _binary_stl_count(data) is not None and size >= NUMPY_MIN_BYTES:
                return _numpy_stl_bounds(data)
            parsed = _stl_columns(data)
        elif suffix == ".obj":
            parsed = _obj_columns(path.read_bytes())
        elif suffix == ".dae":
            return _dae_bounds(path)
        else:
            return _trimesh_bounds(path)
    except Exception:  # noqa: BLE001 - a mesh we cannot read is the loader's problem, not a reason to crash the lint
        return None
    return _bounds(*parsed) if parsed is not None else None


def _bounds(columns: Columns, may_be_nonfinite: bool) -> Bounds | None:
    """Box of the vertices; ``may_be_nonfinite`` says whether a nan can hide among them.

    Python's min() and max() skip a nan unless it comes first, so nan must be ruled out by the
    parser (cheaply, on the raw bytes); infinities always show in the result.
    """
    xs, ys, zs = columns
    if not xs:
        return None
    low, high = (min(xs), min(ys), min(zs)), (max(xs), max(ys), max(zs))
    if not may_be_nonfinite and all(map(math.isfinite, low + high)):
        return low, high
    finite = [v for v in zip(xs, ys, zs) if all(map(math.isfinite, v))]  # rare: filter only then
    return _bounds(tuple(zip(*finite)), False) if finite else None  # type: ignore[arg-type]


def _binary_stl_count(data: bytes) -> int | None:
    """Triangle count when ``data`` is a binary STL (its size matches the count in its header)."""
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + _STL_RECORD * count:
            return count
    return None


def _stl_columns(data: bytes) -> tuple[Columns, bool] | None:
    count = _binary_stl_count(data)
    if count is None:
        tokens = [v for match in _STL_VERTEX.findall(data) for v in match]
        return _text_columns(tokens, b" ".join(tokens))
    # Gather the 36 vertex bytes of each 50-byte record with strided copies of 16-bit words
    # (records are 2-byte aligned), then read them as float32: no per-triangle Python code.
    words = array("H", data[84:])
    gathered = array("H", bytes(36 * count))
    for j in range(18):
        gathered[j::18] = words[6 + j::_STL_RECORD // 2]
    raw = gathered.tobytes()  # still the file's little-endian floats
    flat = array("f", raw)
    if sys.byteorder == "big":
        flat.byteswap()
    # A float32 is nan or infinite only if its top byte, sign bit aside, is 0x7f.
    high_bytes = raw[3::4]
    may_be_nonfinite = b"\x7f" in high_bytes or b"\xff" in high_bytes
    return (flat[0::3], flat[1::3], flat[2::3]), may_be_nonfinite


def _obj_columns(data: bytes) -> tuple[Columns, bool] | None:
    rows = _OBJ_VERTEX.findall(data)
    if data[:2] in (b"v ", b"v\t"):  # the pattern needs a newline before "v"; the first line has none
        end = data.find(b"\n")
        rows.insert(0, data[2:end if end >= 0 else len(data)])
    text = b" ".join(rows)
    tokens = text.split()
    # Three per line is the usual "v x y z" (a malformed file mixing two- and four-number lines
    # could total three per line too, and be misread like the loaders misread it).
    if len(tokens) != 3 * len(rows):  # x y z may be followed by w, or by r g b: keep the first three
        tokens = [value for row in map(bytes.split, rows) if len(row) >= 3 for value in row[:3]]
    return _text_columns(tokens, text)


def _text_columns(tokens: list[bytes], text: bytes) -> tuple[Columns, bool]:
    """Columns of x y z numbers written as text (three tokens per vertex) found in ``text``."""
    values = list(map(float, tokens))
    may_be_nonfinite = b"n" in text or b"N" in text  # only "nan" and "inf" have an n
    return (values[0::3], values[1::3], values[2::3]), may_be_nonfinite


def _numpy_stl_bounds(data: bytes) -> Bounds | None:
    import numpy as np

    count = _binary_stl_count(data)
    records = np.frombuffer(data, dtype=np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")]),
                            count=count, offset=84)
    vertices = records["v"].reshape(-1, 3)
    vertices = vertices[np.isfinite(vertices).all(axis=1)]
    if len(vertices) == 0:
        return None
    return tuple(vertices.min(axis=0).tolist()), tuple(vertices.max(axis=0).tolist())  # type: ignore[return-value]



