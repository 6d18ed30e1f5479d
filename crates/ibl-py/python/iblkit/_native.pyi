"""Type stubs of iblkit's Rust extension (crates/ibl-py/src). Images are float32 (H, W, 3)."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike]
_Image = npt.NDArray[np.float32]
_Rows = npt.NDArray[np.float64]
_Progress = Optional[Callable[[str, int, int], Any]]

__version__: str

class IblError(Exception):
    """Base class of every iblkit error."""

class BadInputError(IblError):
    """The input is at fault (the `ibl` command's exit status 2)."""

class InternalError(IblError):
    """iblkit failed on good input (exit status 1)."""

class LightSet:
    """Directional lights in iblkit's world frame; `len()` is the number of lights."""

    @property
    def directions(self) -> _Rows: ...
    @property
    def radiance(self) -> _Rows: ...
    @property
    def irradiance(self) -> _Rows: ...
    @property
    def solid_angles(self) -> npt.NDArray[np.float64]: ...
    @property
    def shadow_solid_angles(self) -> npt.NDArray[np.float64]: ...
    @property
    def shadow_core_fractions(self) -> npt.NDArray[np.float64]: ...
    @property
    def method(self) -> str: ...
    @property
    def total_power(self) -> List[float]: ...
    def irradiance_at(self, normals: npt.ArrayLike) -> _Rows: ...
    def to_json(self, frame: str = "gltf") -> str: ...
    def write(self, path: _Path, frame: str = "gltf", lux_per_unit: float = 1.0) -> None: ...
    def __len__(self) -> int: ...

# Images (images.rs)
def read_image(path: _Path) -> _Image: ...
def read_probe(
    path: _Path, mapping: Optional[str] = None, progress: _Progress = None
) -> Tuple[_Image, Dict[str, Any]]: ...
def write_image(
    path: _Path, image: npt.ArrayLike, exposure: Optional[float] = None, curve: str = "reinhard"
) -> None: ...
def convert(
    image: npt.ArrayLike,
    source: str,
    target: str = "latlong",
    width: Optional[int] = None,
    rotation: Tuple[float, float, float] = (0.0, 0.0, 0.0),
    progress: _Progress = None,
) -> _Image: ...
def detect_mapping(width: int, height: int) -> Optional[str]: ...
def info(path: _Path, mapping: Optional[str] = None) -> Dict[str, Any]: ...
def names() -> Dict[str, List[str]]: ...

# Lights (lights.rs)
def extract_lights(
    probe: npt.ArrayLike,
    n: int,
    method: str = "median-cut",
    seed: Optional[int] = None,
    fit_domain: str = "hemispheres",
) -> LightSet: ...
def read_lights(path: _Path) -> LightSet: ...
def lights_job(
    probe: _Path,
    n: int,
    outputs: List[_Path],
    method: str = "median-cut",
    seed: Optional[int] = None,
    mapping: Optional[str] = None,
    overlay: Optional[_Path] = None,
    ambient_sh: Optional[int] = None,
    progress: _Progress = None,
    fit_domain: str = "hemispheres",
) -> LightSet: ...

# Spherical harmonics (sh.rs)
def sh_project(
    probe: npt.ArrayLike, bands: int = 3, window: str = "none", irradiance: bool = False
) -> _Rows: ...
def sh_to_format(coefficients: _Rows, format: str) -> str: ...
def sh_from_format(text: str, format: str) -> _Rows: ...
def sh_irradiance(coefficients: _Rows, normals: npt.ArrayLike, window: str = "none") -> _Rows: ...

# Ground truth and metrics (evaluation.rs)
def fibonacci_normals(m: int) -> _Rows: ...
def ground_truth_irradiance(probe: npt.ArrayLike, normals: npt.ArrayLike) -> _Rows: ...
def irradiance_error(truth: _Rows, approx: _Rows) -> Dict[str, float]: ...
def evaluate_lights(probe: npt.ArrayLike, lights: LightSet, normals: int = 2000) -> Dict[str, float]: ...
def compare_images(test: npt.ArrayLike, reference: npt.ArrayLike) -> Dict[str, Any]: ...

# Maps (maps.rs)
def irradiance_map(
    probe: npt.ArrayLike, width: int = 64, method: str = "exact", mapping: str = "latlong", bands: int = 3
) -> _Image: ...
def prefilter(
    probe: npt.ArrayLike,
    face_size: int = 64,
    samples: int = 64,
    target: str = "filament",
    latlong_width: Optional[int] = None,
    irradiance_face: Optional[int] = None,
    progress: _Progress = None,
) -> Dict[str, Any]: ...
def dfg_table(size: int = 128, samples: int = 1024, layout: str = "scale-bias") -> _Image: ...

# Scenes (scene.rs)
def render_scene(
    scene: _Path,
    output: _Path,
    mode: Optional[str] = None,
    lights: Optional[int] = None,
    method: Optional[str] = None,
    spp: Optional[int] = None,
    width: Optional[int] = None,
    seed: Optional[int] = None,
    progress: _Progress = None,
) -> Tuple[_Image, Dict[str, Any]]: ...

# Batches (batch.rs)
def batch_plan(spec: _Path, retry_failed: bool = False) -> Dict[str, Any]: ...
def batch_run_item(spec: _Path, id: str, probe: _Path) -> Dict[str, Any]: ...
def batch_finish(spec: _Path, ran: int = 0, skipped: int = 0) -> Dict[str, Any]: ...
def run_batch(
    spec: _Path, jobs: int = 1, retry_failed: bool = False, progress: _Progress = None
) -> Dict[str, Any]: ...
