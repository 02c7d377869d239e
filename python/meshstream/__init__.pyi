# Type stubs of the meshstream package (python/meshstream/__init__.py), for editors and type
# checkers. Flags (**flags) are the command's, as keyword arguments: see docs/python.md.
from os import PathLike
from typing import Any, Callable, Iterator, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._meshstream import Chunk as Chunk, ChunkReader as ChunkReader, Error as Error

Path = Union[str, PathLike[str]]
Progress = Callable[[str, int, Optional[int]], Any]
Report = dict[str, Any]
Material = dict[str, Any]  # name, base_color (RGBA), texture (uri, mime_type, bytes) or None

class Mesh:
    vertices: npt.NDArray[np.float32]  # n×3
    faces: npt.NDArray[np.uint32]  # m×3
    normals: Optional[npt.NDArray[np.float32]]  # n×3
    colors: Optional[npt.NDArray[np.float32]]  # n×4, RGBA in 0..1
    color_type: str  # "uint8", "uint16" or "float32"
    color_alpha: bool
    uvs: list[npt.NDArray[np.float32]]  # n×2 each
    scalars: dict[str, npt.NDArray[np.float64]]  # n each
    scalar_types: dict[str, str]
    face_materials: Optional[npt.NDArray[np.uint32]]  # m
    materials: list[Material]
    format: Optional[str]
    warnings: list[dict[str, Any]]  # from read(): code, text, count
    def __init__(self, vertices: npt.ArrayLike, faces: npt.ArrayLike, *, normals: Optional[npt.ArrayLike] = ...,
                 colors: Optional[npt.ArrayLike] = ..., color_type: str = ..., color_alpha: bool = ...,
                 uvs: Sequence[npt.ArrayLike] = ..., scalars: Optional[dict[str, npt.ArrayLike]] = ...,
                 scalar_types: Optional[dict[str, str]] = ..., face_materials: Optional[npt.ArrayLike] = ...,
                 materials: Sequence[Material] = ...) -> None: ...

def read(path: Path, *, from_: Optional[str] = ..., memory: Union[str, int, None] = ..., tmpdir: Optional[str] = ...,
         strict: bool = ..., drop: Union[str, Sequence[str], None] = ...) -> Mesh: ...
def write(path: Path, mesh: Union[Mesh, npt.ArrayLike], faces: Optional[npt.ArrayLike] = ..., *,
          to: Optional[str] = ..., compress: Optional[str] = ..., normals: bool = ..., gzip_level: int = ...,
          draco_qp: Optional[int] = ..., draco_qn: Optional[int] = ..., draco_qt: Optional[int] = ...,
          draco_qc: Optional[int] = ..., draco_cl: Optional[int] = ..., memory: Union[str, int, None] = ...,
          tmpdir: Optional[str] = ..., strict: bool = ...) -> None: ...
def chunks(path: Path, capacity: int = ..., *, from_: Optional[str] = ..., memory: Union[str, int, None] = ...,
           tmpdir: Optional[str] = ..., strict: bool = ..., drop: Union[str, Sequence[str], None] = ...) -> ChunkReader: ...

class Writer:
    def __init__(self, path: Path, *, materials: Optional[Sequence[Material]] = ..., color_type: str = ...,
                 color_alpha: bool = ..., scalar_types: Optional[dict[str, str]] = ..., **flags: Any) -> None: ...
    def write(self, chunk_or_positions: Union[Chunk, npt.ArrayLike], *, normals: Optional[npt.ArrayLike] = ...,
              colors: Optional[npt.ArrayLike] = ..., uvs: Union[npt.ArrayLike, Sequence[npt.ArrayLike], None] = ...,
              vertex_scalars: Optional[dict[str, npt.ArrayLike]] = ...,
              face_scalars: Optional[dict[str, npt.ArrayLike]] = ..., materials: Optional[npt.ArrayLike] = ...) -> None: ...
    def close(self) -> None: ...
    @property
    def notes(self) -> list[str]: ...
    def __enter__(self) -> Writer: ...
    def __exit__(self, kind: Any, value: Any, traceback: Any) -> bool: ...

def convert(src: Path, dst: Path, *, progress: Optional[Progress] = ..., clean: bool = ..., threads: Optional[int] = ...,
            **flags: Any) -> Report: ...
def sort(src: Path, dst: Path, *, progress: Optional[Progress] = ..., axis: Optional[str] = ..., clean: bool = ...,
         threads: Optional[int] = ..., **flags: Any) -> Report: ...
def decimate(src: Path, dst: Path, *, progress: Optional[Progress] = ..., ratio: Optional[float] = ...,
             target: Optional[int] = ..., buffer: Optional[int] = ..., seed: Optional[int] = ...,
             weld: Union[str, float, None] = ..., sorted_axis: Optional[str] = ..., sort: Optional[str] = ...,
             threads: Optional[int] = ..., weights: Optional[str] = ..., report: bool = ..., **flags: Any) -> Report: ...
def info(path: Path, *, progress: Optional[Progress] = ..., topology: bool = ..., order: bool = ...,
         buffer: Optional[int] = ..., ratio: Optional[float] = ..., **flags: Any) -> Report: ...
def compare(a: Path, b: Path, *, progress: Optional[Progress] = ..., samples: Optional[int] = ...,
            seed: Optional[int] = ..., attributes: bool = ..., **flags: Any) -> Report: ...
def tiles(src: Path, dst: Path, *, progress: Optional[Progress] = ..., tile_triangles: Optional[int] = ...,
          compress: Optional[str] = ..., origin: Optional[str] = ..., overwrite: bool = ..., seed: Optional[int] = ...,
          threads: Optional[int] = ..., **flags: Any) -> Report: ...

def to_open3d(mesh: Mesh) -> Any: ...
def from_open3d(o: Any) -> Mesh: ...
def to_meshio(mesh: Mesh) -> Any: ...
def from_meshio(m: Any) -> Mesh: ...
