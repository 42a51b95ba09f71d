"""Every notebook runs top to bottom on the learner's default track (``exercises``) without an error.

nbval (the second half of ``./workshop test``) re-runs the notebooks on the ``solutions`` track and compares
their outputs; this test makes sure a learner who has not written anything yet is never stuck on a traceback.
"""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = sorted((Path(__file__).resolve().parents[2] / "notebooks").glob("[0-9][0-9]_*.ipynb"))


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_on_exercises_track(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The notebook executes without an exception on the untouched exercises."""
    monkeypatch.setenv("RRBOT_WORKSHOP_TRACK", "exercises")
    monkeypatch.setenv("PYTHONPATH", str(path.parents[1]))
    nb = nbformat.read(path, as_version=4)
    client = NotebookClient(
        nb,
        timeout=600,
        kernel_name="python3",
        resources={"metadata": {"path": str(path.parent)}},
        allow_errors=False,
    )
    client.execute()
    errors = [
        out
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if out.get("output_type") == "error"
    ]
    assert not errors, f"{path.name} raised: {errors[0].get('ename')}: {errors[0].get('evalue')}"
