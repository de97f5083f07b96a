# SPDX-License-Identifier: MIT
# Type stubs for the cbrdf module (docstrings: help(cbrdf.<name>)).
import os
from typing import Any, Callable, Literal, Sequence, TypedDict, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
MERL_SCALE: tuple[float, float, float]
SHAPE: tuple[int, int, int, int]
CONTAINER_VERSION: tuple[int, int]
COPULA_FAMILIES: tuple[str, ...]

# A path to read (bytes there are the file's contents) and a path to write (bytes too, as
# os.fsencode gives them; a str with surrogate escapes names the same non-UTF-8 file).
_Path = Union[str, os.PathLike[str], os.PathLike[bytes]]
_OutPath = Union[str, bytes, os.PathLike[str], os.PathLike[bytes]]
_Bytes = Union[bytes, bytearray, memoryview]
_Units = Literal["physical", "stored"]
_Count = Union[int, Literal["auto"]]
_Dirs = npt.ArrayLike

class ErrorCode:
    OK: int
    IO: int
    NOT_FOUND: int
    TRUNCATED: int
    BAD_SIGNATURE: int
    UNSUPPORTED: int
    CORRUPT: int
    CHECKSUM: int
    LIMIT: int
    INVALID_ARGUMENT: int
    NUMERIC: int
    INTERNAL: int
    CANCELLED: int
    NAMES: dict[int, str]

class Error(ValueError):
    message: str
    code: int
    code_name: str
    exit_code: int
    def __init__(
        self, message: str, code: int = ..., code_name: str | None = ..., exit_code: int = ...
    ) -> None: ...

class ArgumentTypeError(Error, TypeError):
    def __init__(
        self, message: str, code: int = ..., code_name: str | None = ..., exit_code: int = ...
    ) -> None: ...

class MerlArray(np.ndarray[Any, np.dtype[np.float64]]):
    stored: np.ndarray[Any, np.dtype[np.float64]] | None
    def __new__(
        cls, physical: npt.ArrayLike, stored: np.ndarray[Any, np.dtype[np.float64]] | None = ...
    ) -> MerlArray: ...

class _ChunkInfo(TypedDict):
    tag: str
    offset: int
    stored_bytes: int
    payload_bytes: int
    compressed: bool
    critical: bool
    known: bool

class _ChannelInfo(TypedDict):
    family: str
    theta: float
    scale: float
    components: int

class _SliceInfo(TypedDict):
    theta_d_bins: list[int]
    channels: list[_ChannelInfo]

class _ResidualInfo(TypedDict):
    mode: int  # 0 bounded, 1 exact table, 2 a step per row, 3 interpolated levels, 4 a step per level
    max_error: float  # the bound every measured bin meets (0 in mode 1)
    min_error: float  # the finest row's bound (modes 2 to 4)
    knee: float
    escapes: int
    stored_bytes: int

class ContainerInfo(TypedDict, total=False):
    file: str | None
    format: Literal["cbrdf"]
    version: list[int]
    bytes: int
    chunks: list[_ChunkInfo]
    bits: int
    colour_scale: list[float]
    not_measured_bins: int
    evaluator_bytes: int
    slices: list[_SliceInfo]
    residual: _ResidualInfo  # only in files with the residual layer (1.2)
    metadata: dict[str, str]

class _MerlChannelStats(TypedDict):
    measured: int
    not_measured: int
    zeros: int
    min: float
    max: float
    mean: float

class MerlInfo(TypedDict):
    file: str | None
    format: Literal["merl"]
    dims: list[int]
    folded_from_360: bool
    mask_matches_horizon: bool
    channels: dict[str, _MerlChannelStats]

class _LightMetrics(TypedDict):
    light_angle_deg: float
    psnr_linear: tuple[float, float, float]
    psnr_tonemapped: tuple[float, float, float]
    exposure: float

class SphereMetrics(TypedDict):
    psnr_linear: float
    psnr_tonemapped: float
    per_light: list[_LightMetrics]

class BrdfMetrics(TypedDict):
    rel_rmse: float
    log_rmse: float
    cos_rmse: float
    rel_rmse_rgb: tuple[float, float, float]
    log_rmse_rgb: tuple[float, float, float]
    cos_rmse_rgb: tuple[float, float, float]
    bins: tuple[int, int, int]

class Component:
    family: str
    theta: float
    scale: float
    pdf_h: np.ndarray[Any, np.dtype[np.float64]]
    pdf_d: np.ndarray[Any, np.dtype[np.float64]]
    pdf_p: np.ndarray[Any, np.dtype[np.float64]]

class Channel:
    components: list[Component]
    @property
    def family(self) -> str: ...
    @property
    def theta(self) -> float: ...
    @property
    def scale(self) -> float: ...

class Slice:
    theta_d_begin: int
    theta_d_end: int
    channels: list[Channel]

class CbrdfWarning(UserWarning): ...
class TargetNotMetWarning(CbrdfWarning): ...
class NoisyTableWarning(CbrdfWarning): ...

class Encoded(bytes):
    bits: int
    target_psnr: float | None
    target_bytes: float | None
    target_met: bool | None
    psnr_tonemapped: float | None
    psnr_linear: float | None
    slices: int | None
    components: int | None
    max_error: float | None
    settings_tried: int | None
    note: str | None
    residual_of_smoothed_input: bool | None
    noisy: bool | None
    noise_sigma: float | None
    noise_floor_error: float | None
    psnr_ceiling_tonemapped: float | None
    def __new__(cls, data: bytes = ..., **facts: Any) -> Encoded: ...

class Model:
    def __init__(self, source: _Path | _Bytes) -> None: ...
    @property
    def info(self) -> ContainerInfo: ...
    @property
    def slices(self) -> list[Slice]: ...
    @property
    def file(self) -> str | None: ...
    @property
    def closed(self) -> bool: ...
    @property
    def bits(self) -> int: ...
    @property
    def version(self) -> tuple[int, int]: ...
    @property
    def nbytes(self) -> int: ...
    @property
    def not_measured_bins(self) -> int: ...
    @property
    def footprint_bytes(self) -> int: ...
    def table(self, *, units: _Units = ...) -> np.ndarray[Any, np.dtype[np.float64]]: ...
    @overload
    def eval(
        self, wi: npt.NDArray[np.float32], wo: npt.NDArray[np.float32], threads: int = ...
    ) -> npt.NDArray[np.float32]: ...
    @overload
    def eval(self, wi: _Dirs, wo: _Dirs, threads: int = ...) -> npt.NDArray[np.float64]: ...
    def eval_pair(self, wi: _Dirs, wo: _Dirs) -> tuple[float, float, float]: ...
    def sample(
        self, wo: _Dirs, u: npt.ArrayLike, threads: int = ...
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def sample_pdf(self, wi: _Dirs, wo: _Dirs, threads: int = ...) -> npt.NDArray[np.float64]: ...
    # Deprecated (DeprecationWarning): sample_pdf(wi, wo), the arguments in eval's order.
    def pdf(self, wo: _Dirs, wi: _Dirs, threads: int = ...) -> npt.NDArray[np.float64]: ...
    def bin_value(
        self, channel: npt.ArrayLike, theta_h: npt.ArrayLike, theta_d: npt.ArrayLike,
        phi_d: npt.ArrayLike
    ) -> Any: ...
    def write_merl(self, path: _OutPath) -> None: ...
    def close(self) -> None: ...
    def __enter__(self) -> Model: ...
    def __exit__(self, *exc: object) -> None: ...

_TableLike = Union[npt.ArrayLike, _Path, _Bytes, Model]

def read_merl(source: _Path | _Bytes, *, units: _Units = ...) -> np.ndarray[Any, np.dtype[np.float64]]: ...
def write_merl(
    path: _OutPath, table: _TableLike, mask: npt.ArrayLike | None = ..., *, units: _Units = ...,
    not_measured_value: float = ...
) -> None: ...
def merl_bytes(
    table: _TableLike, mask: npt.ArrayLike | None = ..., *, units: _Units = ...,
    not_measured_value: float = ...
) -> bytes: ...
def samples(kind: Literal["measured", "analytic"] | None = ...) -> list[tuple[str, str]]: ...
def sample_table(name: str, *, units: _Units = ...) -> np.ndarray[Any, np.dtype[np.float64]]: ...
# Deprecated (DeprecationWarning): sample_table(name) is the same table.
def sample(name: str, *, units: _Units = ...) -> np.ndarray[Any, np.dtype[np.float64]]: ...
def encode(
    table: _TableLike, *, bits: _Count = ..., components: _Count = ..., slices: _Count = ...,
    family: Literal["frank", "clayton", "gumbel", "joe", "independence", "auto"] = ...,
    loss: Literal["linear", "cosine", "log"] = ..., level: int = ...,
    placement: Literal["uniform", "adaptive"] = ..., naive_marginals: bool = ...,
    threads: int = ..., target_bytes: float | None = ..., target_psnr: float | None = ...,
    max_error: float | None = ..., lossless: bool = ...,
    mask: npt.ArrayLike | None = ..., source_name: str | None = ...,
    mixture_copulas: Literal["fit", "independence"] | None = ...,
    format_version: Literal["auto", "1.2", "1.3"] = ...,
    metadata: Literal["none", "short", "full"] = ...,
    residual_steps: Literal["one", "visibility"] | None = ...,
    progress: Callable[[float, str], object] | None = ...
) -> Encoded: ...
def decode(source: _Path | _Bytes) -> Model: ...
def info(source: _Path | _Bytes) -> Union[ContainerInfo, MerlInfo]: ...
def sphere_metrics(
    reference: _TableLike, test: _TableLike, *, size: int = ...,
    light_angles: Sequence[float] = ...
) -> SphereMetrics: ...
def sphere_psnr(
    reference: _TableLike, test: _TableLike, tonemapped: bool = ..., *, size: int = ...,
    light_angles: Sequence[float] = ...
) -> float: ...
def brdf_metrics(reference: _TableLike, test: _TableLike) -> BrdfMetrics: ...
def estimate_noise(table: _TableLike) -> dict[str, Any]: ...
def render_sphere(
    brdf: _TableLike, light_angle_deg: float = ..., *, size: int = ...
) -> npt.NDArray[np.float32]: ...
def nearest_bin(
    wi: _Dirs, wo: _Dirs
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.int64]]: ...
def bin_directions(
    theta_h: npt.ArrayLike, theta_d: npt.ArrayLike, phi_d: npt.ArrayLike
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def set_thread_limit(n: int) -> None: ...
def thread_limit() -> int: ...
