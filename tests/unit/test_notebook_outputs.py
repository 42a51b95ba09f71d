"""What the course's notebooks show before a learner runs anything: their stored outputs.

A stored output is what every learner sees on opening the notebook, and what nbval compares: it must not carry the
machine that executed it (an absolute path: a home folder, a temporary folder, the clone's own location).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))

#: An absolute POSIX path of two or more parts (``/home/x``, ``/tmp/y/z``) or a Windows drive path.
_ABSOLUTE = re.compile(r"(?<![\w.:/])(/(?:home|root|tmp|work|Users|var|private|opt|usr|mnt|srv)/[^\s'\"<>)]+"
                       r"|[A-Za-z]:\\\\?[^\s'\"<>]+)")


def _texts(output: dict) -> list[str]:
    texts = []
    if "text" in output:
        texts.append("".join(output["text"]) if isinstance(output["text"], list) else str(output["text"]))
    for mime, data in output.get("data", {}).items():
        if mime.startswith("text/") or mime.endswith("json"):
            texts.append("".join(data) if isinstance(data, list) else json.dumps(data))
    if "traceback" in output:
        texts.extend(output["traceback"])
    return texts


def absolute_paths(notebook: Path) -> list[str]:
    """``"cell N: <path>"`` for each absolute path in the notebook's stored outputs."""
    found = []
    for index, cell in enumerate(json.loads(notebook.read_text(encoding="utf-8"))["cells"]):
        for output in cell.get("outputs", []):
            for text in _texts(output):
                found.extend(f"cell {index}: {m}" for m in _ABSOLUTE.findall(text))
    return found


def test_the_course_has_its_notebooks() -> None:
    assert len(NOTEBOOKS) >= 15


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.stem)
def test_no_stored_output_holds_an_absolute_path(notebook: Path) -> None:
    found = absolute_paths(notebook)
    assert not found, f"{notebook.name} shows paths of the machine that executed it: {found[:5]}"


def test_the_check_finds_paths_of_every_kind(tmp_path: Path) -> None:
    outputs = [{"output_type": "stream", "name": "stdout", "text": ["loaded /home/ana/rrbot_workshop/x.urdf\n"]},
               {"output_type": "execute_result", "data": {"text/plain": ["'/tmp/pytest-1/exercises/a.yaml'"]}},
               {"output_type": "error", "traceback": ["File C:\\\\Users\\\\ana\\\\x.py, line 3"]},
               {"output_type": "stream", "name": "stdout", "text": ["exercises/task01/x.xacro and 1/2 and http://127.0.0.1/static/"]}]
    path = tmp_path / "n.ipynb"
    path.write_text(json.dumps({"cells": [{"cell_type": "code", "outputs": outputs}]}))
    found = absolute_paths(path)
    assert len(found) == 3 and all(f.startswith("cell 0: ") for f in found)


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.stem)
def test_cells_showing_what_a_prediction_asks_store_no_output_and_are_not_compared(notebook: Path) -> None:
    """A cell tagged ``outcome`` runs what a prediction exercise (tasks 6 and 14) asks about: a learner opening the
    notebook must not find the answer in it, so it is stored without output and nbval does not compare it."""
    for index, cell in enumerate(json.loads(notebook.read_text(encoding="utf-8"))["cells"]):
        tags = cell.get("metadata", {}).get("tags", [])
        if "outcome" in tags:
            assert not cell.get("outputs"), f"{notebook.name} cell {index} stores an outcome"
            assert "nbval-ignore-output" in tags, f"{notebook.name} cell {index}: nbval would compare its output"


def test_notebook_06_keeps_its_outcomes_out_of_sight() -> None:
    cells = json.loads((ROOT / "notebooks" / "06_lifecycle.ipynb").read_text(encoding="utf-8"))["cells"]
    tagged = ["".join(c["source"]) for c in cells if "outcome" in c.get("metadata", {}).get("tags", [])]
    # the hardware taken to inactive, a cleanup and an unload, a conflicting activation: what the predictions ask
    assert any("set_hardware_component_state rrbot inactive" in s for s in tagged)
    assert any("set_controller_state joint_trajectory_controller unconfigured" in s for s in tagged)
    assert any('panel.buttons["activate"].click()' in s for s in tagged)
