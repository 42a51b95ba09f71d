"""``force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster``: six state interfaces -> ``~/wrench``.

Either ``sensor_name`` is set (interfaces ``<sensor_name>/force.x`` ... ``<sensor_name>/torque.z``, as the
ros2_control ``ForceTorqueSensor`` semantic component names them), or some of
``interface_names.force.{x,y,z}`` / ``interface_names.torque.{x,y,z}`` give full interface names; an
axis without an interface is published as NaN. ``frame_id`` is required.

Each reading is corrected per axis as Jazzy does: ``(value + offset.<group>.<axis>) * multiplier.<group>.<axis>``
(defaults 0 and 1). The corrected wrench is published, and its configured axes are exported as state
interfaces other controllers can read (the broadcaster is chainable; it has no reference interfaces). As in Jazzy,
with ``sensor_name`` they are ``<controller>/<sensor_name>/force.x`` ... ``/torque.z``; with ``interface_names``
one per configured axis, ``<controller>/<interface name>`` (e.g. ``<controller>/fts_sensor/torque.z``).

Differences from Jazzy: a configuration mistake returns FAILURE (the controller stays unconfigured and
can be fixed and configured again) where Jazzy returns ERROR; the optional filter chain and
``~/wrench_filtered`` are not provided.
"""

from __future__ import annotations

import math
from typing import ClassVar

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.hardware_interface.handles import StateInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.topics import Publisher
from rrbot_workshop.msgs import Header, Vector3, Wrench, WrenchStamped

__all__ = ["ForceTorqueSensorBroadcaster", "AXES"]

#: The six axes in message order: (field group, axis).
AXES = (("force", "x"), ("force", "y"), ("force", "z"), ("torque", "x"), ("torque", "y"), ("torque", "z"))


def _axis_parameters(ptype: str, default: str, what: str) -> str:
    lines = []
    for group in ("force", "torque"):
        lines.append(f"    {group}:")
        for axis in "xyz":
            lines += [
                f"      {axis}:",
                f"        type: {ptype}",
                f"        default_value: {default}",
                f'        description: "{what} {group} along {axis}."',
            ]
    return "\n".join(lines)


class ForceTorqueSensorBroadcaster(ChainableControllerInterface):
    """Publishes a force-torque sensor's state interfaces as ``geometry_msgs/WrenchStamped`` and exports them."""

    PARAMETERS: ClassVar[str | None] = f"""
force_torque_sensor_broadcaster:
  frame_id:
    type: string
    default_value: ""
    description: "Frame of the sensor; header.frame_id of ~/wrench."
    validation:
      not_empty<>: []
  sensor_name:
    type: string
    default_value: ""
    description: "Sensor name; its interfaces are <sensor_name>/force.x ... torque.z."
  interface_names:
{_axis_parameters("string", '""', "State interface with the")}
  offset:
{_axis_parameters("double", "0.0", "Added to the measured")}
  multiplier:
{_axis_parameters("double", "1.0", "Multiplies the (offset) measured")}
"""

    def __init__(self) -> None:
        super().__init__()
        self._names: list[str | None] = [None] * 6  # full interface name per axis, None = absent
        self._export_prefix = ""
        self._exported: list[tuple[int, str]] = []  # (axis index, exported interface name) of configured axes
        self._frame_id = ""
        self._pub: Publisher | None = None
        self._offset = [0.0] * 6
        self._multiplier = [1.0] * 6

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Work out the six interface names; create ``~/wrench``."""
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        given = [getattr(getattr(params.interface_names, g), a) for g, a in AXES]
        if not params.sensor_name and not any(given):
            self.logger.error(
                "'%s': set parameter 'sensor_name' or at least one of 'interface_names.[force|torque].[x|y|z]'",
                self.get_name())
            return CallbackReturn.FAILURE
        if params.sensor_name and any(given):
            self.logger.error(
                "'%s': parameters 'sensor_name' and 'interface_names.[force|torque].[x|y|z]' cannot be used "
                "together; choose one", self.get_name())
            return CallbackReturn.FAILURE
        if params.sensor_name:
            self._names = [f"{params.sensor_name}/{g}.{a}" for g, a in AXES]
            self._export_prefix = f"{self.get_name()}/{params.sensor_name}"
            self._exported = [(k, f"{g}.{a}") for k, (g, a) in enumerate(AXES)]
        else:
            self._names = [n or None for n in given]
            self._export_prefix = self.get_name()
            self._exported = [(k, n) for k, n in enumerate(given) if n]
        self._frame_id = params.frame_id
        self._offset = [float(getattr(getattr(params.offset, g), a)) for g, a in AXES]
        self._multiplier = [float(getattr(getattr(params.multiplier, g), a)) for g, a in AXES]
        if self._pub is None:
            self._pub = self.get_node().create_publisher(WrenchStamped, "~/wrench")
        return CallbackReturn.SUCCESS

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """The configured axes' interfaces, in the order force x, y, z, torque x, y, z."""
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, [n for n in self._names if n])

    def on_export_state_interfaces(self) -> list[StateInterface]:
        """The corrected wrench's configured axes (see the module's docstring for their names)."""
        return [StateInterface(self._export_prefix, name, initial_value=math.nan) for _, name in self._exported]

    def update_reference_from_subscribers(self, time: float, period: float) -> ReturnType:
        """A broadcaster has no references to read."""
        return ReturnType.OK

    def update_and_write_commands(self, time: float, period: float) -> ReturnType:
        """Correct each axis, export and publish the wrench, stamped with ``time``."""
        values = [math.nan] * 6
        loans = iter(self.state_interfaces)
        for k, name in enumerate(self._names):
            if name:
                loan = next(loans, None)
                if loan is not None:
                    values[k] = (float(loan.get_value()) + self._offset[k]) * self._multiplier[k]
        for handle, (k, _) in zip(self.exported_state_interfaces, self._exported):  # noqa: B905 - strict= is slow
            handle.set_value(values[k])
        if self._pub is not None:
            self._pub.publish(WrenchStamped(
                header=Header(stamp=time, frame_id=self._frame_id),
                wrench=Wrench(force=Vector3(*values[:3]), torque=Vector3(*values[3:])),
            ))
        return ReturnType.OK
