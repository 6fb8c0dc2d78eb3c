"""The first-hour notebook (crates/python/examples/first-hour.ipynb) runs, cell by cell,
in a fresh kernel, so that it never goes stale."""

from __future__ import annotations

from pathlib import Path

import nbformat
from nbclient import NotebookClient

NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "first-hour.ipynb"


def test_the_first_hour_notebook_runs(tmp_path):
    # (the kernel draws its figures with matplotlib's inline backend: PNG outputs, no
    # display needed)
    nb = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    ).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "late scanline(s)" in text and "settings measured" in text
    # every plot was drawn
    assert sum(1 for o in outputs if "image/png" in o.get("data", {})) >= 3
