"""Resource manager: loading, availability per lifecycle state, claims, mode switches, read/write errors.

Ported from the key cases of ros2_control's hardware_interface_testing/test/test_resource_manager.cpp.
"""

from __future__ import annotations

import pytest
from core_helpers import TestSensor, TestSystem, make_info

from rrbot_workshop.exceptions import ControllerError, HardwareError, InterfaceAlreadyClaimed, InterfaceNotFound
from rrbot_workshop.hardware_interface.handles import CommandInterface
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.lifecycle import ReturnType, State

JOINTS = {"joint1": (["position"], ["position", "velocity"]), "joint2": (["position"], ["position"])}


def _rm(activate_all: bool = True, **kwargs: object) -> tuple[ResourceManager, TestSystem]:
    rm = ResourceManager(update_rate=100, activate_all=activate_all, **kwargs)  # type: ignore[arg-type]
    impl = TestSystem()
    rm.import_component(impl, make_info("sys", JOINTS))
    return rm, impl


def test_keys_are_sorted_full_names() -> None:
    rm, _ = _rm()
    assert rm.state_interface_keys() == ["joint1/position", "joint1/velocity", "joint2/position"]
    assert rm.command_interface_keys() == ["joint1/position", "joint2/position"]


def test_unconfigured_component_has_no_available_interfaces() -> None:
    rm, _ = _rm(activate_all=False)
    assert rm.get_components_status()["sys"].state is State.UNCONFIGURED
    assert rm.available_state_interfaces() == [] and rm.available_command_interfaces() == []


def test_configure_makes_state_and_command_interfaces_available() -> None:
    rm, _ = _rm(activate_all=False)
    assert rm.set_component_state("sys", State.INACTIVE)
    assert rm.available_command_interfaces() == ["joint1/position", "joint2/position"]
    assert rm.state_interface_is_available("joint1/velocity")


def test_deactivate_keeps_and_cleanup_removes_availability() -> None:
    rm, _ = _rm()
    assert rm.set_component_state("sys", State.INACTIVE)
    assert rm.command_interface_is_available("joint1/position")
    assert rm.set_component_state("sys", State.UNCONFIGURED)
    assert not rm.command_interface_is_available("joint1/position")
    assert not rm.state_interface_is_available("joint1/position")


def test_set_component_state_chains_unconfigured_to_active() -> None:
    rm, _ = _rm(activate_all=False)
    assert rm.set_component_state("sys", State.ACTIVE)
    assert rm.get_component("sys").get_lifecycle_state() is State.ACTIVE


def test_finalized_is_terminal() -> None:
    rm, _ = _rm()
    assert rm.set_component_state("sys", State.FINALIZED)
    assert not rm.set_component_state("sys", State.ACTIVE)
    assert rm.available_state_interfaces() == []


def test_set_state_of_unknown_component_raises_with_valid_names() -> None:
    rm, _ = _rm()
    with pytest.raises(HardwareError, match="'nope'.*sys"):
        rm.set_component_state("nope", State.ACTIVE)


def test_double_claim_raises_naming_the_holder() -> None:
    rm, _ = _rm()
    rm.claim_command_interface("joint1/position", holder="ctrl_a")
    with pytest.raises(InterfaceAlreadyClaimed) as err:
        rm.claim_command_interface("joint1/position", holder="ctrl_b")
    assert err.value.holder == "ctrl_a" and "ctrl_a" in str(err.value) and "ctrl_b" in str(err.value)


def test_release_frees_the_claim() -> None:
    rm, _ = _rm()
    loan = rm.claim_command_interface("joint1/position", holder="a")
    assert rm.command_interface_is_claimed("joint1/position")
    assert rm.command_interface_holder("joint1/position") == "a"
    loan.release()
    assert not rm.command_interface_is_claimed("joint1/position")
    rm.claim_command_interface("joint1/position", holder="b")


def test_state_interfaces_can_be_claimed_many_times() -> None:
    rm, _ = _rm()
    a = rm.claim_state_interface("joint1/position")
    b = rm.claim_state_interface("joint1/position")
    assert a.get_value() == b.get_value() == 0.0


def test_claiming_missing_or_unavailable_interface_raises() -> None:
    rm, _ = _rm(activate_all=False)
    with pytest.raises(InterfaceNotFound, match="not available"):
        rm.claim_command_interface("joint1/position")
    with pytest.raises(InterfaceNotFound, match="not available"):
        rm.claim_state_interface("joint1/position")
    with pytest.raises(InterfaceNotFound, match="does not exist"):
        rm.claim_command_interface("joint9/position")
    with pytest.raises(InterfaceNotFound, match="does not exist"):
        rm.claim_state_interface("joint9/position")


def test_get_interface_value_unknown_raises() -> None:
    rm, _ = _rm()
    assert rm.get_interface_value("joint1/velocity") == 0.0
    with pytest.raises(InterfaceNotFound):
        rm.get_interface_value("nothing/here")


def test_duplicate_component_names_fail_the_load() -> None:
    rm = ResourceManager()
    infos = [make_info("same", {"a": (["position"], ["position"])}), make_info("same", {"b": (["position"], ["position"])})]
    with pytest.raises(HardwareError, match="'same'.*more than once"):
        rm.load_hardware_infos(infos)
    assert rm.component_names() == []


def test_unknown_plugin_fails_the_load_naming_the_component() -> None:
    rm = ResourceManager()
    with pytest.raises(HardwareError, match="'hw'.*no_such/Plugin"):
        rm.load_hardware_infos([make_info("hw", JOINTS, plugin="no_such/Plugin")])


def test_missing_plugin_name_fails_the_load() -> None:
    with pytest.raises(HardwareError, match="no <hardware><plugin>"):
        ResourceManager().load_hardware_infos([make_info("hw", JOINTS, plugin="")])


def test_duplicate_interfaces_across_components_fail_the_load() -> None:
    rm = ResourceManager()
    rm.import_component(TestSystem(), make_info("a", JOINTS))
    with pytest.raises(HardwareError, match="already exported"):
        rm.import_component(TestSystem(), make_info("b", {"joint1": (["position"], ["position"])}))


def test_component_that_does_not_export_declared_interfaces_fails() -> None:
    class Lazy(TestSystem):
        def export_command_interfaces(self) -> list[CommandInterface]:
            return []

    with pytest.raises(HardwareError, match="does not export"):
        ResourceManager().import_component(Lazy(), make_info("lazy", JOINTS))


def test_initial_states_per_component() -> None:
    rm = ResourceManager(initial_states={"a": State.INACTIVE, "b": State.UNCONFIGURED})
    rm.load_hardware_infos([
        make_info("a", {"ja": (["position"], ["position"])}),
        make_info("b", {"jb": (["position"], ["position"])}),
        make_info("c", {"jc": (["position"], ["position"])}),
    ])
    status = rm.get_components_status()
    assert [status[n].state for n in "abc"] == [State.INACTIVE, State.UNCONFIGURED, State.ACTIVE]


def test_initial_state_of_unknown_component_raises() -> None:
    rm = ResourceManager(initial_states={"ghost": State.INACTIVE})
    with pytest.raises(HardwareError, match="ghost"):
        rm.load_hardware_infos([make_info("a", JOINTS)])


def test_read_error_takes_only_that_component_out() -> None:
    rm = ResourceManager()
    bad, good = TestSystem(), TestSystem()
    rm.import_component(bad, make_info("bad", {"j1": (["position"], ["position"])}))
    rm.import_component(good, make_info("good", {"j2": (["position"], ["position"])}))
    bad.read_result = ReturnType.ERROR
    status = rm.read(0.01, 0.01)
    assert not status.ok and status.failed_hardware_names == ["bad"]
    assert rm.get_components_status()["bad"].state is State.UNCONFIGURED  # on_error SUCCESS
    assert not rm.state_interface_is_available("j1/position")
    assert rm.read(0.02, 0.01).ok and good.reads == 2 and bad.reads == 1


def test_read_exception_is_caught_and_reported() -> None:
    rm, impl = _rm()
    impl.raise_in_read = True
    status = rm.read(0.01, 0.01)
    assert status.failed_hardware_names == ["sys"]
    assert rm.available_command_interfaces() == []


def test_failed_on_error_finalizes_the_component() -> None:
    rm, impl = _rm()
    impl.read_result = ReturnType.ERROR
    impl.on_error_result = impl.on_error_result.FAILURE
    rm.read(0.01, 0.01)
    assert rm.get_components_status()["sys"].state is State.FINALIZED


def test_write_deactivate_makes_component_inactive_and_keeps_interfaces() -> None:
    rm, impl = _rm()
    impl.write_result = ReturnType.DEACTIVATE
    status = rm.write(0.01, 0.01)
    assert status.failed_hardware_names == ["sys"]
    assert rm.get_components_status()["sys"].state is State.INACTIVE
    assert rm.command_interface_is_available("joint1/position")


def test_read_deactivate_counts_as_error() -> None:
    rm, impl = _rm()
    impl.read_result = ReturnType.DEACTIVATE
    rm.read(0.01, 0.01)
    assert rm.get_components_status()["sys"].state is State.UNCONFIGURED


def test_group_members_fail_together() -> None:
    rm = ResourceManager()
    a, b, c = TestSystem(), TestSystem(), TestSystem()
    rm.import_component(a, make_info("a", {"ja": (["position"], ["position"])}, group="arm"))
    rm.import_component(b, make_info("b", {"jb": (["position"], ["position"])}, group="arm"))
    rm.import_component(c, make_info("c", {"jc": (["position"], ["position"])}))
    b.read_result = ReturnType.ERROR
    status = rm.read(0.01, 0.01)
    assert sorted(status.failed_hardware_names) == ["a", "b"]
    assert rm.get_components_status()["c"].state is State.ACTIVE


def test_read_order_is_actuators_sensors_systems() -> None:
    calls: list[str] = []

    class Recording(TestSystem):
        def read(self, time: float, period: float) -> ReturnType:
            calls.append(self.get_name())
            return ReturnType.OK

    class RecordingSensor(TestSensor):
        def read(self, time: float, period: float) -> ReturnType:
            calls.append(self.get_name())
            return ReturnType.OK

    rm = ResourceManager()
    rm.import_component(Recording(), make_info("sys", {"j1": (["position"], ["position"])}))
    rm.import_component(RecordingSensor(), make_info("fts", sensors={"s": ["fx"]}, type="sensor"))
    rm.import_component(Recording(), make_info("act", {"j2": (["position"], ["position"])}, type="actuator"))
    rm.read(0.01, 0.01)
    assert calls == ["act", "fts", "sys"]


def test_rw_rate_below_manager_rate_skips_cycles_and_passes_own_period() -> None:
    rm = ResourceManager(update_rate=100)
    impl = TestSystem()
    rm.import_component(impl, make_info("slow", JOINTS, rw_rate=50))
    for k in range(1, 11):
        rm.read(k / 100, 0.01)
    assert impl.reads == 5
    assert impl.read_periods[1:] == pytest.approx([0.02] * 4)
    assert rm.get_components_status()["slow"].rw_rate == 50


def test_prepare_with_empty_lists_is_true() -> None:
    rm, _ = _rm()
    assert rm.prepare_command_mode_switch([], [])


def test_prepare_rejects_missing_keys_and_inactive_hardware() -> None:
    rm, _ = _rm()
    assert not rm.prepare_command_mode_switch(["joint9/position"], [])
    rm.set_component_state("sys", State.INACTIVE)
    assert not rm.prepare_command_mode_switch(["joint1/position"], [])
    assert "inactive" in rm.last_switch_error
    assert rm.prepare_command_mode_switch([], ["joint1/position"])  # stopping is fine while inactive


def test_prepare_routes_only_own_keys_and_honours_hook_result() -> None:
    rm = ResourceManager()
    a, b = TestSystem(), TestSystem()
    rm.import_component(a, make_info("a", {"ja": (["position"], ["position"])}))
    rm.import_component(b, make_info("b", {"jb": (["position"], ["position"])}))
    assert rm.prepare_command_mode_switch(["ja/position"], [])
    assert a.prepared == [(["ja/position"], [])] and b.prepared == []
    a.prepare_result = ReturnType.ERROR
    assert not rm.prepare_command_mode_switch(["ja/position"], [])
    assert rm.perform_command_mode_switch(["jb/position"], [])
    assert b.performed == [(["jb/position"], [])]


def test_controller_exports_are_unavailable_until_made_available() -> None:
    rm, _ = _rm()
    rm.import_controller_reference_interfaces("pid", [CommandInterface("pid/joint1", "position", initial_value=0.0)])
    assert rm.command_interface_exists("pid/joint1/position")
    assert not rm.command_interface_is_available("pid/joint1/position")
    rm.make_controller_reference_interfaces_available("pid", True)
    assert rm.claim_command_interface("pid/joint1/position", "pre").get_value() == 0.0
    assert rm.controller_of_interface("pid/joint1/position") == "pid"
    assert rm.hardware_of_interface("pid/joint1/position") is None
    rm.remove_controller_reference_interfaces("pid")
    assert not rm.command_interface_exists("pid/joint1/position")


def test_controller_export_clash_raises() -> None:
    rm, _ = _rm()
    with pytest.raises(ControllerError, match="already exist"):
        rm.import_controller_reference_interfaces("joint1", [CommandInterface("joint1", "position")])


URDF = """<robot name="tiny">
  <link name="base"/><link name="l1"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <ros2_control name="tiny_hw" type="system">
    <hardware><plugin>test_hardware/TestSystem</plugin></hardware>
    <joint name="j1"><command_interface name="position"/><state_interface name="position"/></joint>
  </ros2_control>
</robot>"""


def test_load_urdf_loads_and_activates_components() -> None:
    rm = ResourceManager(URDF)
    info = rm.get_components_status()["tiny_hw"]
    assert info.state is State.ACTIVE and info.plugin_name == "test_hardware/TestSystem"
    assert rm.available_command_interfaces() == ["j1/position"]


def test_asking_for_the_unknown_state_raises() -> None:
    rm, _ = _rm()
    with pytest.raises(HardwareError, match="'unknown' is not a state"):
        rm.set_component_state("sys", State.UNKNOWN)


def test_an_on_init_that_raises_is_the_load_errors_cause() -> None:
    class Raising(TestSystem):
        def on_init(self, info):  # type: ignore[no-untyped-def]
            raise TypeError("a learner's mistake")

    rm = ResourceManager(update_rate=100)
    with pytest.raises(HardwareError) as err:
        rm.import_component(Raising(), make_info("sys", JOINTS))
    assert isinstance(err.value.__cause__, TypeError) and str(err.value.__cause__) == "a learner's mistake"
