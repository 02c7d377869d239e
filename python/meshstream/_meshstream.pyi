# Type stubs of the compiled part of the meshstream package (python/meshstream_module.cpp).
from typing import Any, Iterator, Optional

import numpy as np
import numpy.typing as npt

class Error(Exception):
    file: Optional[str]
    line: Optional[int]  # 1-based
    offset: Optional[int]  # bytes into the file
    message: str

class Chunk:
    def __len__(self) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...  # t×3×3
    @property
    def normals(self) -> Optional[npt.NDArray[np.float32]]: ...  # t×3×3
    @property
    def colors(self) -> Optional[npt.NDArray[np.float32]]: ...  # t×3×4
    @property
    def uvs(self) -> list[npt.NDArray[np.float32]]: ...  # t×3×2 each
    @property
    def vertex_scalars(self) -> dict[str, npt.NDArray[np.float64]]: ...  # t×3 each
    @property
    def face_scalars(self) -> dict[str, npt.NDArray[np.float64]]: ...  # t each
    @property
    def materials(self) -> Optional[npt.NDArray[np.uint32]]: ...  # t
    @property
    def vertex_ids(self) -> Optional[npt.NDArray[np.uint64]]: ...  # t×3

class ChunkReader(Iterator[Chunk]):
    def __init__(self, path: str, capacity: int = ..., **flags: Any) -> None: ...
    def __iter__(self) -> ChunkReader: ...
    def __next__(self) -> Chunk: ...
    @property
    def channels(self) -> dict[str, Any]: ...
    @property
    def materials(self) -> list[dict[str, Any]]: ...
    @property
    def triangle_count(self) -> Optional[int]: ...
    @property
    def sorted_axis(self) -> Optional[int]: ...

def convert(src: str, dst: str, *, progress: Any = ..., **flags: Any) -> dict[str, Any]: ...
def sort(src: str, dst: str, *, progress: Any = ..., **flags: Any) -> dict[str, Any]: ...
def decimate(src: str, dst: str, *, progress: Any = ..., **flags: Any) -> dict[str, Any]: ...
def info(path: str, *, progress: Any = ..., **flags: Any) -> dict[str, Any]: ...
def compare(a: str, b: str, *, progress: Any = ..., **flags: Any) -> dict[str, Any]: ...
