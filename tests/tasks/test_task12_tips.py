"""Grader of task 12: parameter injection into the description and the controllers YAML at bringup.

The specification:

* ``rrbot_bringup/config/rrbot_controllers.yaml`` is the RRBot's controllers YAML (task 2) whose joints follow the
  launch argument ``prefix`` through ``$(var prefix)`` substitutions (read as launch's
  ``ParameterFile(path, allow_substs=True)`` reads it); without substitution it is not a usable file for a prefixed
  robot, with ``prefix=""`` it is task 2's;
* ``rrbot_bringup/bringup.py``: ``start_rrbot(prefix="", robot_controller="forward_position_controller",
  update_rate=None, use_mock_hardware=True)`` returns a running RRBot whose every name carries ``prefix``, with the
  broadcaster and ``robot_controller`` active and the other robot controller inactive; ``update_rate`` overrides the
  file's rate without changing the file; an unknown ``robot_controller`` raises ``ValueError``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, systems
from rrbot_workshop.course.grading import graded
from rrbot_workshop.middleware.param_substitution import load_with_substitutions
from rrbot_workshop.msgs import Float64MultiArray

TASK = 12
CONTROLLERS = "rrbot_bringup/config/rrbot_controllers.yaml"
BRINGUP = "rrbot_bringup/bringup.py"
FPC, JTC = "forward_position_controller", "joint_trajectory_controller"


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


@pytest.fixture(scope="module")
def bringup_module(task_file: Callable[[int, str], Path]) -> ModuleType:
    task_file(TASK, BRINGUP)
    module = rw.course.load_module(TASK, BRINGUP, quiet=True)
    if module is None:
        pytest.fail(f"{BRINGUP} does not import", pytrace=False)
    return module


@contextmanager
def _started(module: ModuleType, **kwargs: Any) -> Iterator[System]:
    fn = getattr(module, "start_rrbot", None)
    if not callable(fn):
        pytest.fail("bringup.py has no start_rrbot()", pytrace=False)
    try:
        system = fn(**kwargs)
    except NotImplementedError:
        pytest.fail("start_rrbot() is not written yet", pytrace=False)
    except Exception as exc:  # noqa: BLE001 - the learner's error is the check's failure
        for running in list(systems().values()):
            running.shutdown()
        pytest.fail(f"start_rrbot({kwargs}) raised {type(exc).__name__}: {exc}", pytrace=False)
    try:
        yield system
    finally:
        system.shutdown()


def _states(system: System) -> dict[str, str]:
    return {c.name: c.state for c in system.controller_manager.list_controllers()}


@graded(points=2, hint="Task 12.1: each controller's joints follow the launch argument prefix with $(var prefix); with "
        "prefix \"\" the file is task 2's.")
def test_yaml_follows_the_prefix(controllers_file: Path) -> None:
    for prefix in ("", "left_"):
        try:
            data = load_with_substitutions(controllers_file, {"prefix": prefix})
        except rw.ParameterError as exc:
            pytest.fail(f"the YAML cannot be read with substitutions: {exc}", pytrace=False)
        for name in (FPC, JTC):
            joints = ((data.get(name) or {}).get("ros__parameters") or {}).get("joints")
            assert joints == [f"{prefix}joint1", f"{prefix}joint2"], f"prefix {prefix!r}: {name} joints {joints}"


@graded(points=3, hint="Task 12.2: the prefix must reach both the description (xacro argument) and the controllers "
        "(substituted YAML): the broadcaster publishes left_joint1, and the forward controller moves it.")
def test_prefix_reaches_the_running_system(bringup_module: ModuleType) -> None:
    with _started(bringup_module, prefix="left_") as system:
        assert _states(system).get(FPC) == "active" and _states(system).get("joint_state_broadcaster") == "active"
        components = [c.name for c in system.controller_manager.list_hardware_components()]
        assert all(name.startswith("left_") for name in components), f"components {components}"
        system.publish(f"/{FPC}/commands", Float64MultiArray(data=[0.4, -0.2]))
        system.spin(0.1)
        msg = system.latest("/joint_states")
    assert list(msg.name) == ["left_joint1", "left_joint2"], f"/joint_states names {msg.name}"
    assert list(msg.position) == pytest.approx([0.4, -0.2]), f"/joint_states positions {msg.position}"


@graded(points=1, hint="Task 12.2: without arguments, start_rrbot() is task 2's robot: no prefix, forward position "
        "controller active, trajectory controller loaded and inactive.")
def test_defaults(bringup_module: ModuleType) -> None:
    with _started(bringup_module) as system:
        states = _states(system)
        names = system.controller_manager.list_hardware_interfaces().command_interfaces
    assert states == {"joint_state_broadcaster": "active", FPC: "active", JTC: "inactive"}, states
    assert "joint1/position" in [i.name for i in names]


@graded(points=2, hint="Task 12.2: update_rate overrides the controller manager's rate from the file, without editing "
        "the file (the next start without it is back at 100 Hz).")
def test_update_rate_is_injected(bringup_module: ModuleType, controllers_file: Path) -> None:
    before = controllers_file.read_text()
    with _started(bringup_module, update_rate=50) as system:
        rate = system.controller_manager.get_update_rate()
    assert rate == 50, f"update rate {rate} Hz with update_rate=50"
    assert controllers_file.read_text() == before, "start_rrbot() changed the YAML file"
    with _started(bringup_module) as system:
        assert system.controller_manager.get_update_rate() == 100


@graded(points=1, hint="Task 12.2: robot_controller chooses which robot controller is active; anything else is a "
        "ValueError that lists the two valid names.")
def test_robot_controller_choice(bringup_module: ModuleType) -> None:
    with _started(bringup_module, prefix="r2_", robot_controller=JTC) as system:
        states = _states(system)
    assert states.get(JTC) == "active" and states.get(FPC) == "inactive", states
    with pytest.raises(ValueError, match="forward_position_controller"):
        bringup_module.start_rrbot(robot_controller="joint_state_broadcaster")
    assert not systems(), "a refused start_rrbot() left a system running"
