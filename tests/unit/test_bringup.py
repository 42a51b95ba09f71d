"""bringup(): description and controllers in, running System out; spawner semantics; System API."""

from __future__ import annotations

from pathlib import Path

import core_helpers  # noqa: F401  (registers the test plugins)
import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import bringup, current_system, get_system, systems
from rrbot_workshop.exceptions import ControllerNotFound, DescriptionError, HardwareError, ParameterError, SwitchError
from rrbot_workshop.middleware.lifecycle import State

URDF = """<robot name="tiny">
  <link name="base"/><link name="l1"/><link name="l2"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <ros2_control name="tiny_hw" type="system">
    <hardware><plugin>test_hardware/TestSystem</plugin></hardware>
    <joint name="j1"><command_interface name="position"/><state_interface name="position"/></joint>
    <joint name="j2"><command_interface name="position"/><state_interface name="position"/></joint>
  </ros2_control>
</robot>"""

CONTROLLERS = {
    "controller_manager": {"ros__parameters": {
        "update_rate": 50,
        "c1": {"type": "test_controller/TestController"},
        "c2": {"type": "test_controller/TestController"},
        "clash": {"type": "test_controller/TestController"},
    }},
    "c1": {"ros__parameters": {"command_interfaces": ["j1/position"]}},
    "c2": {"ros__parameters": {"command_interfaces": ["j2/position"]}},
    "clash": {"ros__parameters": {"command_interfaces": ["j1/position"]}},
}


@pytest.fixture
def system():  # noqa: ANN201
    with bringup(URDF, CONTROLLERS, spawn=["c1"], inactive=["c2"]) as s:
        yield s


def test_spawn_activates_and_inactive_only_configures(system: rw.System) -> None:
    states = {c.name: c.state for c in system.controller_manager.list_controllers()}
    assert states == {"c1": "active", "c2": "inactive"}


def test_rate_comes_from_the_yaml_and_spin_advances_whole_cycles(system: rw.System) -> None:
    assert system.period == pytest.approx(0.02)
    assert system.spin(0.1) == pytest.approx(0.1)
    assert system.clock.cycles == 5
    system.spin_cycles(3)
    assert system.time == pytest.approx(0.16)


def test_commands_reach_the_hardware(system: rw.System) -> None:
    system.spin_cycles(1)
    assert system.resource_manager.get_interface_value("j1/position") == 1.0


def test_system_exposes_its_parts(system: rw.System) -> None:
    assert system.urdf.startswith("<robot") and system.hardware_infos[0].name == "tiny_hw"
    assert system.bus is system.controller_manager.bus
    assert "/controller_manager/list_controllers" in system.bus.service_names()
    assert [c.name for c in system.call_service("/controller_manager/list_controllers").controller] == ["c1", "c2"]


def test_publish_latest_and_history(system: rw.System) -> None:
    system.publish("/chatter", rw.msgs.String(data="a"))
    system.publish("/chatter", rw.msgs.String(data="b"))
    assert system.latest("/chatter").data == "b"
    assert [m.data for m in system.history("/chatter")] == ["a", "b"]
    assert system.latest("/nothing") is None


def test_current_system_is_the_last_brought_up(system: rw.System) -> None:
    assert current_system() is system and get_system(system.name) is system
    with bringup(URDF, CONTROLLERS) as second:
        assert current_system() is second and second.name != system.name
    assert current_system() is system


def test_shutdown_is_idempotent_and_stops_the_system() -> None:
    s = bringup(URDF, CONTROLLERS, spawn=["c1"])
    s.shutdown()
    s.shutdown()
    assert not s.running and s.name not in systems()
    assert s.resource_manager.get_components_status()["tiny_hw"].state is State.FINALIZED
    with pytest.raises(HardwareError, match="shut down"):
        s.spin(0.1)
    with pytest.raises(KeyError, match="no running system"):
        get_system(s.name)


def test_undeclared_spawn_names_the_controller_and_lists_declared() -> None:
    with pytest.raises(ControllerNotFound, match="'nope'.*'c1', 'c2', 'clash'"):
        bringup(URDF, CONTROLLERS, spawn=["nope"])


def test_spawn_group_that_conflicts_fails_and_leaves_no_system() -> None:
    before = set(systems())
    with pytest.raises(SwitchError, match="both claim"):
        bringup(URDF, CONTROLLERS, spawn=["c1", "clash"])
    assert set(systems()) == before


def test_same_controller_in_spawn_and_inactive_is_an_error() -> None:
    with pytest.raises(ParameterError, match="both lists"):
        bringup(URDF, CONTROLLERS, spawn=["c1"], inactive=["c1"])


def test_hardware_initial_state_argument() -> None:
    with bringup(URDF, CONTROLLERS, hardware_initial_state={"tiny_hw": "inactive"}) as s:
        assert s.controller_manager.list_hardware_components()[0].state is State.INACTIVE


def test_hardware_components_initial_state_from_yaml() -> None:
    cfg = {**CONTROLLERS, "controller_manager": {"ros__parameters": {
        **CONTROLLERS["controller_manager"]["ros__parameters"],
        "hardware_components_initial_state": {"unconfigured": ["tiny_hw"]}}}}
    with bringup(URDF, cfg) as s:
        assert s.resource_manager.get_components_status()["tiny_hw"].state is State.UNCONFIGURED


def test_initial_state_for_unknown_component_raises() -> None:
    with pytest.raises(HardwareError, match="ghost"):
        bringup(URDF, CONTROLLERS, hardware_initial_state={"ghost": "inactive"})


def test_bad_initial_state_label_raises() -> None:
    with pytest.raises(HardwareError, match="sleeping"):
        bringup(URDF, CONTROLLERS, hardware_initial_state={"tiny_hw": "sleeping"})


def test_description_and_controllers_from_files(tmp_path: Path) -> None:
    import yaml

    (tmp_path / "tiny.urdf").write_text(URDF)
    (tmp_path / "ctrl.yaml").write_text(yaml.safe_dump(CONTROLLERS))
    with bringup(tmp_path / "tiny.urdf", tmp_path / "ctrl.yaml", spawn=["c2"]) as s:
        assert s.controller_manager.controllers["c2"].state is State.ACTIVE


def test_missing_description_file_raises() -> None:
    with pytest.raises(DescriptionError, match="does not exist"):
        bringup("/no/such/robot.urdf.xacro", CONTROLLERS)


def test_unknown_description_package_lists_packages() -> None:
    with pytest.raises(DescriptionError, match="packages"):
        bringup("no_such_robot", CONTROLLERS)


def test_missing_controllers_file_raises() -> None:
    with pytest.raises(ParameterError, match="does not exist"):
        bringup(URDF, "/no/such/controllers.yaml")


def test_package_name_and_config_file_name_resolve_under_descriptions() -> None:
    with bringup("rrbot", "rrbot_controllers.yaml", spawn=["joint_state_broadcaster"]) as s:
        assert s.name.startswith("rrbot")
        assert s.controller_manager.controllers["joint_state_broadcaster"].state is State.ACTIVE


def test_unknown_config_file_in_package_lists_files() -> None:
    with pytest.raises(ParameterError, match="rrbot_controllers.yaml"):
        bringup("rrbot", "nope.yaml")


def test_package_level_bringup_is_callable_after_submodule_import() -> None:
    import rrbot_workshop.bringup  # noqa: F401  (binds rw.bringup to the module)

    with rw.bringup(URDF, CONTROLLERS) as s:
        assert isinstance(s, rw.System)
