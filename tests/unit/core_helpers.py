"""Small hardware and controllers for the core's tests (like ros2_control's test_controller and
test_chainable_controller), so the manager's tests do not depend on the real controllers."""

from __future__ import annotations

from typing import Any

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo
from rrbot_workshop.hardware_interface.component_interface import SensorInterface, SystemInterface
from rrbot_workshop.hardware_interface.handles import CommandInterface, StateInterface
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.params import load_controllers_yaml

__all__ = [
    "TestSystem",
    "TestSensor",
    "TestController",
    "TestChainableController",
    "make_info",
    "make_cm",
    "load_configure",
]


def make_info(
    name: str,
    joints: dict[str, tuple[list[str], list[str]]] | None = None,
    sensors: dict[str, list[str]] | None = None,
    type: str = "system",  # noqa: A002
    group: str = "",
    rw_rate: int = 0,
    plugin: str = "test_hardware/TestSystem",
) -> HardwareInfo:
    """A HardwareInfo built by hand: joints map to (command interfaces, state interfaces)."""
    info = HardwareInfo(name=name, type=type, group=group, rw_rate=rw_rate, hardware_plugin_name=plugin)
    for j, (cmds, states) in (joints or {}).items():
        info.joints.append(
            ComponentInfo(
                name=j,
                type="joint",
                command_interfaces=[InterfaceInfo(c, initial_value="0.0") for c in cmds],
                state_interfaces=[InterfaceInfo(s, initial_value="0.0") for s in states],
            )
        )
    for s, states in (sensors or {}).items():
        info.sensors.append(
            ComponentInfo(name=s, type="sensor", state_interfaces=[InterfaceInfo(i, initial_value="0.0") for i in states])
        )
    return info


class TestSystem(SystemInterface):
    """Copies each command to the state of the same name on write; failure modes set by attributes."""

    __test__ = False

    def __init__(self) -> None:
        super().__init__()
        self.read_result = ReturnType.OK
        self.write_result = ReturnType.OK
        self.raise_in_read = False
        self.reads = 0
        self.writes = 0
        self.read_periods: list[float] = []
        self.prepare_result = ReturnType.OK
        self.prepared: list[tuple[list[str], list[str]]] = []
        self.performed: list[tuple[list[str], list[str]]] = []
        self.on_error_result = CallbackReturn.SUCCESS

    def on_error(self, previous_state: State) -> CallbackReturn:
        return self.on_error_result

    def read(self, time: float, period: float) -> ReturnType:
        self.reads += 1
        self.read_periods.append(period)
        if self.raise_in_read:
            raise RuntimeError("sensor cable unplugged")
        return self.read_result

    def write(self, time: float, period: float) -> ReturnType:
        self.writes += 1
        for name in self.command_interface_names:
            if name in self._state_handles:
                value = self.get_command(name)
                if value == value:  # not NaN
                    self.set_state(name, value)
        return self.write_result

    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        self.prepared.append((list(start_interfaces), list(stop_interfaces)))
        return self.prepare_result

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        self.performed.append((list(start_interfaces), list(stop_interfaces)))
        return ReturnType.OK


class TestSensor(SensorInterface):
    """A sensor that reads fine."""

    __test__ = False

    def __init__(self) -> None:
        super().__init__()
        self.reads = 0

    def read(self, time: float, period: float) -> ReturnType:
        self.reads += 1
        return ReturnType.OK


def _config(names: list[str] | str | None) -> InterfaceConfiguration:
    if names == "all":
        return InterfaceConfiguration(InterfaceConfigurationType.ALL)
    if not names:
        return InterfaceConfiguration(InterfaceConfigurationType.NONE)
    return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, list(names))


class TestController(ControllerInterface):
    """Writes ``command_value`` to every claimed command interface; parameters ``command_interfaces`` and
    ``state_interfaces`` (lists, or ``"all"``)."""

    __test__ = False

    def __init__(self) -> None:
        super().__init__()
        self.command_value = 1.0
        self.update_result = ReturnType.OK
        self.raise_in_update = False
        self.updates: list[tuple[float, float]] = []
        self.activate_result = CallbackReturn.SUCCESS

    def command_interface_configuration(self) -> InterfaceConfiguration:
        return _config(self.get_node().get_parameter("command_interfaces", []))

    def state_interface_configuration(self) -> InterfaceConfiguration:
        return _config(self.get_node().get_parameter("state_interfaces", []))

    def on_activate(self, previous_state: State) -> CallbackReturn:
        return self.activate_result

    def update(self, time: float, period: float) -> ReturnType:
        self.updates.append((time, period))
        if self.raise_in_update:
            raise ValueError("learner bug in update")
        for loan in self.command_interfaces:
            loan.set_value(self.command_value)
        return self.update_result


class TestChainableController(ChainableControllerInterface):
    """Exports ``reference_interfaces`` (and ``exported_state_interfaces``) as ``<name>/<entry>``; writes
    ``2 * reference`` to its command interfaces. When not chained, the references come from
    ``reference_value``."""

    __test__ = False

    def __init__(self) -> None:
        super().__init__()
        self.reference_value = 0.5
        self.update_result = ReturnType.OK
        self.updates = 0

    def command_interface_configuration(self) -> InterfaceConfiguration:
        return _config(self.get_node().get_parameter("command_interfaces", []))

    def state_interface_configuration(self) -> InterfaceConfiguration:
        return _config(self.get_node().get_parameter("state_interfaces", []))

    def on_export_reference_interfaces(self) -> list[CommandInterface]:
        refs = self.get_node().get_parameter("reference_interfaces", [])
        return [CommandInterface(self.get_name(), r, initial_value=0.0) for r in refs]

    def on_export_state_interfaces(self) -> list[StateInterface]:
        exps = self.get_node().get_parameter("exported_state_interfaces", [])
        return [StateInterface(self.get_name(), e, initial_value=0.0) for e in exps]

    def update_reference_from_subscribers(self, time: float, period: float) -> ReturnType:
        for ref in self.reference_interfaces:
            ref.set_value(self.reference_value)
        return ReturnType.OK

    def update_and_write_commands(self, time: float, period: float) -> ReturnType:
        self.updates += 1
        for loan, ref in zip(self.command_interfaces, self.reference_interfaces, strict=False):
            loan.set_value(2.0 * ref.get_value())
        for exp in self.exported_state_interfaces:
            exp.set_value(float(self.updates))
        return self.update_result


plugins.register("controller", "test_controller/TestController", TestController)
plugins.register("controller", "test_controller/TestChainableController", TestChainableController)
plugins.register("hardware", "test_hardware/TestSystem", TestSystem)
plugins.register("hardware", "test_hardware/TestSensor", TestSensor)


def make_cm(
    controllers: dict[str, dict[str, Any]],
    hardware: list[tuple[Any, HardwareInfo]] | None = None,
    update_rate: int = 100,
    manager: dict[str, Any] | None = None,
) -> ControllerManager:
    """A manager over the given hardware (default: one TestSystem 'sys' with joint1, joint2 in position).

    ``controllers`` maps a name to its parameters plus a ``type`` key (default TestController).
    """
    rm = ResourceManager(update_rate=update_rate)
    if hardware is None:
        hardware = [
            (TestSystem(), make_info("sys", {"joint1": (["position"], ["position"]), "joint2": (["position"], ["position"])}))
        ]
    for impl, info in hardware:
        rm.import_component(impl, info)
    cm_params: dict[str, Any] = {"update_rate": update_rate, **(manager or {})}
    doc: dict[str, Any] = {"controller_manager": {"ros__parameters": cm_params}}
    for name, params in controllers.items():
        params = dict(params)
        cm_params[name] = {"type": params.pop("type", "test_controller/TestController")}
        doc[name] = {"ros__parameters": params}
    return ControllerManager(rm, params=load_controllers_yaml(doc), update_rate=update_rate)


def load_configure(cm: ControllerManager, *names: str) -> None:
    """Load and configure each controller."""
    for n in names:
        cm.load_controller(n)
        cm.configure_controller(n)
