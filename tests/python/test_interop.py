# The one-liners to and from Open3D's TriangleMesh and meshio's Mesh (Debian's python3-open3d
# and python3-meshio), by round trips in both directions over corpus files.
import numpy as np
import pytest

import meshstream
from conftest import fixture

open3d = pytest.importorskip("open3d")
meshio = pytest.importorskip("meshio")

CORPUS = [("ply", "cactus_vcolor.binary_le.ply"), ("ply", "cube_uv.ply"), ("obj", "WusonOBJ.obj"),
          ("ply", "elephant_normals.binary_be.ply")]


@pytest.mark.parametrize("name", CORPUS)
def test_open3d_round_trip(name):
    mesh = meshstream.read(fixture(*name))
    o = meshstream.to_open3d(mesh)
    assert len(o.vertices) == len(mesh.vertices) and len(o.triangles) == len(mesh.faces)
    assert o.has_vertex_normals() == (mesh.normals is not None)
    back = meshstream.from_open3d(o)
    assert np.array_equal(back.vertices, mesh.vertices) and np.array_equal(back.faces, mesh.faces)
    if mesh.normals is not None:
        assert np.array_equal(back.normals, mesh.normals)
    if mesh.colors is not None:
        assert np.array_equal(back.colors[:, :3], mesh.colors[:, :3])
    if mesh.uvs:
        assert np.array_equal(np.asarray(o.triangle_uvs, np.float32), mesh.uvs[0][mesh.faces.reshape(-1)])


@pytest.mark.parametrize("name", ["cactus_vcolor.binary_le.ply", "elephant_normals.binary_be.ply"])
def test_ply_read_gives_the_files_own_arrays(name):
    # A PLY keeps its vertices in file order and its faces' indices: what meshio (and Open3D)
    # read from the file, array for array.
    mesh = meshstream.read(fixture("ply", name))
    m = meshio.read(fixture("ply", name))
    assert np.array_equal(mesh.vertices, np.asarray(m.points, np.float32))
    assert np.array_equal(mesh.faces, np.asarray(m.cells_dict["triangle"], np.uint32))
    o = open3d.io.read_triangle_mesh(fixture("ply", name))
    assert np.array_equal(mesh.faces, np.asarray(o.triangles, np.uint32))


def test_open3d_mesh_written_and_read_back(tmp_path):
    o = open3d.geometry.TriangleMesh.create_box(1.0, 2.0, 3.0)
    o.compute_vertex_normals()
    meshstream.write(tmp_path / "box.ply", meshstream.from_open3d(o))
    back = meshstream.to_open3d(meshstream.read(tmp_path / "box.ply"))
    # The same triangles (the writer numbers the vertices in the order the faces use them).
    corners = np.asarray(o.vertices)[np.asarray(o.triangles)]
    assert np.array_equal(np.asarray(back.vertices)[np.asarray(back.triangles)], corners)
    # Open3D reads what meshstream wrote: the same triangles.
    read = open3d.io.read_triangle_mesh(str(tmp_path / "box.ply"))
    assert len(read.triangles) == 12 and len(read.vertices) == 8


@pytest.mark.parametrize("name", CORPUS)
def test_meshio_round_trip(name):
    mesh = meshstream.read(fixture(*name))
    m = meshstream.to_meshio(mesh)
    assert len(m.points) == len(mesh.vertices) and len(m.cells_dict["triangle"]) == len(mesh.faces)
    back = meshstream.from_meshio(m)
    assert np.array_equal(back.vertices, mesh.vertices) and np.array_equal(back.faces, mesh.faces)
    for channel in ("normals", "colors"):
        if getattr(mesh, channel) is not None:
            assert np.array_equal(getattr(back, channel), getattr(mesh, channel))
    assert len(back.uvs) == len(mesh.uvs) and all(np.array_equal(a, b) for a, b in zip(back.uvs, mesh.uvs))


def test_meshio_file_read_by_meshstream_and_back(tmp_path):
    # meshio writes, meshstream reads; meshstream writes, meshio reads.
    mesh = meshstream.read(fixture("ply", "cube_uv.ply"))
    meshio.write(tmp_path / "m.obj", meshstream.to_meshio(meshstream.Mesh(mesh.vertices, mesh.faces)))
    again = meshstream.read(tmp_path / "m.obj")
    assert np.array_equal(again.vertices[again.faces], mesh.vertices[mesh.faces])
    meshstream.write(tmp_path / "s.stl", mesh)
    m = meshio.read(tmp_path / "s.stl")
    assert len(m.cells_dict["triangle"]) == 12
    assert np.array_equal(m.points[m.cells_dict["triangle"]].astype(np.float32), mesh.vertices[mesh.faces])
