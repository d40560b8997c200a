"""Type stubs of the extension module ``motorfactory._core`` (checked against it by mypy's
stubtest)."""

from os import PathLike
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt

PRESETS: List[str]
CONFIGS: List[str]
__version__: str
__all__ = [
    "CONFIGS",
    "PRESETS",
    "Generator",
    "Motor",
    "Part",
    "Scan",
    "Station",
    "__version__",
    "motor",
    "scan",
    "write",
]

_Cloud = Dict[str, npt.NDArray[Any]]

@final
class Part:
    """One part of a motor: a closed mesh with its labels (motor frame, metres)."""

    name: str
    kind: str
    class_id: int
    instance: int
    @property
    def vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def triangles(self) -> npt.NDArray[np.uint32]: ...
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]: ...

@final
class Motor:
    """A built motor: its parts, parameters and ground truth."""

    @property
    def parts(self) -> List[Part]: ...
    @property
    def attributes(self) -> Dict[str, Any]: ...
    @property
    def params(self) -> Dict[str, Any]: ...
    def save(
        self,
        folder: Union[str, PathLike[str]],
        formats: Sequence[str] = ...,
        per_part: bool = True,
        replace: bool = False,
    ) -> List[str]: ...
    def __reduce__(self) -> Tuple[Any, Tuple[str, str]]: ...

def motor(
    params: Optional[Mapping[str, Any]] = None,
    seed: int = 0,
    random: bool = False,
    detail: str = "normal",
) -> Motor: ...

@final
class Scan:
    """A scan: the sensor's organized image, pixel by pixel (rows x columns)."""

    @property
    def xyz(self) -> npt.NDArray[np.float32]: ...
    @property
    def normal(self) -> npt.NDArray[np.float32]: ...
    @property
    def depth(self) -> npt.NDArray[np.float32]: ...
    @property
    def label(self) -> npt.NDArray[np.uint16]: ...
    @property
    def instance(self) -> npt.NDArray[np.uint32]: ...
    @property
    def intensity(self) -> npt.NDArray[np.float32]: ...
    @property
    def pose(self) -> npt.NDArray[np.float32]: ...
    def points(self) -> _Cloud: ...
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]: ...

_Mesh = Union[
    str,
    PathLike[str],
    Tuple[npt.NDArray[np.float32], npt.NDArray[np.uint32], int, int],
]

def scan(
    meshes: List[_Mesh],
    sensor: str = "zivid-2plus-m130",
    eye: Tuple[float, float, float] = ...,
    target: Tuple[float, float, float] = ...,
    up: Tuple[float, float, float] = ...,
    seed: int = 0,
    sampling: str = "all",
    material: str = "grey-plastic",
) -> Scan: ...

def write(
    out: Union[str, PathLike[str]],
    config: Union[None, str, PathLike[str], Mapping[str, Any]] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    overrides: Optional[Mapping[str, Any]] = None,
    shard: Tuple[int, int] = ...,
    resume: bool = False,
) -> Dict[str, Any]: ...

@final
class Generator:
    """Dataset samples made in memory: ``Generator(config)[i]`` is sample ``i``."""

    def __new__(
        cls,
        config: Union[None, str, PathLike[str], Mapping[str, Any]] = None,
        seed: Optional[int] = None,
        overrides: Optional[Mapping[str, Any]] = None,
        samples: Optional[int] = None,
    ) -> Generator: ...
    def __len__(self) -> int: ...
    def __reduce__(self) -> Tuple[Any, Tuple[Dict[str, Any]]]: ...
    def __getitem__(self, index: int, /) -> Dict[str, Any]: ...
    def sample_at(self, index: int) -> Dict[str, Any]: ...
    def indices(self, split: Optional[str] = None) -> List[int]: ...
    def split_of(self, index: int) -> str: ...
    @property
    def classes(self) -> List[str]: ...
    @property
    def config(self) -> str: ...

@final
class Station:
    """One motor of a dataset configuration clamped at the inspection station, viewed one view
    at a time."""

    def __new__(
        cls,
        config: Union[None, str, PathLike[str], Mapping[str, Any]] = None,
        index: int = 0,
        clamping: str = "gear-container-up",
        overrides: Optional[Mapping[str, Any]] = None,
        density: float = 2e5,
        radius: float = 0.002,
        max_angle: float = 75.0,
    ) -> Station: ...
    @property
    def centre(self) -> Tuple[float, float, float]: ...
    @property
    def working_range(self) -> Tuple[float, float]: ...
    @property
    def views(self) -> int: ...
    def restart(self) -> None: ...
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...], List[List[float]]]: ...
    def __setstate__(self, taken: Sequence[Sequence[float]], /) -> None: ...
    def camera_pose(
        self, azimuth: float, elevation: float, distance: float, roll: float = 0.0
    ) -> List[List[float]]: ...
    def capture(
        self, azimuth: float, elevation: float, distance: float, roll: float = 0.0
    ) -> Dict[str, Any]: ...
    def predict(
        self, azimuth: float, elevation: float, distance: float, roll: float = 0.0
    ) -> float: ...
    @property
    def seen(self) -> npt.NDArray[np.bool_]: ...
    def coverage(self) -> Tuple[float, List[Tuple[str, float]]]: ...
    def surface(self) -> Dict[str, Any]: ...
