"""The example notebook runs, every cell, in a kernel of this Python, and
docs/python.md is what it prints: make_doc.py's page of it, pictures too."""

from __future__ import annotations

import difflib
import importlib.util
import pathlib

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
spec = importlib.util.spec_from_file_location("make_doc", EXAMPLES / "make_doc.py")
make_doc = importlib.util.module_from_spec(spec)
spec.loader.exec_module(make_doc)


def test_the_notebook_runs_and_is_the_python_page():
    notebook = make_doc.executed()
    page, pictures = make_doc.markdown(notebook)
    # The render cell shows the image as a PNG, and the grade cell's report says one fails.
    assert "python-1.png" in pictures and "1 pass, 1 fail" in page
    written = make_doc.PAGE.read_text()
    stale = "docs/python.md is not what the notebook prints; run: python python/examples/make_doc.py\n"
    assert page == written, stale + "".join(
        difflib.unified_diff(written.splitlines(True), page.splitlines(True), "docs/python.md", "notebook"))
    on_disk = {p.name for p in make_doc.DOCS.glob(make_doc.PICTURE.format("*"))}
    assert on_disk == set(pictures), stale
    for name, data in pictures.items():
        assert (make_doc.DOCS / name).read_bytes() == data, stale + f"({name} differs)"


def test_links_are_moved_from_the_notebook_to_docs():
    assert make_doc.relinked("[a](../../docs/grading.md#x) [b](glint.ipynb) [c](https://x.org/a)") == (
        "[a](grading.md#x) [b](../python/examples/glint.ipynb) [c](https://x.org/a)")
