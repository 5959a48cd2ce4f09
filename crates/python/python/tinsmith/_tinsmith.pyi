"""Type stubs of the extension module (the Rust side of ``tinsmith``)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

DEFAULT_TILE_SIZE: int

class BoundError(Exception):
    """A mesh failed its own verification (never expected; nothing returned or written)."""

class Tin:
    """A TIN within ``max_error`` of every valid sample, measured by the verifier."""

    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """N x 3 float64 (x, y, z); read-only."""
    @property
    def triangles(self) -> npt.NDArray[np.uint32]:
        """M x 3 uint32 indices into ``vertices``, counter-clockwise; read-only."""
    @property
    def max_error(self) -> float:
        """The largest |sample - TIN| the verifier measured."""
    @property
    def report(self) -> Dict[str, Any]:
        """The fields of ``tinsmith mesh --report``."""
    def write(
        self,
        path: Union[str, "PathLike[str]"],
        format: Optional[str] = None,
        crs: Union[str, int, Any, None] = None,
        base: Optional[float] = None,
        normals: bool = False,
    ) -> None:
        """Write the TIN as ply, obj, stl, glb, geojson, fgb or landxml; ``base`` closes an
        STL into a solid with a floor at that height, ``normals`` adds glTF normals."""
    def to_trimesh(self) -> Any:
        """The TIN as a ``trimesh.Trimesh``."""
    def __len__(self) -> int: ...

def mesh(
    heights: npt.NDArray[Any],
    choices: Dict[str, Any],
    nodata: Optional[float] = None,
    mask: Optional[npt.NDArray[np.bool_]] = None,
    transform: Optional[Sequence[float]] = None,
) -> Tin: ...
def verify(
    heights: npt.NDArray[Any],
    vertices: npt.NDArray[np.float64],
    triangles: npt.NDArray[np.int64],
    max_error: Optional[float] = None,
    nodata: Optional[float] = None,
    mask: Optional[npt.NDArray[np.bool_]] = None,
    transform: Optional[Sequence[float]] = None,
) -> Dict[str, Any]: ...
def contour(
    heights: npt.NDArray[Any],
    interval: Optional[float] = None,
    levels: Optional[List[float]] = None,
    offset: Optional[float] = None,
    max_error: Optional[float] = None,
    simplify: Optional[float] = None,
    nodata: Optional[float] = None,
    mask: Optional[npt.NDArray[np.bool_]] = None,
    transform: Optional[Sequence[float]] = None,
) -> List[Tuple[float, bool, List[Tuple[float, float]]]]: ...
