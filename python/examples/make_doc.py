"""docs/python.md, made from the example notebook glint.ipynb beside this file.

    python python/examples/make_doc.py

runs every cell (nbclient, a kernel of this Python with `glint` installed) and
writes the notebook as Markdown: its Markdown cells as they are, with links
made relative to docs/; each code cell as a Python block followed by what it
printed and returned, text as a text block, a picture as a PNG beside the page
(docs/python-N.png). The pytest suite runs the same and fails where the page
differs, so the page is what the notebook does."""

from __future__ import annotations

import base64
import os
import pathlib
import re
import sys
import tempfile
from typing import Dict, List, Tuple

import nbformat
from nbclient import NotebookClient

HERE = pathlib.Path(__file__).resolve().parent
NOTEBOOK = HERE / "glint.ipynb"
DOCS = HERE.parents[1] / "docs"
PAGE = DOCS / "python.md"
PICTURE = "python-{}.png"
LINK = re.compile(r"\]\(([^)#:]+)(#[^)]*)?\)")


def executed(path: pathlib.Path = NOTEBOOK) -> nbformat.NotebookNode:
    """The notebook with every cell run, in its own folder."""
    notebook = nbformat.read(path, as_version=4)
    client = NotebookClient(notebook, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(path.parent)}})
    client.execute()
    return notebook


def markdown(notebook: nbformat.NotebookNode) -> Tuple[str, Dict[str, bytes]]:
    """The page's text and its pictures by file name."""
    parts: List[str] = []
    pictures: Dict[str, bytes] = {}
    for cell in notebook.cells:
        if cell.cell_type == "markdown":
            parts.append(relinked(cell.source))
        elif cell.cell_type == "code":
            parts.append(f"```python\n{cell.source}\n```")
            parts.extend(shown(cell.outputs, pictures))
    return "\n\n".join(parts) + "\n", pictures


def relinked(text: str) -> str:
    """Relative link targets, written from the notebook's folder, made from docs/."""
    def move(match: re.Match) -> str:
        target = os.path.normpath(HERE / match.group(1))
        return f"]({os.path.relpath(target, DOCS)}{match.group(2) or ''})"
    return LINK.sub(move, text)


def shown(outputs: List[nbformat.NotebookNode], pictures: Dict[str, bytes]) -> List[str]:
    """A cell's outputs as the page shows them: consecutive text in one block."""
    blocks: List[str] = []
    text: List[str] = []

    def flush() -> None:
        if text:
            blocks.append("```text\n" + "".join(text).rstrip("\n") + "\n```")
            text.clear()

    for output in outputs:
        if output.output_type == "stream":
            text.append(output.text)
        elif output.output_type == "error":
            raise RuntimeError(f"a cell failed: {output.ename}: {output.evalue}")
        elif "image/png" in output.data:
            flush()
            name = PICTURE.format(len(pictures) + 1)
            pictures[name] = base64.b64decode(output.data["image/png"])
            blocks.append(f"![the cell's picture]({name})")
        elif "text/plain" in output.data:
            text.append(output.data["text/plain"] + "\n")
    flush()
    return blocks


def write_atomically(path: pathlib.Path, data: bytes) -> None:
    with tempfile.NamedTemporaryFile(dir=path.parent, delete=False) as out:
        out.write(data)
    os.replace(out.name, path)


def main() -> int:
    page, pictures = markdown(executed())
    for name, data in pictures.items():
        write_atomically(DOCS / name, data)
    write_atomically(PAGE, page.encode())
    # Only once the new page is in place: pictures it no longer shows.
    for stale in DOCS.glob(PICTURE.format("*")):
        if stale.name not in pictures:
            stale.unlink()
    print(f"wrote {PAGE} and {len(pictures)} pictures")
    return 0


if __name__ == "__main__":
    sys.exit(main())
