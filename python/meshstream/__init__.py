"""meshstream: streaming mesh I/O, sorting and decimation for files of any size.

Whole meshes as numpy arrays (read, write), the triangle stream a chunk at a time (chunks,
Writer), and every command as a call returning its --json report as a dict (convert, sort,
decimate, info, compare, and tiles for OGC 3D Tiles when built with glTF). Keyword arguments are the command's flags: ``from_`` for --from,
``draco_qp`` for --draco-qp, ``memory="512M"``; bad values raise ValueError in the command's
words, unknown keywords TypeError. Files that cannot be read or written raise
meshstream.Error with .file, .line and .offset. The work runs without the GIL; Ctrl-C (or a
progress callable that raises) stops it and removes the unfinished output. docs/python.md
has examples.
"""

from ._meshstream import Chunk, ChunkReader, Error, compare, convert, decimate, info, sort
from . import _meshstream

if hasattr(_meshstream, "tiles"):  # built with glTF (MESHSTREAM_WITH_GLTF)
    from ._meshstream import tiles

import numpy as _np

__all__ = [
    "Chunk",
    "Error",
    "Mesh",
    "Writer",
    "chunks",
    "compare",
    "convert",
    "decimate",
    "from_meshio",
    "from_open3d",
    "info",
    "read",
    "sort",
    *(["tiles"] if hasattr(_meshstream, "tiles") else []),
    "to_meshio",
    "to_open3d",
    "write",
]


class Mesh:
    """An indexed mesh: vertices (n×3 float32) and faces (m×3 uint32, counter-clockwise), and
    the channels the file has, per vertex: normals (n×3 float32), colors (n×4 float32 RGBA in
    0..1, stored in the file as color_type, "uint8", "uint16" or "float32"), uvs (a list of
    n×2 float32 sets), scalars (name -> n float64, stored as scalar_types[name]); per face:
    face_materials (m uint32) indexing materials (dicts: name, base_color, texture). Absent
    channels are None (or empty). Vertices on a UV or normal seam are separate vertices."""

    def __init__(self, vertices, faces, *, normals=None, colors=None, color_type="uint8", color_alpha=False,
                 uvs=(), scalars=None, scalar_types=None, face_materials=None, materials=()):
        self.vertices = _np.asarray(vertices, dtype=_np.float32)
        self.faces = _np.asarray(faces, dtype=_np.uint32)
        self.normals = None if normals is None else _np.asarray(normals, dtype=_np.float32)
        self.colors = None if colors is None else _np.asarray(colors, dtype=_np.float32)
        self.color_type = color_type
        self.color_alpha = color_alpha
        self.uvs = [_np.asarray(u, dtype=_np.float32) for u in uvs]
        self.scalars = {k: _np.asarray(v, dtype=_np.float64) for k, v in (scalars or {}).items()}
        self.scalar_types = dict(scalar_types or {})
        self.face_materials = None if face_materials is None else _np.asarray(face_materials, dtype=_np.uint32)
        self.materials = list(materials)
        self.format = None
        self.warnings = []

    def __repr__(self):
        extra = [name for name in ("normals", "colors", "face_materials") if getattr(self, name) is not None]
        extra += [f"{len(self.uvs)} uv sets"] if self.uvs else []
        extra += [f"scalars {sorted(self.scalars)}"] if self.scalars else []
        return f"<meshstream.Mesh {len(self.vertices)} vertices, {len(self.faces)} faces{', ' if extra else ''}{', '.join(extra)}>"


def read(path, **flags):
    """Reads a whole mesh file (any format meshstream reads) as a Mesh. Flags: from_, memory,
    tmpdir, strict, drop. Triangles with a NaN or infinite coordinate are dropped
    (mesh.non_finite_triangles counts them; strict=True makes them an Error). mesh.warnings lists
    what the reader changed or left out (dicts: code, text, count; count 0 for a one-off), as the
    commands' --json reports do, and the per-face scalars that only chunks() gives."""
    d = _meshstream._read(str(path), **flags)
    mesh = Mesh.__new__(Mesh)
    for key in ("vertices", "faces", "normals", "colors", "color_type", "color_alpha", "uvs", "scalars",
                "scalar_types", "face_materials", "materials", "format", "non_finite_triangles",
                "non_finite_attributes", "warnings"):
        setattr(mesh, key, d[key])
    if mesh.color_type is None:
        mesh.color_type = "uint8"
    return mesh


def write(path, mesh, faces=None, **flags):
    """Writes a Mesh, or vertices and faces arrays, to `path` in the format of its extension
    (or to=...), with the command's write flags: to, compress, normals, gzip_level,
    draco_qp/qn/qt/qc/cl, memory, tmpdir, strict. Channels the format cannot hold are left out.
    An output that fails is not left behind."""
    if not isinstance(mesh, Mesh):
        if faces is None:
            raise TypeError("write: give a meshstream.Mesh, or vertices and faces arrays")
        mesh = Mesh(mesh, faces)
    elif faces is not None:
        raise TypeError("write: faces goes with a vertices array, not with a Mesh")
    _meshstream._write(str(path), mesh.vertices, mesh.faces, mesh.normals, mesh.colors, mesh.color_type,
                       mesh.color_alpha, list(mesh.uvs), mesh.scalars, mesh.scalar_types, mesh.face_materials,
                       list(mesh.materials), **flags)


def chunks(path, capacity=16384, **flags):
    """Iterates over a mesh file's triangles a chunk at a time, in memory that does not grow with
    the file: each Chunk has positions (t×3×3 float32) and the file's channels per corner
    (normals t×3×3, colors t×3×4, uvs [t×3×2], vertex_scalars {name: t×3}) and per triangle
    (materials t, face_scalars {name: t}), as views of a buffer the next chunk reuses (copy what
    you keep). The iterator has channels, materials, triangle_count and sorted_axis. Flags as
    read()'s; every triangle is passed on as read."""
    return ChunkReader(str(path), capacity, **flags)


class Writer:
    """Writes a mesh file as its triangles come: ``with meshstream.Writer("out.ply") as w:
    w.write(chunk)`` for chunks of meshstream.chunks, or ``w.write(positions, normals=...)`` for
    arrays of triangles' corners (positions t×3×3, normals t×3×3, colors t×3×4, uvs [t×3×2],
    vertex_scalars {name: t×3}, face_scalars {name: t}, materials t). Every write must carry the
    channels of the first. Leaving the block normally completes the file; an exception discards
    it. Flags as write()'s; materials: the table the materials channel indexes."""

    def __init__(self, path, *, materials=None, color_type="uint8", color_alpha=False, scalar_types=None, **flags):
        self._writer = _meshstream._Writer(str(path), materials=materials, **flags)
        self._color_type = color_type
        self._color_alpha = color_alpha
        self._scalar_types = dict(scalar_types or {})

    def write(self, chunk_or_positions, *, normals=None, colors=None, uvs=None, vertex_scalars=None,
              face_scalars=None, materials=None):
        if isinstance(chunk_or_positions, Chunk):
            self._writer.write_chunk(chunk_or_positions)
        else:
            self._writer.write_arrays(chunk_or_positions, normals, colors, self._color_type, self._color_alpha, uvs,
                                      vertex_scalars, self._scalar_types, face_scalars, materials)

    def close(self):
        """Completes the file (a Writer never written to writes an empty mesh)."""
        self._writer.close()

    @property
    def notes(self):
        """What the writer says of the output once closed (a lossy encoding), one sentence each."""
        return self._writer.notes

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            self.close()
        else:
            self._writer.abandon()
        return False


# Interop: one call each way. Open3D's TriangleMesh keeps vertices, triangles, vertex normals
# and colours (RGB) and the first uv set per triangle corner; meshio's Mesh keeps points,
# "triangle" cells and point_data (normals, colors, uv sets, scalars) and cell_data.


def to_open3d(mesh):
    """The Mesh as an open3d.geometry.TriangleMesh (vertex normals, RGB colours, the first uv set
    as triangle_uvs)."""
    import open3d

    o = open3d.geometry.TriangleMesh(open3d.utility.Vector3dVector(mesh.vertices.astype(_np.float64)),
                                     open3d.utility.Vector3iVector(mesh.faces.astype(_np.int32)))
    if mesh.normals is not None:
        o.vertex_normals = open3d.utility.Vector3dVector(mesh.normals.astype(_np.float64))
    if mesh.colors is not None:
        o.vertex_colors = open3d.utility.Vector3dVector(mesh.colors[:, :3].astype(_np.float64))
    if mesh.uvs:
        o.triangle_uvs = open3d.utility.Vector2dVector(mesh.uvs[0][mesh.faces.reshape(-1)].astype(_np.float64))
    return o


def from_open3d(o):
    """A Mesh from an open3d.geometry.TriangleMesh (its vertex normals and colours when it has
    them; colours as float32)."""
    mesh = Mesh(_np.asarray(o.vertices), _np.asarray(o.triangles))
    if o.has_vertex_normals():
        mesh.normals = _np.asarray(o.vertex_normals, dtype=_np.float32)
    if o.has_vertex_colors():
        rgb = _np.asarray(o.vertex_colors, dtype=_np.float32)
        mesh.colors = _np.hstack([rgb, _np.ones((len(rgb), 1), _np.float32)])
        mesh.color_type = "float32"
    return mesh


def to_meshio(mesh):
    """The Mesh as a meshio.Mesh: points, "triangle" cells, point_data normals, colors, uv0.. and
    scalars by name, cell_data material."""
    import meshio

    point_data = {}
    if mesh.normals is not None:
        point_data["normals"] = mesh.normals
    if mesh.colors is not None:
        point_data["colors"] = mesh.colors
    for i, uv in enumerate(mesh.uvs):
        point_data[f"uv{i}"] = uv
    point_data.update(mesh.scalars)
    cell_data = {} if mesh.face_materials is None else {"material": [mesh.face_materials]}
    return meshio.Mesh(mesh.vertices, [("triangle", mesh.faces)], point_data=point_data, cell_data=cell_data)


def from_meshio(m):
    """A Mesh from a meshio.Mesh's "triangle" cells and the point_data to_meshio names (normals,
    colors, uv0.., other 1-D arrays as scalars)."""
    faces = _np.concatenate([block.data for block in m.cells if block.type == "triangle"]) if m.cells else \
        _np.zeros((0, 3), _np.uint32)
    mesh = Mesh(m.points[:, :3], faces)
    uvs = {}
    for name, values in m.point_data.items():
        values = _np.asarray(values)
        if name == "normals" and values.shape[1:] == (3,):
            mesh.normals = values.astype(_np.float32)
        elif name == "colors" and values.shape[1:] == (4,):
            mesh.colors = values.astype(_np.float32)
        elif name.startswith("uv") and name[2:].isdigit() and values.shape[1:] == (2,):
            uvs[int(name[2:])] = values.astype(_np.float32)
        elif values.ndim == 1:
            mesh.scalars[name] = values.astype(_np.float64)
    mesh.uvs = [uvs[i] for i in sorted(uvs)]
    material = m.cell_data.get("material")
    if material is not None:
        mesh.face_materials = _np.concatenate(material).astype(_np.uint32)
    return mesh
