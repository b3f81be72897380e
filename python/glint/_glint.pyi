"""The extension module behind :mod:`glint` (Rust, pyo3). Use :mod:`glint`."""

from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
cpu_features: list[str]

class Scene:
    @property
    def resolution(self) -> Tuple[int, int]: ...
    @property
    def settings(self) -> Dict[str, Any]: ...
    @property
    def regions(self) -> Dict[str, Tuple[int, int, int, int]]: ...
    def render(
        self,
        *,
        crop: Optional[Tuple[int, int, int, int]] = None,
        aov: Optional[str] = None,
        threads: Optional[int] = None,
        progress: Optional[Callable[[int, int], Any]] = None,
    ) -> npt.NDArray[np.float32]: ...
    def explain_json(
        self,
        x: int,
        y: int,
        *,
        sample: int = 0,
        all_samples: bool = False,
        stage: Optional[str] = None,
        against: Optional[str] = None,
    ) -> str: ...

def load(path: str, overrides: Dict[str, Any]) -> Scene: ...
def parse(scene: Any, name: str, base_dir: str, overrides: Dict[str, Any]) -> Scene: ...
def imread(path: str) -> Tuple[npt.NDArray[np.float32], str]: ...
def imwrite(path: str, image: npt.NDArray[np.float32]) -> None: ...
def encode(image: npt.NDArray[np.float32], format: str) -> bytes: ...
def diff(test: npt.NDArray[np.float32], reference: npt.NDArray[np.float32]) -> Dict[str, Any]: ...
def main(program: str, args: list[str]) -> int: ...
def grade_json(
    scene: Union[str, Scene],
    files: list[str],
    stated: Dict[str, Any],
    alpha: float = 0.01,
    block: Optional[int] = None,
    cache: Optional[str] = None,
    mistakes: bool = False,
) -> Tuple[str, list[Optional[npt.NDArray[np.uint8]]]]: ...
def grade_class_json(
    submissions: str,
    scenes: Optional[str],
    stated: Dict[str, Any],
    alpha: float = 0.01,
    block: Optional[int] = None,
    cache: Optional[str] = None,
    mistakes: bool = False,
) -> Tuple[str, list[Optional[npt.NDArray[np.uint8]]]]: ...
