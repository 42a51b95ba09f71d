"""Mock actuator and mock sensor: what ``mock_hardware`` puts in place of an actuator or sensor plugin it lacks.

Jazzy has one mock, ``mock_components/GenericSystem``, and exports it only as a ``SystemInterface``: its plugin
loader refuses it on a ``<ros2_control type="actuator">`` or ``type="sensor">`` tag. A ROS user who wants to try
such a robot without its drivers has to rewrite the tag as ``type="system"`` (or have the real plugin). To bring up
a robot of the demos' layouts as it is written, ``bringup(..., mock_hardware="unknown")`` replaces an unknown
actuator or sensor plugin with the library's own stand-ins, which are *not* in Jazzy:

* ``rrbot_workshop/MockActuator``: GenericSystem's mirroring (and its ``<hardware><param>`` options) as an actuator;
  it behaves as GenericSystem would on the same joint.
* ``rrbot_workshop/MockSensor``: a sensor that exports the declared state interfaces and holds them at their
  ``initial_value`` (NaN without one, as GenericSystem leaves a sensor state). Differences from GenericSystem: a
  sensor has no command interfaces in ros2_control, so ``mock_sensor_commands``/``mock_gpio_commands`` cannot make
  its values settable (they are ignored with a warning), and nothing ever changes its readings.

Both are resolved by their names like any plugin, so a description may name them, but such a description loads in
this library only; ``bringup`` reports every substitution it made.
"""

from __future__ import annotations

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware.mock import GenericSystem
from rrbot_workshop.hardware_interface.handles import CommandInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType

__all__ = ["MockActuator", "MockSensor"]


class MockActuator(GenericSystem):
    """GenericSystem's mirroring for a ``<ros2_control type="actuator">`` tag (``rrbot_workshop/MockActuator``)."""

    component_type = "actuator"


class MockSensor(GenericSystem):
    """A sensor whose states hold their initial values (``rrbot_workshop/MockSensor``)."""

    component_type = "sensor"

    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        """Read the parameters as GenericSystem does; command mocking is not possible on a sensor."""
        result = super().on_init(info)
        if self.mock_sensor_commands or self.mock_gpio_commands:
            self.logger.warning(
                "hardware '%s' (type sensor, mocked by rrbot_workshop/MockSensor): a sensor has no command "
                "interfaces, so mock_sensor_commands/mock_gpio_commands are ignored and its states keep their "
                "initial values", info.name)
        self.mock_sensor_commands = self.mock_gpio_commands = False
        return result

    def export_command_interfaces(self) -> list[CommandInterface]:
        """Sensors have no command interfaces."""
        return []

    def write(self, time: float, period: float) -> ReturnType:
        """Sensors do not write; always OK."""
        return ReturnType.OK
