"""The notebook panels, driven through their widgets as a click would: a full load -> configure -> activate -> switch
-> deactivate -> cleanup -> unload on the controller manager panel, the dry run's answer on a request that would fail,
hardware states, and the trajectory panel moving the arm."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest

import rrbot_workshop as rw
from rrbot_workshop.viz.panels import ControllerManagerPanel, TrajectoryPanel

JSB, FWD, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"


@pytest.fixture
def system() -> Iterator[rw.System]:
    logging.disable(logging.CRITICAL)
    with rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB, FWD], name="panel_test") as s:
        yield s
    logging.disable(logging.NOTSET)


def _click(panel: ControllerManagerPanel, verb: str, controller: str) -> None:
    panel.controller.value = controller
    panel.buttons[verb].click()


def test_a_full_lifecycle_through_the_buttons(system: rw.System) -> None:
    panel = ControllerManagerPanel(system)
    assert panel.states()[0] == {FWD: "active", JSB: "active", JTC: "not loaded"}
    _click(panel, "load", JTC)
    _click(panel, "configure", JTC)
    assert panel.states()[0][JTC] == "inactive" and "configure joint_trajectory_controller: done" in panel.message.value
    panel.switch([JTC], [FWD])
    assert panel.states()[0] == {FWD: "inactive", JSB: "active", JTC: "active"}
    _click(panel, "deactivate", JTC)
    _click(panel, "cleanup", JTC)
    _click(panel, "unload", JTC)
    assert panel.states()[0][JTC] == "not loaded"
    assert "<td>joint_trajectory_controller</td><td>controller</td><td>not loaded</td>" in panel.table.value
    assert "<svg" in panel.diagram.value


def test_a_request_that_would_fail_shows_why_and_changes_nothing(system: rw.System) -> None:
    panel = ControllerManagerPanel(system)
    _click(panel, "load", JTC)
    _click(panel, "configure", JTC)
    before = panel.states()
    _click(panel, "activate", JTC)  # the forward controller holds the position interfaces
    assert panel.states() == before
    text = panel.message.value
    assert "would fail; nothing was changed" in text and "is already claimed by" in text
    assert "forward_position_controller" in text
    _click(panel, "unload", FWD)  # active: refused by the controller manager itself
    assert panel.states() == before and "unload forward_position_controller:" in panel.message.value


def test_hardware_buttons_and_the_run_button(system: rw.System) -> None:
    panel = ControllerManagerPanel(system)
    panel.component.value = "rrbot"
    panel.hardware_buttons["inactive"].click()
    assert panel.states()[1] == {"rrbot": "inactive"}
    now = system.clock.now()
    panel.run_button.click()
    assert system.clock.now() == pytest.approx(now + 1.0)
    panel.hardware_buttons["active"].click()
    assert panel.states()[1] == {"rrbot": "active"}


def test_the_trajectory_panel_moves_the_arm_within_the_limits(system: rw.System) -> None:
    panel = ControllerManagerPanel(system)
    _click(panel, "load", JTC)
    _click(panel, "configure", JTC)
    panel.switch([JTC], [FWD])
    system.spin_cycles(1)
    trajectory = TrajectoryPanel(system, JTC)
    assert [s.description for s in trajectory.sliders] == ["joint1", "joint2"]
    assert trajectory.sliders[1].min == pytest.approx(-1.0472, abs=1e-4)  # joint2's URDF lower limit
    trajectory.sliders[0].value, trajectory.sliders[1].value = 0.6, -0.4
    trajectory.duration.value = 1.0
    trajectory.send_button.click()
    assert system.latest("/joint_states").position == pytest.approx([0.6, -0.4], abs=1e-3)
    assert trajectory.status.value.startswith("goal [0.6, -0.4], now at")


def test_a_trajectory_panel_for_a_controller_that_is_not_loaded_is_refused(system: rw.System) -> None:
    with pytest.raises(rw.exceptions.RRBotWorkshopError, match="not a loaded controller"):
        TrajectoryPanel(system, JTC)


def test_switch_to_replaces_the_controllers_commanding_the_same_joints(system: rw.System) -> None:
    panel = ControllerManagerPanel(system)
    _click(panel, "load", JTC)
    _click(panel, "configure", JTC)
    _click(panel, "switch to", JTC)
    assert panel.states()[0] == {FWD: "inactive", JSB: "active", JTC: "active"}
    assert "activate joint_trajectory_controller and deactivate forward_position_controller: done" in panel.last_message
