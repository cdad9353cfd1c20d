"""The guide's notebook (`docs/guide/python.ipynb`) runs headless, top to bottom."""

from __future__ import annotations

import pytest

from conftest import ROOT


def test_guide_notebook_executes(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    path = ROOT / "docs" / "guide" / "python.ipynb"
    notebook = nbformat.read(path, as_version=4)
    # the kernel inherits the environment: its files go to tmp_path, never
    # into the checkout (an `out/` there would change what the Rust docs test checks)
    monkeypatch.setenv("RELDESIGN_GUIDE_OUT", str(tmp_path))
    client = nbclient.NotebookClient(
        notebook,
        timeout=600,
        kernel_name="python3",
        resources={"metadata": {"path": str(path.parent)}},
    )
    client.execute()
    errors = [
        output
        for cell in notebook.cells
        if cell.cell_type == "code"
        for output in cell.get("outputs", [])
        if output.get("output_type") == "error"
    ]
    assert not errors
    assert (tmp_path / "resistances.png").exists()
    assert not (ROOT / "out" / "guide-python").exists()
