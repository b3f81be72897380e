"""The example notebook runs, every cell, in a kernel of this Python."""

from __future__ import annotations

import pathlib

import nbformat
from nbclient import NotebookClient

NOTEBOOK = pathlib.Path(__file__).resolve().parents[1] / "examples" / "glint.ipynb"


def test_the_example_notebook_runs_every_cell():
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = NotebookClient(notebook, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    # The render cell shows the image as a PNG, and the grade cell's report says one fails.
    assert any("image/png" in o.get("data", {}) for o in outputs)
    assert any("1 pass, 1 fail" in o.get("text", "") for o in outputs)
