"""The background loop and the live plot: the loop spins on the running event loop between awaits, stops on request,
with ``shutdown`` and after an error without taking the process down; panels follow it; the live plot samples
interfaces and topic fields within its window. No timing is asserted: only that time moved, or did not."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Iterator

import pytest

import rrbot_workshop as rw
from rrbot_workshop.exceptions import HardwareError, RRBotWorkshopError
from rrbot_workshop.msgs import JointState
from rrbot_workshop.viz.live_plot import PlotPanel, field_value
from rrbot_workshop.viz.panels import ControllerManagerPanel, TrajectoryPanel

JSB, FWD = "joint_state_broadcaster", "forward_position_controller"


@pytest.fixture
def system() -> Iterator[rw.System]:
    logging.disable(logging.CRITICAL)
    with rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB, FWD], name="background_test") as s:
        yield s
    logging.disable(logging.NOTSET)


def test_the_loop_spins_between_awaits_and_stops_on_request(system: rw.System) -> None:
    async def scenario() -> tuple[float, float, float, int]:
        spinner = system.spin_in_background(real_time_factor=5.0, tick=0.01)
        assert system.background is spinner and spinner.running
        before = system.time
        await asyncio.sleep(0.3)
        during = system.time
        spinner.stop()
        await asyncio.sleep(0.1)
        return before, during, system.time, spinner.cycles

    before, during, after, cycles = asyncio.run(scenario())
    assert before == 0.0 and during > 0.0, "the background loop did not advance time while the cell awaited"
    assert after == pytest.approx(cycles * system.period), "time is not whole cycles of the loop"
    assert system.background is None
    system.spin(0.5)  # spinning by hand still works, by exactly the time asked
    assert system.time == pytest.approx(after + 0.5)


def test_shutdown_stops_the_loop(system: rw.System) -> None:
    async def scenario() -> bool:
        spinner = system.spin_in_background(tick=0.01)
        await asyncio.sleep(0.05)
        system.shutdown()
        await asyncio.sleep(0.05)
        return spinner.running

    assert asyncio.run(scenario()) is False


def test_an_error_in_the_loop_stops_it_and_is_kept(system: rw.System) -> None:
    def broken_listener(_system: rw.System) -> None:
        raise RuntimeError("a panel's redraw failed")

    system.add_spin_listener(broken_listener)  # logged, the robot goes on
    system.spin(0.1)

    async def scenario() -> rw.System:
        spinner = system.spin_in_background(tick=0.01)
        await asyncio.sleep(0.05)
        system.spin_cycles = None  # type: ignore[method-assign,assignment]  # the next batch raises TypeError
        await asyncio.sleep(0.1)
        return spinner

    spinner = asyncio.run(scenario())
    assert not spinner.running and isinstance(spinner.error, TypeError)


def test_refusals_say_why(system: rw.System) -> None:
    with pytest.raises(HardwareError, match="needs a running event loop"):
        system.spin_in_background()

    async def bad_factor() -> None:
        system.spin_in_background(real_time_factor=0)

    with pytest.raises(HardwareError, match="must be positive"):
        asyncio.run(bad_factor())
    with rw.bringup("rrbot", "rrbot_controllers.yaml", clock="wall", name="wall_clock_test") as wall:
        async def wall_clock() -> None:
            wall.spin_in_background()

        with pytest.raises(HardwareError, match="wall clock"):
            asyncio.run(wall_clock())


def test_the_controller_manager_panel_follows_changes_made_elsewhere(system: rw.System) -> None:
    panel = ControllerManagerPanel(system)
    system.controller_manager.switch_controllers([], [FWD])  # a cell, not the panel

    async def scenario() -> None:
        system.spin_in_background(tick=0.01)
        await asyncio.sleep(0.1)
        system.stop_background()

    asyncio.run(scenario())
    assert "<td>forward_position_controller</td><td>controller</td><td>inactive</td>" in panel.table.value
    panel.run()
    assert "spins in the background" not in panel.last_message
    panel.stop()


def test_the_trajectory_panel_leaves_the_motion_to_the_background_loop(system: rw.System) -> None:
    system.controller_manager.load_controller("joint_trajectory_controller")
    system.controller_manager.configure_controller("joint_trajectory_controller")
    system.controller_manager.switch_controllers(["joint_trajectory_controller"], [FWD], strictness="strict")
    panel = TrajectoryPanel(system)
    panel.sliders[0].value, panel.duration.value = 0.5, 1.0

    async def scenario() -> tuple[float, float]:
        system.spin_in_background(real_time_factor=20.0, tick=0.01)
        before = system.time
        panel.send_button.click()
        clicked = system.time  # the click itself did not spin
        for _ in range(1000):  # until the goal's second has passed in simulated time (no wall time is asserted)
            if system.time > before + 1.2:
                break
            await asyncio.sleep(0.01)
        system.stop_background()
        return before, clicked

    before, clicked = asyncio.run(scenario())
    assert clicked == before
    assert "sent from" in panel.status.value and "background" in panel.status.value
    assert system.latest("/joint_states").position[0] == pytest.approx(0.5, abs=1e-6), "the goal was not reached"


def test_the_plot_panel_keeps_its_window_of_interfaces_and_topic_fields(system: rw.System) -> None:
    plot = PlotPanel(system, ["joint1/position", "command:joint1/position", "/joint_states:position[joint2]"],
                     window=0.5)
    system.publish("/forward_position_controller/commands", rw.msgs.Float64MultiArray(data=[0.4, -0.2]))
    system.spin(1.0)
    series = plot.series()
    times, positions = series["joint1/position"]
    assert times[0] == pytest.approx(0.5, abs=2 * system.period) and times[-1] == pytest.approx(1.0)
    assert positions[-1] == pytest.approx(0.4)
    topic_times, joint2 = series["/joint_states:position[joint2]"]
    assert topic_times and topic_times[0] >= 0.5 - 1e-9 and joint2[-1] == pytest.approx(-0.2)
    assert plot.image.value[:8] == b"\x89PNG\r\n\x1a\n"
    plot.stop()
    system.spin(0.2)
    assert plot.series()["joint1/position"][0][-1] == pytest.approx(1.0), "a stopped panel still samples"


def test_field_paths_name_what_is_missing() -> None:
    msg = JointState(name=["joint1", "joint2"], position=[0.1, 0.2], velocity=[0.0, 0.0], effort=[])
    assert field_value(msg, "position[joint2]") == 0.2
    assert field_value(msg, "velocity[0]") == 0.0
    with pytest.raises(RRBotWorkshopError, match="no 'joint3'"):
        field_value(msg, "position[joint3]")
    with pytest.raises(RRBotWorkshopError, match="no 'positions' in JointState"):
        field_value(msg, "positions[0]")
    with pytest.raises(RRBotWorkshopError, match="not a number"):
        field_value(msg, "name")
    with pytest.raises(RRBotWorkshopError, match="at least one signal"):
        PlotPanel(None, [])
