"""HardwareComponent: the hardware lifecycle table, read/write rules and exception handling.

Held against ros2_control's hardware_component.cpp and test_component_interfaces.cpp.
"""

from __future__ import annotations

import logging
from typing import Any

import pytest

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo
from rrbot_workshop.exceptions import HardwareError
from rrbot_workshop.hardware_interface.component_interface import SensorInterface, SystemInterface
from rrbot_workshop.hardware_interface.handles import CommandInterface, StateInterface
from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent, HardwareComponentInfo
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

S, F, E = CallbackReturn.SUCCESS, CallbackReturn.FAILURE, CallbackReturn.ERROR
UNKNOWN, UNCONFIGURED, INACTIVE, ACTIVE, FINALIZED = (
    State.UNKNOWN, State.UNCONFIGURED, State.INACTIVE, State.ACTIVE, State.FINALIZED,
)


class Scripted(SystemInterface):
    """A system whose callbacks return (or raise) what the test says, and record their calls."""

    def __init__(self) -> None:
        super().__init__()
        self.results: dict[str, Any] = {}
        self.calls: list[tuple[str, Any]] = []

    def _do(self, name: str, arg: Any, default: Any) -> Any:
        self.calls.append((name, arg))
        result = self.results.get(name, default)
        if isinstance(result, BaseException):
            raise result
        return result

    def called(self, name: str) -> bool:
        return any(call[0] == name for call in self.calls)

    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        super().on_init(info)
        return self._do("on_init", info.name, S)

    def on_configure(self, previous_state: State) -> CallbackReturn:
        return self._do("on_configure", previous_state, S)

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        return self._do("on_cleanup", previous_state, S)

    def on_activate(self, previous_state: State) -> CallbackReturn:
        return self._do("on_activate", previous_state, S)

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        return self._do("on_deactivate", previous_state, S)

    def on_shutdown(self, previous_state: State) -> CallbackReturn:
        return self._do("on_shutdown", previous_state, S)

    def on_error(self, previous_state: State) -> CallbackReturn:
        return self._do("on_error", previous_state, F)  # rclcpp_lifecycle's default

    def read(self, time: float, period: float) -> ReturnType:
        return self._do("read", (time, period), ReturnType.OK)

    def write(self, time: float, period: float) -> ReturnType:
        return self._do("write", (time, period), ReturnType.OK)

    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        return self._do("prepare", (start_interfaces, stop_interfaces), ReturnType.OK)

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        return self._do("perform", (start_interfaces, stop_interfaces), ReturnType.OK)


def info(type_: str = "system") -> HardwareInfo:
    return HardwareInfo(
        name="hw",
        type=type_,
        group="arm",
        hardware_plugin_name="test/Scripted",
        rw_rate=50,
        joints=[ComponentInfo(
            name="joint1",
            type="joint",
            command_interfaces=[InterfaceInfo("position")],
            state_interfaces=[InterfaceInfo("position", initial_value="0.5")],
        )],
    )


def component_in(state: State, impl: Scripted | None = None) -> HardwareComponent:
    """A component brought to ``state`` with successful transitions; its call log is then cleared."""
    comp = HardwareComponent(impl or Scripted())
    if state is not UNKNOWN:
        comp.initialize(info())
    if state in (INACTIVE, ACTIVE):
        comp.configure()
    if state is ACTIVE:
        comp.activate()
    if state is FINALIZED:
        comp.shutdown()
    assert comp.get_lifecycle_state() is state
    scripted(comp).calls.clear()
    return comp


def scripted(comp: HardwareComponent) -> Scripted:
    assert isinstance(comp.impl, Scripted)
    return comp.impl


# ----------------------------------------------------------------- initialize
@pytest.mark.parametrize(
    ("result", "expected"),
    [(S, UNCONFIGURED), (F, FINALIZED), (E, FINALIZED), (RuntimeError("boom"), FINALIZED), (None, FINALIZED)],
    ids=["success", "failure", "error", "raises", "returns-none"],
)
def test_initialize_row(result: Any, expected: State) -> None:
    impl = Scripted()
    impl.results["on_init"] = result
    comp = HardwareComponent(impl)
    assert comp.initialize(info()) is expected
    assert impl.get_lifecycle_state() is expected  # the implementation's own state is kept in sync


def test_initialize_twice_does_not_call_on_init_again() -> None:
    comp = component_in(UNCONFIGURED)
    assert comp.initialize(info()) is UNCONFIGURED
    assert not scripted(comp).called("on_init")


# ----------------------------------------------------------------- transition rows
ROWS = [
    # call, start, callback, result, on_error result (None: must not run), expected end
    ("configure", UNCONFIGURED, "on_configure", S, None, INACTIVE),
    ("configure", UNCONFIGURED, "on_configure", F, None, UNCONFIGURED),
    ("configure", UNCONFIGURED, "on_configure", E, None, UNCONFIGURED),  # error() is a no-op when unconfigured
    ("cleanup", INACTIVE, "on_cleanup", S, None, UNCONFIGURED),
    ("cleanup", INACTIVE, "on_cleanup", F, F, FINALIZED),
    ("cleanup", INACTIVE, "on_cleanup", F, S, UNCONFIGURED),
    ("cleanup", INACTIVE, "on_cleanup", E, F, FINALIZED),
    ("activate", INACTIVE, "on_activate", S, None, ACTIVE),
    ("activate", INACTIVE, "on_activate", F, None, INACTIVE),
    ("activate", INACTIVE, "on_activate", E, F, FINALIZED),
    ("activate", INACTIVE, "on_activate", E, S, UNCONFIGURED),
    ("deactivate", ACTIVE, "on_deactivate", S, None, INACTIVE),
    ("deactivate", ACTIVE, "on_deactivate", F, None, ACTIVE),
    ("deactivate", ACTIVE, "on_deactivate", E, E, FINALIZED),
    ("shutdown", UNCONFIGURED, "on_shutdown", S, None, FINALIZED),
    ("shutdown", UNCONFIGURED, "on_shutdown", F, None, UNCONFIGURED),  # error() is a no-op when unconfigured
    ("shutdown", INACTIVE, "on_shutdown", S, None, FINALIZED),
    ("shutdown", INACTIVE, "on_shutdown", F, F, FINALIZED),
    ("shutdown", ACTIVE, "on_shutdown", S, None, FINALIZED),
    ("shutdown", ACTIVE, "on_shutdown", E, S, UNCONFIGURED),
    ("error", INACTIVE, "on_error", S, None, UNCONFIGURED),
    ("error", INACTIVE, "on_error", F, None, FINALIZED),
    ("error", ACTIVE, "on_error", E, None, FINALIZED),
    ("error", FINALIZED, "on_error", S, None, UNCONFIGURED),
]


@pytest.mark.parametrize(("call", "start", "callback", "result", "on_error", "expected"), ROWS)
def test_transition_row(
    call: str, start: State, callback: str, result: CallbackReturn, on_error: CallbackReturn | None, expected: State
) -> None:
    comp = component_in(start)
    impl = scripted(comp)
    impl.results[callback] = result
    if on_error is not None:
        impl.results["on_error"] = on_error
    assert getattr(comp, call)() is expected
    assert comp.get_lifecycle_state() is expected and impl.get_lifecycle_state() is expected
    assert impl.calls[0] == (callback, start)  # the callback sees the state it starts from
    error_ran = impl.called("on_error")
    assert error_ran == (on_error is not None or callback == "on_error")


@pytest.mark.parametrize(
    ("call", "start", "callback", "expected"),
    [
        ("configure", UNCONFIGURED, "on_configure", UNCONFIGURED),
        ("cleanup", INACTIVE, "on_cleanup", FINALIZED),
        ("activate", INACTIVE, "on_activate", FINALIZED),
        ("deactivate", ACTIVE, "on_deactivate", FINALIZED),
        ("shutdown", INACTIVE, "on_shutdown", FINALIZED),
        ("error", ACTIVE, "on_error", FINALIZED),
    ],
)
def test_callback_that_raises_counts_as_error(call: str, start: State, callback: str, expected: State) -> None:
    comp = component_in(start)
    boom = ValueError("learner bug")
    scripted(comp).results[callback] = boom
    assert getattr(comp, call)() is expected
    assert comp.last_error is boom


def test_callback_returning_none_counts_as_error() -> None:
    comp = component_in(INACTIVE)
    scripted(comp).results["on_activate"] = None  # a forgotten `return CallbackReturn.SUCCESS`
    assert comp.activate() is FINALIZED


def test_error_from_activate_passes_inactive_to_on_error() -> None:
    comp = component_in(INACTIVE)
    scripted(comp).results["on_activate"] = E
    comp.activate()
    assert ("on_error", INACTIVE) in scripted(comp).calls


ALLOWED = {
    "configure": {UNCONFIGURED},
    "cleanup": {INACTIVE},
    "activate": {INACTIVE},
    "deactivate": {ACTIVE},
    "shutdown": {UNCONFIGURED, INACTIVE, ACTIVE},
    "error": {INACTIVE, ACTIVE, FINALIZED},
}
CALLBACK = {"configure": "on_configure", "cleanup": "on_cleanup", "activate": "on_activate",
            "deactivate": "on_deactivate", "shutdown": "on_shutdown", "error": "on_error"}
NO_OPS = [(call, state) for call, allowed in ALLOWED.items() for state in State if state not in allowed]


@pytest.mark.parametrize(("call", "start"), NO_OPS)
def test_call_from_a_disallowed_state_is_a_no_op(call: str, start: State) -> None:
    comp = component_in(start)
    assert getattr(comp, call)() is start
    assert not scripted(comp).called(CALLBACK[call])


# ----------------------------------------------------------------- read / write
@pytest.mark.parametrize("state", list(State))
def test_read_runs_only_when_inactive_or_active(state: State) -> None:
    comp = component_in(state)
    assert comp.read(1.0, 0.01) is ReturnType.OK
    assert scripted(comp).called("read") == (state in (INACTIVE, ACTIVE))


@pytest.mark.parametrize("state", list(State))
def test_write_runs_only_when_active(state: State) -> None:
    comp = component_in(state)
    assert comp.write(1.0, 0.01) is ReturnType.OK
    assert scripted(comp).called("write") == (state is ACTIVE)


def test_read_passes_time_and_period() -> None:
    comp = component_in(ACTIVE)
    comp.read(2.5, 0.01)
    assert ("read", (2.5, 0.01)) in scripted(comp).calls


class ScriptedSensor(SensorInterface):
    def __init__(self) -> None:
        super().__init__()
        self.writes = 0

    def read(self, time: float, period: float) -> ReturnType:
        return ReturnType.OK

    def write(self, time: float, period: float) -> ReturnType:
        self.writes += 1
        return ReturnType.ERROR


def test_sensor_never_writes() -> None:
    impl = ScriptedSensor()
    comp = HardwareComponent(impl)
    comp.initialize(HardwareInfo(name="fts", type="sensor"))
    comp.configure()
    comp.activate()
    assert comp.write(0.0, 0.01) is ReturnType.OK
    assert impl.writes == 0 and comp.get_lifecycle_state() is ACTIVE


@pytest.mark.parametrize("method", ["read", "write"])
@pytest.mark.parametrize(("on_error", "expected"), [(F, FINALIZED), (S, UNCONFIGURED)])
def test_error_result_calls_error(method: str, on_error: CallbackReturn, expected: State) -> None:
    comp = component_in(ACTIVE)
    scripted(comp).results.update({method: ReturnType.ERROR, "on_error": on_error})
    assert getattr(comp, method)(0.0, 0.01) is ReturnType.ERROR
    assert comp.get_lifecycle_state() is expected


@pytest.mark.parametrize("method", ["read", "write"])
def test_deactivate_result_is_passed_up_without_error(method: str) -> None:
    """DEACTIVATE is the resource manager's business; the wrapper only reports it."""
    comp = component_in(ACTIVE)
    scripted(comp).results[method] = ReturnType.DEACTIVATE
    assert getattr(comp, method)(0.0, 0.01) is ReturnType.DEACTIVATE
    assert comp.get_lifecycle_state() is ACTIVE and not scripted(comp).called("on_error")


@pytest.mark.parametrize("method", ["read", "write"])
def test_exception_in_read_or_write_is_logged_with_traceback_and_is_error(
    method: str, caplog: pytest.LogCaptureFixture
) -> None:
    comp = component_in(ACTIVE)
    boom = ZeroDivisionError("division by zero in learner code")
    scripted(comp).results[method] = boom
    with caplog.at_level(logging.ERROR, logger="rrbot_workshop.hardware_interface.hardware_component"):
        assert getattr(comp, method)(0.0, 0.01) is ReturnType.ERROR
    assert comp.get_lifecycle_state() is FINALIZED and comp.last_error is boom
    records = [r for r in caplog.records if r.exc_info is not None]
    assert records and records[0].exc_info[1] is boom  # type: ignore[index]
    assert "hw" in records[0].getMessage() and method in records[0].getMessage()


def test_read_returning_none_is_error() -> None:
    comp = component_in(ACTIVE)
    scripted(comp).results["read"] = None
    assert comp.read(0.0, 0.01) is ReturnType.ERROR


# ----------------------------------------------------------------- mode switching
@pytest.mark.parametrize("hook", ["prepare", "perform"])
def test_mode_switch_hooks_forward_lists_and_results(hook: str) -> None:
    comp = component_in(INACTIVE)
    scripted(comp).results[hook] = ReturnType.ERROR
    method = getattr(comp, f"{hook}_command_mode_switch")
    assert method(("joint1/position",), ()) is ReturnType.ERROR
    assert (hook, (["joint1/position"], [])) in scripted(comp).calls


@pytest.mark.parametrize("hook", ["prepare", "perform"])
def test_mode_switch_exception_is_error_and_keeps_state(hook: str) -> None:
    comp = component_in(ACTIVE)
    scripted(comp).results[hook] = KeyError("joint9")
    assert getattr(comp, f"{hook}_command_mode_switch")(["joint1/position"], []) is ReturnType.ERROR
    assert comp.get_lifecycle_state() is ACTIVE


# ----------------------------------------------------------------- interfaces and identity
def test_export_happens_once_and_registers_handles_on_the_implementation() -> None:
    comp = component_in(UNCONFIGURED)
    states = comp.export_state_interfaces()
    commands = comp.export_command_interfaces()
    assert [h.name for h in states] == ["joint1/position"] and [h.name for h in commands] == ["joint1/position"]
    assert comp.export_state_interfaces()[0] is states[0]  # the same handle objects every time
    impl = scripted(comp)
    assert impl.get_state("joint1/position") == 0.5
    impl.set_command("joint1/position", 0.7)
    assert commands[0].get_value() == 0.7


class ExportFails(SystemInterface):
    def export_state_interfaces(self) -> list[StateInterface]:
        raise RuntimeError("cannot open device")

    def export_command_interfaces(self) -> list[CommandInterface]:
        return []


def test_export_failure_raises_hardware_error_naming_the_component() -> None:
    comp = HardwareComponent(ExportFails())
    comp.initialize(HardwareInfo(name="broken", type="system"))
    with pytest.raises(HardwareError, match="broken"):
        comp.export_state_interfaces()


def test_unsupported_data_type_raises_hardware_error_on_export() -> None:
    bad = info()
    bad.joints[0].state_interfaces = [InterfaceInfo("image", data_type="cv::Mat")]
    comp = HardwareComponent(Scripted())
    comp.initialize(bad)
    with pytest.raises(HardwareError, match="cv::Mat"):
        comp.export_command_interfaces()


def test_identity_and_status_come_from_the_description() -> None:
    comp = component_in(ACTIVE)
    assert (comp.name, comp.type, comp.group, comp.plugin_name) == ("hw", "system", "arm", "test/Scripted")
    assert (comp.get_name(), comp.get_group_name()) == ("hw", "arm")
    status = comp.component_info(rw_rate=100)
    assert status == HardwareComponentInfo(
        name="hw", type="system", plugin_name="test/Scripted", group="arm", state=ACTIVE, is_async=False,
        rw_rate=100, command_interfaces=["joint1/position"], state_interfaces=["joint1/position"],
    )
    assert comp.component_info().rw_rate == 50


def test_type_falls_back_to_the_class_before_initialize() -> None:
    assert HardwareComponent(ScriptedSensor()).type == "sensor"


def test_configure_exports_first_and_raises_if_export_fails() -> None:
    comp = HardwareComponent(ExportFails())
    comp.initialize(HardwareInfo(name="broken", type="system"))
    with pytest.raises(HardwareError, match="cannot open device"):
        comp.configure()
    assert comp.get_lifecycle_state() is UNCONFIGURED


def test_configure_without_explicit_export_registers_handles() -> None:
    comp = component_in(UNCONFIGURED)
    comp.configure()
    assert scripted(comp).get_state("joint1/position") == 0.5
