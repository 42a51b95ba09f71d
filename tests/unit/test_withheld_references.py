"""A student copy says what the library contains that answers tasks, and can leave the Python references out.

``export --student DIR --withhold-references`` replaces the task-7 driver, the task-8 controller and the task-13
planner by stand-ins; the copy's README says so, its test command runs the notebooks they made outputs for without
comparing them, and every later notebook keeps running.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade
from rrbot_workshop.course.grading.references import MANIFEST, REFERENCES, STAND_INS, readme_section

REPO = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))
_ENV = {k: v for k, v in os.environ.items() if not k.startswith("RRBOT_WORKSHOP_")}

#: How a notebook could reach each withheld module: its import path, and the plugin names that load it.
_USES = {
    "rrbot_workshop.hardware.rrbot": ("rrbot_workshop.hardware.rrbot", "rrbot_workshop/RRBotHardwareInterface"),
    "rrbot_workshop.controllers.displacement": ("rrbot_workshop.controllers.displacement",
                                                "rrbot_workshop/DisplacementController"),
    "rrbot_workshop.motion": ("rrbot_workshop.motion", "rw.motion", "from rrbot_workshop import motion"),
}


@pytest.fixture(scope="module")
def withheld_copy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("withheld") / "student"
    result = subprocess.run([sys.executable, "-m", "rrbot_workshop.cli", "export", "--student", str(target),
                             "--withhold-references"], cwd=REPO, env=_ENV, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    return target


def _code(notebook: Path) -> str:
    return "\n".join("".join(c["source"]) for c in json.loads(notebook.read_text(encoding="utf-8"))["cells"]
                     if c["cell_type"] == "code")


def test_every_withheld_module_has_a_stand_in_and_a_way_notebooks_would_use_it() -> None:
    modules = {r.module for r in REFERENCES if r.module}
    assert {r.path for r in REFERENCES if r.module} == set(STAND_INS) and modules == set(_USES)


@pytest.mark.parametrize("ref", [r for r in REFERENCES if r.module], ids=lambda r: r.module)
def test_no_notebook_after_the_task_uses_a_withheld_reference_and_those_before_are_run_without_comparing(ref) -> None:
    """A later notebook that used the reference would stop in a withholding copy; an earlier one is listed, so the
    copy's test command does not compare outputs the stand-in changes."""
    last = max(ref.tasks)
    for notebook in NOTEBOOKS:
        number = int(notebook.name[:2])
        used = any(u in _code(notebook) for u in _USES[ref.module])
        if number > last:
            assert not used, f"{notebook.name} uses {ref.module}, withheld from copies as the answer to task {last}"
        elif used:
            assert f"notebooks/{notebook.name}" in ref.notebooks, f"{notebook.name} uses {ref.module}: list it"


def test_the_withholding_copy_replaces_the_references_and_says_so(withheld_copy: Path) -> None:
    manifest = json.loads((withheld_copy / MANIFEST).read_text())
    assert manifest["modules"] == [r.path for r in REFERENCES if r.module]
    for path, text in STAND_INS.items():
        assert (withheld_copy / path).read_text() == text
    for test in manifest["tests"]:
        assert not (withheld_copy / test).exists()
    readme = (withheld_copy / "README.md").read_text()
    section = readme.index("## What the library contains that answers tasks")
    assert section < readme.index("## License")
    assert readme.count("**Withheld from this copy.**") == 3 and "descriptions/multi_rrbot/" in readme
    assert "<!-- instructor -->" not in readme


def test_an_ordinary_student_copy_lists_the_references_and_how_to_withhold_them() -> None:
    text = readme_section(False)
    assert "--withhold-references" in text and "Withheld" not in text
    assert all(r.path in text for r in REFERENCES)


_STAND_IN_USE = textwrap.dedent(
    """\
    import rrbot_workshop as rw
    from rrbot_workshop.msgs import Float64MultiArray

    root = rw.description.descriptions_root()
    urdf = rw.description.process_xacro(root / "rrbot/urdf/rrbot.urdf.xacro", use_mock_hardware=False)
    urdf = urdf.replace("controlko_hardware_interface/RRBotHardwareInterface", "rrbot_workshop/RRBotHardwareInterface")
    system = rw.bringup(urdf, root / "rrbot/config/rrbot_controllers.yaml",
                        spawn=["joint_state_broadcaster", "forward_position_controller"])
    system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.4, -0.2]))
    system.spin(0.1)
    print("positions", system.latest("/joint_states").position)
    cm = system.controller_manager
    try:
        cm.load_controller("displacement_controller", "rrbot_workshop/DisplacementController")
    except rw.RRBotWorkshopError as exc:
        print("displacement:", exc)
    system.shutdown()
    try:
        rw.motion.jerk_limited_trajectory([0.0], [1.0])
    except rw.RRBotWorkshopError as exc:
        print("motion:", exc)
    """
)


def test_the_stand_ins_run_the_robot_as_mock_hardware_and_refuse_the_rest(withheld_copy: Path) -> None:
    env = {**_ENV, "PYTHONPATH": str(withheld_copy)}
    result = subprocess.run([sys.executable, "-c", _STAND_IN_USE], cwd=withheld_copy, env=env, capture_output=True,
                            text=True, check=False)
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "positions [0.4, -0.2]" in out
    assert re.search(r"displacement:.*withheld from this copy.*task 8", out)
    assert re.search(r"motion:.*withheld from this copy.*task 13", out)
    assert "RRBot driver is withheld" in result.stderr


_GRADER = '''
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.grading.references import reference_or_skip


@graded(points=2, hint=("idea", "api", "code"))
def test_same_as_the_reference():
    reference_or_skip("rrbot_workshop.motion")


@graded(points=1, hint=("idea", "api", "code"))
def test_rule():
    pass
'''


@pytest.mark.parametrize("withheld", [False, True])
def test_a_check_comparing_with_a_withheld_reference_is_given_and_scores_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, withheld: bool
) -> None:
    root = tmp_path / "course"
    (root / "tests" / "tasks").mkdir(parents=True)
    (root / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER)
    (root / "exercises" / "task05_fake").mkdir(parents=True)
    if withheld:
        (root / MANIFEST).write_text(json.dumps({"modules": ["rrbot_workshop/motion.py"]}))
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    for name in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(name, raising=False)
    tracks.set_track(None)
    rubric = grade(5, check_timeout=5.0, record=False)
    checks = {c.name: c for c in rubric.checks}
    assert checks["same_as_the_reference"].passed and checks["same_as_the_reference"].given is withheld
    assert (rubric.score, rubric.max_score) == ((1, 1) if withheld else (3, 3))
