"""Where the tests find the repository's scenes and the `glint` program
whose output the package must match: $GLINT, else target/{debug,release}/glint."""

from __future__ import annotations

import os
import pathlib
import shutil

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"


def glint_program() -> str:
    given = os.environ.get("GLINT")
    if given:
        return given
    for profile in ("debug", "release"):
        candidate = REPO / "target" / profile / "glint"
        if candidate.exists():
            return str(candidate)
    found = shutil.which("glint")
    if found:
        return found
    pytest.fail("no glint program: build it (cargo build) or set GLINT")


@pytest.fixture(scope="session")
def glint_bin() -> str:
    return glint_program()
