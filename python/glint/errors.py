"""The exceptions Glint raises.

Every error of Glint's own is a :class:`GlintError`. A scene that cannot be
loaded is a :class:`SceneError`, which is also a :class:`ValueError` and says
where: ``file``, ``line`` and ``column`` (1-based) and ``field`` (the dotted
path of the key, e.g. ``sphere[2].radius``). A scene file that does not exist
is Python's own :class:`FileNotFoundError`; a bad argument (an unknown
setting, a wrongly shaped array) is a :class:`TypeError` or
:class:`ValueError`.
"""

from __future__ import annotations

from typing import Optional

__all__ = ["GlintError", "SceneError"]


class GlintError(Exception):
    """An error of Glint's own: a file it cannot read or write, a render that failed."""


class SceneError(GlintError, ValueError):
    """A scene that cannot be loaded, with where in its file."""

    def __init__(
        self,
        message: str,
        file: Optional[str] = None,
        line: Optional[int] = None,
        column: Optional[int] = None,
        field: Optional[str] = None,
    ) -> None:
        super().__init__(message)
        self.file = file
        self.line = line
        self.column = column
        self.field = field
