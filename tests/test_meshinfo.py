"""Mesh bounds read without numpy: real pybullet_data meshes against trimesh, and the edge cases."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np
import pytest

from ar3cli.urdf import meshinfo


def _binary_stl(triangles: list[list[tuple[float, float, float]]]) -> bytes:
    records = b"".join(struct.pack("<12fH", 0, 0, 0, *(c for v in tri for c in v), 0) for tri in triangles)
    return b"\0" * 80 + struct.pack("<I", len(triangles)) + records


@pytest.mark.parametrize("relative", ["franka_panda/meshes/visual/link6.obj", "franka_panda/meshes/collision/link4.obj",
                                      "kuka_iiwa/meshes/link_3.stl", "differential/diff_ring.stl",
                                      "duck.obj"])
def test_bounds_match_trimesh_on_real_meshes(pybullet_data_dir, relative):
    import trimesh

    path = pybullet_data_dir / relative
    vertices = np.asarray(trimesh.load(str(path), force="mesh", process=False).vertices)
    low, high = meshinfo.mesh_bounds(path)
    np.testing.assert_allclose(low, vertices.min(axis=0), rtol=1e-15, atol=0)
    np.testing.assert_allclose(high, vertices.max(axis=0), rtol=1e-15, atol=0)
    assert all(isinstance(v, float) for v in (*low, *high))


def test_large_binary_stl_numpy_path_agrees(pybullet_data_dir):
    data = (pybullet_data_dir / "differential" / "diff_ring.stl").read_bytes()
    columns, may_be_nonfinite = meshinfo._stl_columns(data)
    assert not may_be_nonfinite
    assert meshinfo._bounds(columns, False) == meshinfo._numpy_stl_bounds(data)


def test_non_finite_vertices_are_ignored_whole(tmp_path):
    nan, inf = math.nan, math.inf
    triangles = [[(0, 0, 0), (1, 2, 3), (nan, 50, 50)], [(inf, -9, 0), (0.5, 0.5, -1), (0, 0, 0)]]
    stl = tmp_path / "t.stl"
    stl.write_bytes(_binary_stl(triangles))
    expected = ((0.0, 0.0, -1.0), (1.0, 2.0, 3.0))  # (nan, 50, 50) and (inf, -9, 0) dropped entirely
    assert meshinfo.mesh_bounds(stl) == expected
    assert meshinfo._numpy_stl_bounds(stl.read_bytes()) == expected
    obj = tmp_path / "t.obj"
    obj.write_text("v 0 0 0\nv 1 2 3\nv nan 50 50\nv inf -9 0\nv 0.5 0.5 -1\nf 1 2 3\n")
    assert meshinfo.mesh_bounds(obj) == expected
    ascii_stl = tmp_path / "a.stl"
    ascii_stl.write_text("solid s\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex NaN 9 9\n"
                         "   vertex 1 2 3\n  endloop\n endfacet\nendsolid s\n")
    assert meshinfo.mesh_bounds(ascii_stl) == ((0.0, 0.0, 0.0), (1.0, 2.0, 3.0))


def test_obj_extra_columns_and_empty(tmp_path):
    obj = tmp_path / "c.obj"
    obj.write_text("# colours and w\r\nv 1 2 3 0.5 0.5 0.5\r\nv -1 -2 -3 1.0\r\nvn 0 0 9\r\nvt 7 7\r\nv 0 0 0\r\n")
    assert meshinfo.mesh_bounds(obj) == ((-1.0, -2.0, -3.0), (1.0, 2.0, 3.0))
    single = tmp_path / "s.obj"
    single.write_bytes(b"v 5 6 7")  # first line, no newline at all
    assert meshinfo.mesh_bounds(single) == ((5.0, 6.0, 7.0), (5.0, 6.0, 7.0))
    empty = tmp_path / "e.obj"
    empty.write_text("# nothing\nvn 0 0 1\n")
    assert meshinfo.mesh_bounds(empty) is None
    junk = tmp_path / "j.obj"
    junk.write_text("v 1 two 3\n")
    assert meshinfo.mesh_bounds(junk) is None


def test_disk_cache_reuses_and_invalidates(tmp_path, monkeypatch):
    """Bounds survive the process (keyed by path, mtime, size); an edited mesh is read again."""
    import os

    from ar3cli.infra import file_cache as cache
    from ar3cli.urdf import meshinfo

    monkeypatch.setenv("AR3CLI_CACHE_DIR", str(tmp_path / "cache"))
    mesh = tmp_path / "m.obj"
    mesh.write_text("v 0 0 0\nv 1 2 3\n")

    def fresh_bounds():
        meshinfo._DISK_CACHE = cache.FileFacts("mesh-bounds", version=2)  # a new process, in effect
        meshinfo._mesh_bounds.cache_clear()
        return meshinfo.mesh_bounds(mesh)

    assert fresh_bounds() == ((0.0, 0.0, 0.0), (1.0, 2.0, 3.0))
    meshinfo._DISK_CACHE.save()
    stored = next((tmp_path / "cache" / "mesh-bounds-v2").glob("*.json"))
    import json

    entries = json.loads(stored.read_text())
    (key,) = entries
    assert key.startswith(str(mesh.resolve()))
    stored.write_text(json.dumps({key: [[9, 9, 9], [9, 9, 9]]}))  # plant a value only the disk knows
    assert fresh_bounds() == ((9, 9, 9), (9, 9, 9))  # answered from disk, the mesh was not read
    mesh.write_text("v 0 0 0\nv 5 5 5\n")
    os.utime(mesh, ns=(1, 10**18))
    assert fresh_bounds() == ((0.0, 0.0, 0.0), (5.0, 5.0, 5.0))  # edited: read again
    stored.write_text("{ not json")
    assert fresh_bounds() == ((0.0, 0.0, 0.0), (5.0, 5.0, 5.0))  # a damaged cache is ignored
    monkeypatch.setenv("AR3CLI_NO_CACHE", "1")
    assert cache.cache_dir() is None


def test_collada_bounds_follow_the_scene_and_skip_unused_positions() -> None:
    """ar3cli's own COLLADA reader: node transforms (translate, rotate, scale, matrix, nesting),
    only the positions the triangles use; the same box as trimesh."""
    import numpy as np
    import trimesh

    from ar3cli.urdf.dae import dae_bounds

    path = Path(__file__).parent / "data" / "meshes" / "transformed.dae"
    low, high = dae_bounds(path)
    # moved: the square scaled by 2 and turned 90 degrees about z -> x in [-2, 0], y in [0, 2], z = 2;
    # matrixed/child: shifted to x in [5, 6], z = -1.
    assert low == pytest.approx((-2.0, 0.0, -1.0), abs=1e-12)
    assert high == pytest.approx((6.0, 2.0, 2.0), abs=1e-12)
    with path.open("rb") as handle:
        vertices = np.asarray(trimesh.load(handle, file_type="dae", force="mesh", process=False).vertices)
    assert low == pytest.approx(tuple(vertices.min(axis=0)), abs=1e-6)
    assert high == pytest.approx(tuple(vertices.max(axis=0)), abs=1e-6)
