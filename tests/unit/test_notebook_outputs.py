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
