"""Glint from Python: load a scene, render it to a numpy array, explain a
pixel, read, write and compare images.

>>> import glint
>>> scene = glint.load("scenes/cornell-set1.toml", spp=4, resolution=(64, 64))
>>> image = scene.render()            # float32 (64, 64, 3), linear radiance
>>> image.shape
(64, 64, 3)

Settings are the keywords of ``glint render``'s flags, ``-`` written ``_``:
``spp``, ``light_samples``, ``pixel_sampler`` (``--sampler``),
``light_sampler``, ``max_depth``, ``environment_samples``,
``environment_sampler``, ``environment_sampling``, ``area_sampling``, ``mis``
(``mis=False`` is ``--no-mis``), ``seed``, ``resolution`` (``(w, h)`` or
``"WxH"``), ``texture_filter``, ``texture_level``. The same scene, settings
and seed give the bytes ``glint render`` writes, bit for bit.
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, Mapping, Optional, Tuple, Union

import numpy as np

from . import _glint
from .errors import GlintError, SceneError

__all__ = [
    "GlintError",
    "Image",
    "Scene",
    "SceneError",
    "diff",
    "grade",
    "grade_class",
    "GradeReport",
    "imread",
    "imwrite",
    "load",
    "load_string",
    "load_dict",
    "__version__",
    "cpu_features",
]

__version__: str = _glint.__version__

#: The x86-64 instruction sets this build uses (``pip install ./python``
#: builds for this machine's CPU; a wheel for others for ``x86-64-v3``).
cpu_features: "list[str]" = list(_glint.cpu_features)

PathLike = Union[str, "os.PathLike[str]"]


class Image(np.ndarray):
    """A float32 ``(height, width, 3)`` array of linear RGB that shows itself
    in Jupyter as the PNG ``glint render`` would write (8-bit sRGB).
    ``np.asarray(image)`` is the plain array."""

    def __new__(cls, array: Any) -> "Image":
        return _image_array(array).view(cls)

    def _repr_png_(self) -> bytes:
        return bytes(_glint.encode(_image_array(self), "png"))

    def to_bytes(self, format: str = "png") -> bytes:
        """The image as a ``png``, ``exr`` or ``pfm`` file would hold it."""
        return bytes(_glint.encode(_image_array(self), format))


def _image_array(array: Any) -> np.ndarray:
    """``array`` as a C-contiguous float32 ``(h, w, 3)`` ndarray, or a
    TypeError (another dtype) or ValueError (another shape)."""
    a = np.asarray(array)
    if a.dtype != np.float32:
        raise TypeError(f"an image is float32; this array is {a.dtype} (convert with .astype(np.float32))")
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"an image is (height, width, 3); this array's shape is {a.shape}")
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise ValueError(f"an image has at least one pixel; this array's shape is {a.shape}")
    return np.ascontiguousarray(a).view(np.ndarray)


class Scene:
    """A loaded scene and its render settings. Made by :func:`load`,
    :func:`load_string` or :func:`load_dict`."""

    def __init__(self, inner: "_glint.Scene") -> None:
        self._inner = inner

    @property
    def resolution(self) -> Tuple[int, int]:
        """The film's size, ``(width, height)``."""
        return self._inner.resolution

    @property
    def settings(self) -> Dict[str, Any]:
        """The render settings, by the scene file's ``[render]`` key names."""
        return self._inner.settings

    @property
    def regions(self) -> Dict[str, Tuple[int, int, int, int]]:
        """The file's ``[regions]``: name to ``(x0, y0, x1, y1)``."""
        return self._inner.regions

    def render(
        self,
        *,
        crop: Optional[Tuple[int, int, int, int]] = None,
        aov: Optional[str] = None,
        threads: Optional[int] = None,
        progress: Union[bool, Callable[[int, int], Any], None] = None,
    ) -> Image:
        """The linear radiance (or the buffer ``aov``: ``uv``, ``mip-level``,
        ``normal``, ``depth``, ``albedo``, ...) of the film, or of the window
        ``crop = (x0, y0, x1, y1)`` (half-open), each pixel the whole
        render's. The GIL is released while Glint's threads render; Ctrl-C
        raises :class:`KeyboardInterrupt` within a twentieth of a second.
        ``progress`` is ``progress(done, total)`` in tiles, or ``True`` for a
        bar (``tqdm``, where installed)."""
        callback, close = _progress(progress)
        try:
            array = self._inner.render(crop=crop, aov=aov, threads=threads, progress=callback)
        finally:
            close()
        return array.view(Image)

    def explain(
        self,
        pixel: Tuple[int, int],
        *,
        sample: int = 0,
        all_samples: bool = False,
        stage: Optional[str] = None,
    ) -> Dict[str, Any]:
        """``glint explain SCENE --pixel X,Y --json`` with this scene's
        settings: the ``glint-explain/1`` document as a dict."""
        return json.loads(self.explain_json(pixel, sample=sample, all_samples=all_samples, stage=stage))

    def explain_json(
        self,
        pixel: Tuple[int, int],
        *,
        sample: int = 0,
        all_samples: bool = False,
        stage: Optional[str] = None,
    ) -> str:
        """:meth:`explain` as the text ``glint explain --json`` prints, byte for byte."""
        x, y = pixel
        return self._inner.explain_json(x, y, sample=sample, all_samples=all_samples, stage=stage)

    def explain_against(
        self,
        pixel: Tuple[int, int],
        student: Union[Mapping[str, Any], str, PathLike],
        *,
        sample: int = 0,
        all_samples: bool = False,
        stage: Optional[str] = None,
    ) -> Dict[str, Any]:
        """A student's ``glint-explain/1`` document (a dict, JSON text, or
        the path of a ``.json`` file) against Glint's for this pixel:
        ``glint explain --against STUDENT.json --json``'s comparison, with
        the first stage where they part."""
        if isinstance(student, Mapping):
            text = json.dumps(student)
        elif isinstance(student, os.PathLike) or (isinstance(student, str) and not student.lstrip().startswith("{")):
            with open(os.fspath(student), encoding="utf-8") as f:
                text = f.read()
        else:
            text = student
        x, y = pixel
        document = self._inner.explain_json(
            x, y, sample=sample, all_samples=all_samples, stage=stage, against=text
        )
        return json.loads(document)


def _progress(progress: Any) -> Tuple[Optional[Callable[[int, int], Any]], Callable[[], None]]:
    """A ``(done, total)`` callback for ``progress``, and what closes it."""
    if progress is None or progress is False:
        return None, lambda: None
    if progress is True:
        try:
            from tqdm.auto import tqdm  # type: ignore[import-not-found]
        except ImportError:
            return None, lambda: None
        bar = tqdm(unit="tile")

        def update(done: int, total: int) -> None:
            bar.total = total
            bar.n = done
            bar.refresh()

        return update, bar.close
    return progress, lambda: None


def load(path: PathLike, **settings: Any) -> Scene:
    """Loads the scene file at ``path`` (TOML, docs/scene-format.md) and the
    assets it names, with ``settings`` replacing the file's."""
    return Scene(_glint.load(os.fspath(path), settings))


def load_string(text: str, *, base_dir: PathLike = ".", name: str = "<string>", **settings: Any) -> Scene:
    """A scene from TOML text, its asset paths relative to ``base_dir``."""
    return Scene(_glint.parse(text, name, os.fspath(base_dir), settings))


def load_dict(tables: Mapping[str, Any], *, base_dir: PathLike = ".", **settings: Any) -> Scene:
    """A scene from a dict of the scene file's tables (``{"camera": {...},
    "sphere": [{...}], ...}``), its asset paths relative to ``base_dir``."""
    if not isinstance(tables, Mapping):
        raise TypeError(f"a scene dict is a mapping of tables; got {type(tables).__name__}")
    return Scene(_glint.parse(dict(tables), "<dict>", os.fspath(base_dir), settings))


def imread(path: PathLike) -> Image:
    """Reads an image of any format Glint reads (PNG, JPEG, BMP, TGA, PPM,
    Radiance HDR, OpenEXR, PFM) as linear RGB; ``.format`` says what it was
    read as."""
    array, description = _glint.imread(os.fspath(path))
    image = array.view(Image)
    image.format = description  # type: ignore[attr-defined]
    return image


def imwrite(path: PathLike, image: Any) -> None:
    """Writes a float32 ``(h, w, 3)`` linear image: ``.png`` as 8-bit sRGB,
    ``.exr`` or ``.pfm`` as 32-bit float; atomically (a failed write leaves
    what was at ``path``)."""
    _glint.imwrite(os.fspath(path), _image_array(image))


def diff(test: Any, reference: Any) -> Dict[str, Any]:
    """``glint diff``'s measures of ``test`` against ``reference``: ``rmse``,
    ``rel_mse``, ``flip`` (mean), ``max_difference`` and its pixel, and each
    image's channel means."""
    return _glint.diff(_image_array(test), _image_array(reference))


class GradeReport:
    """``glint grade``'s verdicts on a scene's submissions: ``passed`` (every
    one), ``submissions`` (one dict each: ``verdict``, ``rejected`` regions
    with their channels' z, ...), ``heatmaps`` (each graded submission's
    ``--heatmap`` picture as a uint8 ``(h, w, 3)`` array, else None), and
    ``to_dict()``, the document ``glint grade --format json`` prints."""

    def __init__(self, graded: Tuple[str, "list[Optional[np.ndarray]]"]) -> None:
        text, self.heatmaps = graded
        self._document = json.loads(text)

    @property
    def passed(self) -> bool:
        return self._document["pass"] == len(self._document["submissions"])

    @property
    def submissions(self) -> "list[Dict[str, Any]]":
        return self._document["submissions"]

    def to_dict(self) -> Dict[str, Any]:
        return json.loads(json.dumps(self._document))

    def __repr__(self) -> str:
        d = self._document
        return f"<GradeReport: {d['pass']} pass, {d['fail']} fail, {d['unreadable']} unreadable>"


#: The settings submissions state, by ``glint grade``'s flag names
#: (``pixel_sampler`` for ``--sampler``).
STATED = ("spp", "pixel_sampler", "light_samples", "light_sampler")


def _stated(stated: Mapping[str, Any]) -> Dict[str, Any]:
    unknown = sorted(set(stated) - set(STATED))
    if unknown:
        raise TypeError(f"unknown stated setting {unknown[0]!r}; the stated settings are {', '.join(STATED)}")
    return {name: stated.get(name) for name in STATED}


def grade(
    scene: Union[PathLike, Scene],
    *submissions: Any,
    alpha: float = 0.01,
    block: Optional[int] = None,
    cache: Optional[PathLike] = None,
    mistakes: bool = False,
    **stated: Any,
) -> GradeReport:
    """Grades image files or float32 ``(h, w, 3)`` arrays against ``scene``
    (a scene file, or a :class:`Scene` from :func:`load_string` or
    :func:`load_dict`, its settings replaced or not) as ``glint grade SCENE
    IMAGE...`` does, under the settings the submissions state
    (:data:`STATED`: ``spp``, ``pixel_sampler``, ``light_samples``,
    ``light_sampler``), at significance ``alpha``; references are cached in
    ``cache`` where given (a scene from memory by its text and replaced
    settings, a file by its bytes). An array is graded as the lossless PFM
    file of its values. With ``mistakes``, a failing submission is also
    tested against the classic mistakes, as ``glint grade`` does by default
    (``likely_mistakes``; each mistake is rendered once and cached)."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="glint-grade-") as folder:
        files = []
        for k, submission in enumerate(submissions):
            if isinstance(submission, (str, os.PathLike)):
                files.append(os.fspath(submission))
            else:
                path = os.path.join(folder, f"submission-{k}.pfm")
                imwrite(path, submission)
                files.append(path)
        if not files:
            raise ValueError("give the images to grade after the scene")
        against = scene._inner if isinstance(scene, Scene) else os.fspath(scene)
        graded = _glint.grade_json(against, files, _stated(stated), alpha, block, _path(cache), mistakes)
    return GradeReport(graded)


def grade_class(
    submissions: PathLike,
    *,
    scenes: Optional[PathLike] = None,
    alpha: float = 0.01,
    block: Optional[int] = None,
    cache: Optional[PathLike] = None,
    mistakes: bool = False,
    **stated: Any,
) -> GradeReport:
    """Grades a class as ``glint grade --class`` does: ``submissions`` is a
    folder of ``STUDENT/SCENE.EXT`` images or a CSV manifest
    (``student,scene,file``, and settings columns where students differ),
    the scenes ``NAME.toml`` in ``scenes`` (else beside it); the rest as
    :func:`grade`."""
    graded = _glint.grade_class_json(
        os.fspath(submissions), _path(scenes), _stated(stated), alpha, block, _path(cache), mistakes
    )
    return GradeReport(graded)


def _path(path: Optional[PathLike]) -> Optional[str]:
    return None if path is None else os.fspath(path)
